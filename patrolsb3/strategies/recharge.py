"""The recharge planner every heuristic shares (docs/model.md, section 6).

Rule: an active agent heads for its nearest charging station as soon as its battery is at or
below :func:`patrolsb3.core.masks.return_threshold` for its cell,

    battery <= steps_home(cell) * drain_high * push_factor_margin + b_l

(the one place of that rule; the learned policies' optional shield ``env.return_guard`` uses
it too), so that it arrives with about ``b_l`` (20 % of b_max) to spare. The decision is
latched: the agent keeps heading home (shortest path, valid moves only) until its swap
starts, and a new agent appears with a full battery. An agent that the wind pushed onto the
station (a pushed arrival starts no swap) steps off and back on.

Deadlocks: any number of agents may share a station, so arrivals never wait for each other
there; agents leave a station only while no agent heading home is within
``STATION_CLEARANCE`` steps of it (the station exit rule: dead-end corridors to the station
stay one-way). An agent heading home has right of way: a patrolling agent standing on the
cell a blocked returning agent needs next (any shortest-path step toward its station) gives
way at once with a random valid move, backing onto the station (and swapping early) only
when that is its only way out, as in a dead-end corridor that leads to the station; when
such an agent cannot move at all, the patrolling agents next to it give way too, so a
corridor full of agents empties from its far end (:meth:`RechargePlanner.give_way`). Other
blockages follow the general deadlock rule: patrolling agents move aside after
``PATROL_PATIENCE`` blocked steps, a returning agent only after ``HOME_PATIENCE`` (see
:meth:`patrolsb3.strategies.navigation.Navigator.unblock`).
"""
from __future__ import annotations

import numpy as np

from ..core.config import EnvConfig
from ..core.maps import STAY, MapSpec
from ..core.masks import return_threshold, station_cells
from ..core.state import ACTIVE, State
from .navigation import Navigator

PATROL_PATIENCE = 3
"""Blocked steps a patrolling agent tolerates before moving aside."""
HOME_PATIENCE = 8
"""Blocked steps an agent heading home tolerates before moving aside (it has priority)."""
STATION_CLEARANCE = 6
"""Station exit rule: an agent on a station stays while an agent heading home is this close."""


class RechargePlanner:
    """Decides who heads home and how.

    Args:
        spec: the map.
        cfg: environment parameters (battery, drain, pushes).
    """

    def __init__(self, spec: MapSpec, cfg: EnvConfig):
        self.spec = spec
        station_free = spec.free_index[spec.stations]                          # (S,)
        to_station = spec.dist[:, station_free]                                 # (F, S)
        n_cells = spec.kinds.size
        self.station_of_cell = np.full(n_cells, spec.station, dtype=np.int64)   # (H*W,) nearest station
        self.station_of_cell[spec.free_cells] = spec.stations[np.argmin(to_station, axis=1)]
        self.steps_home = spec.steps_home                                       # (H*W,)
        self.threshold = return_threshold(spec, cfg)                            # (H*W,) battery units
        self.is_station = station_cells(spec)                                   # (H*W,)

    def update(self, sim: State, returning: np.ndarray) -> np.ndarray:
        """Latch the "heading home" flag in place and return it.

        Args:
            sim: the batched simulator state.
            returning: (E, A) bool flags carried between steps, updated in place.

        Returns:
            The same (E, A) array: active agents heading for a station.
        """
        active = sim.status == ACTIVE
        returning |= active & (sim.battery <= self.threshold[sim.pos])
        returning &= active
        return returning

    def home_traffic(self, sim: State, returning: np.ndarray) -> np.ndarray:
        """(E,) bool: an agent heading home is within ``STATION_CLEARANCE`` steps of a station."""
        return (returning & (self.steps_home[sim.pos] <= STATION_CLEARANCE)).any(axis=1)

    def give_way(self, nav: Navigator, sim: State, returning: np.ndarray, home_stuck: np.ndarray,
                 mask: np.ndarray) -> np.ndarray:
        """(E, A) bool: patrolling agents that must give way to an agent heading home now.

        Only episodes with a blocked returning agent are examined (rare in large batches);
        :meth:`in_the_way` says who blocks.

        Args:
            nav: the navigator.
            sim: the batched simulator state.
            returning: (E, A) bool, agents heading home.
            home_stuck: (E, A) bool, slots with no valid step toward their station.
            mask: (E, A, 5) valid moves.
        """
        active = sim.status == ACTIVE
        blocked_home = returning & home_stuck & active                          # (E, A)
        rows = blocked_home.any(axis=1)                                        # (E,)
        give_way = np.zeros_like(blocked_home)
        if rows.any():
            give_way[rows] = self.in_the_way(nav, sim.pos[rows], active[rows], returning[rows],
                                             blocked_home[rows], mask[rows])
        return give_way

    def in_the_way(self, nav: Navigator, pos: np.ndarray, active: np.ndarray, returning: np.ndarray,
                   blocked_home: np.ndarray, mask: np.ndarray) -> np.ndarray:
        """Patrolling agents that block an agent heading home (they must give way).

        Args:
            nav: the navigator (its station-avoiding distances).
            pos: (E, A) cells.
            active: (E, A) bool, active agents.
            returning: (E, A) bool, agents heading home.
            blocked_home: (E, A) bool, returning agents with no valid step toward their station.
            mask: (E, A, 5) valid moves.

        Returns:
            (E, A) bool: active agents not heading home that stand on a cell one step closer
            to the station of a blocked returning agent of the same episode (its next cell on
            some shortest path, other agents ignored), and, in a chain, the agents around
            such a blocker that has no valid move at all (a one-cell corridor full of
            patrolling agents empties from its far end, onto the station if that is the end).
        """
        goal = self.station_of_cell[pos]                                         # (E, A)
        here = nav.distance(pos, goal)                                           # (E, A)
        nxt = self.spec.neighbour[pos]                                           # (E, A, 5)
        closer = (self.spec.move_ok[pos]
                  & (nav.distance(nxt, goal[..., None]) == here[..., None] - 1))  # (E, A, 5)
        wants = closer & blocked_home[..., None]                                 # (E, A, 5)
        # blocker[e, j]: some agent i of episode e wants the cell of agent j next
        hits = wants[:, :, None, :] & (nxt[:, :, None, :] == pos[:, None, :, None])  # (E, A_i, A_j, 5)
        patrolling = active & ~returning & ~self.is_station[pos]                 # (E, A) on a station blocks nobody
        blocker = hits.any(axis=(1, 3)) & patrolling                             # (E, A)
        cannot_move = ~mask[..., :STAY].any(axis=-1)                             # (E, A)
        others = ~np.eye(pos.shape[1], dtype=bool)[None, :, :, None]             # (1, A_i, A_j, 1)
        around = (nxt[:, :, None, :STAY] == pos[:, None, :, None]) & others      # (E, A_i, A_j, 4)
        for _ in range(pos.shape[1] - 1):                                         # chains of blockers
            wedged = blocker & cannot_move                                        # (E, A)
            grown = blocker | ((wedged[:, :, None, None] & around).any(axis=(1, 3)) & patrolling)
            if (grown == blocker).all():
                break
            blocker = grown
        return blocker

    def moves(self, nav: Navigator, sim: State, mask: np.ndarray):
        """Moves toward the nearest station for every slot (meaningful where heading home).

        Returns:
            moves (E, A) int64 and stuck (E, A) bool.
        """
        pos = sim.pos
        moves, stuck = nav.toward(pos, self.station_of_cell[pos], mask)
        on_station = self.is_station[pos]
        if on_station.any():   # pushed onto the station: step off to come back on purpose
            moves = np.where(on_station, nav.random_moves(pos, mask, include_stay=False), moves)
        return moves, stuck
