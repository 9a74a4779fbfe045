"""Shortest-path navigation shared by every heuristic.

* :func:`patrol_distances` — shortest-path lengths between free cells that never pass
  *through* a charging station (entering a station on purpose starts a battery swap, so a
  patrolling agent must not cross one by accident). Where the only path crosses a station
  (a station that cuts the map in two) the map's own distance is used instead.
* :class:`Navigator` — one greedy step toward a goal cell among the *valid* moves (the core's
  action mask), ties at random; random valid moves; and the deadlock rule "move aside when
  blocked": an agent that wants to move but has had no valid move toward its goal for
  ``patience`` steps in a row takes a random valid move (never onto a station), which frees
  one-cell corridors and doorways where two agents face each other.
"""
from __future__ import annotations

import numpy as np

from ..core.maps import STAY, MapSpec, _all_pairs_bfs
from ..core.masks import station_cells

_CACHE: dict[int, tuple] = {}


def entering_station(spec: MapSpec) -> np.ndarray:
    """(H*W, 5) bool, True where an action moves from another cell onto a station."""
    here = np.arange(spec.kinds.size)[:, None]
    return station_cells(spec)[spec.neighbour] & (spec.neighbour != here)


def patrol_distances(spec: MapSpec) -> np.ndarray:
    """(F, F) int32 shortest-path lengths between free cells avoiding stations in between.

    Paths may start or end on a station but never cross one; pairs that can only be joined
    through a station get :attr:`MapSpec.dist`. Cached per map object.
    """
    key = id(spec)
    if key not in _CACHE or _CACHE[key][0] is not spec:
        move_ok = spec.move_ok & ~entering_station(spec)                   # (H*W, 5)
        dist, _ = _all_pairs_bfs(spec.free_cells, spec.free_index, spec.neighbour, move_ok)
        dist = np.where(dist < 0, spec.dist, dist).astype(np.int32)       # (F, F)
        dist.setflags(write=False)
        _CACHE[key] = (spec, dist)
    return _CACHE[key][1]


def restricted_distances(spec: MapSpec, cells: np.ndarray) -> np.ndarray:
    """(F, F) int32 path lengths moving only inside ``cells`` (H*W bool); -1 outside."""
    move_ok = spec.move_ok & cells[spec.neighbour] & cells[:, None]
    move_ok[:, STAY] = spec.move_ok[:, STAY]
    dist, _ = _all_pairs_bfs(spec.free_cells, spec.free_index, spec.neighbour, move_ok)
    return dist


class Navigator:
    """Greedy shortest-path steps and random valid moves for a batch of agents.

    Args:
        spec: the map.
        rng: generator for tie-breaks and random moves.
    """

    def __init__(self, spec: MapSpec, rng: np.random.Generator):
        self.spec = spec
        self.rng = rng
        self.dist = patrol_distances(spec)                                 # (F, F)
        self.free_index = spec.free_index                                  # (H*W,)
        self.neighbour_free = np.where(spec.free_index[spec.neighbour] >= 0,
                                       spec.free_index[spec.neighbour], 0)  # (H*W, 5)
        self.enters_station = entering_station(spec)                      # (H*W, 5)

    def distance(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """Station-avoiding path length between cells ``a`` and ``b`` (broadcasting)."""
        return self.dist[self.free_index[a], self.free_index[b]]

    def toward(self, pos: np.ndarray, goal: np.ndarray, mask: np.ndarray, tables=None, which=None):
        """One step toward ``goal`` for every slot.

        Among valid moves that do not enter a station (unless the station is the goal), take
        one that leaves the fewest steps to the goal; ties at random. Staying wins when every
        valid move leads farther away (grid moves change the distance by exactly 1).

        Args:
            pos: (E, A) current cells.
            goal: (E, A) goal cells.
            mask: (E, A, 5) valid moves (``core.masks.action_mask``).
            tables: optional (T, F, F) distance tables to use instead of the patrol one.
            which: (E, A) index into ``tables`` per slot.

        Returns:
            moves (E, A) int64 and stuck (E, A) bool (not at the goal and no step toward it).
        """
        if tables is None:
            left = self.dist[self.neighbour_free[pos], self.free_index[goal][..., None]]   # (E, A, 5)
        else:
            left = tables[which[..., None], self.neighbour_free[pos], self.free_index[goal][..., None]]
        allowed = mask & (~self.enters_station[pos] | (self.spec.neighbour[pos] == goal[..., None]))
        score = np.where(allowed, left + 0.5 * self.rng.random(left.shape), np.inf)
        moves = np.argmin(score, axis=-1)
        return moves, (moves == STAY) & (pos != goal)

    def random_moves(self, pos: np.ndarray, mask: np.ndarray, include_stay: bool = True) -> np.ndarray:
        """A uniformly random valid move per slot that does not enter a station.

        Args:
            pos: (E, A) current cells.
            mask: (E, A, 5) valid moves.
            include_stay: when False, Stay is taken only if nothing else is valid.

        Returns:
            (E, A) int64 moves.
        """
        weight = self.rng.random(mask.shape) * (mask & ~self.enters_station[pos])   # (E, A, 5)
        weight[..., STAY] = weight[..., STAY] if include_stay else 1e-9
        return np.argmax(weight, axis=-1)

    def retreat_moves(self, pos: np.ndarray, mask: np.ndarray) -> np.ndarray:
        """Like :meth:`random_moves` without Stay, but a station is allowed when it is the
        only way out (an agent wedged between the station and another agent in a dead-end
        corridor backs onto the station: it costs a swap, it breaks the deadlock)."""
        weight = self.rng.random(mask.shape) * mask
        weight[..., :STAY] *= np.where(self.enters_station[pos][..., :STAY], 1e-3, 1.0)
        weight[..., STAY] = 1e-9
        return np.argmax(weight, axis=-1)

    def unblock(self, moves: np.ndarray, stuck: np.ndarray, blocked: np.ndarray,
                patience: np.ndarray, pos: np.ndarray, mask: np.ndarray) -> np.ndarray:
        """The deadlock rule: after ``patience`` stuck steps in a row, move aside at random.

        Args:
            moves: (E, A) planned moves.
            stuck: (E, A) bool, slots with no step toward their goal this step.
            blocked: (E, A) int64 stuck-step counters, updated in place.
            patience: (E, A) or scalar, stuck steps tolerated before moving aside.
            pos: (E, A) current cells.
            mask: (E, A, 5) valid moves.

        Returns:
            (E, A) moves with the moves aside applied.
        """
        blocked[...] = np.where(stuck, blocked + 1, 0)
        aside = blocked >= patience
        if aside.any():
            moves = np.where(aside, self.retreat_moves(pos, mask), moves)
            blocked[aside] = 0
        return moves
