"""CYCLIC: every agent follows one closed tour of all vertices, spread evenly along it.

Tour (:func:`build_tour`, once per map): nearest-neighbour construction from vertex 0, then
2-opt until no exchange shortens it, on station-avoiding shortest-path lengths; consecutive
tour vertices that are not grid neighbours are joined by a shortest path. Its length L is the
number of steps of one lap; one agent alone revisits every vertex at most every L steps.

Patrol rule: an agent heads for its next tour vertex and, on reaching it, for the one after.
An agent joining (start, or back from a swap) heads for the tour vertex nearest to it.
Spreading: each agent's arc position on the tour is measured; an agent waits (stays) while its
gap to the agent ahead is more than ``SPACING_SLACK`` steps shorter than its gap to the agent
behind, so the team drifts to an even spacing of L / k. Recharge and deadlock rules: the shared
ones (:mod:`.recharge`).
"""
from __future__ import annotations

import numpy as np

from ..core.maps import STAY, MapSpec
from .base import HeuristicPolicy
from .navigation import patrol_distances

SPACING_SLACK = 2
"""Steps of imbalance tolerated between the gaps ahead and behind before an agent waits."""

_CACHE: dict[int, tuple] = {}


def tour_length(tour: np.ndarray, vdist: np.ndarray) -> int:
    """Steps of one closed lap of ``tour`` (vertex indices) under the distance table."""
    return int(vdist[tour, np.roll(tour, -1)].sum())


def build_tour(spec: MapSpec) -> np.ndarray:
    """A short closed tour of every vertex (nearest neighbour + 2-opt).

    Returns:
        (V,) int64 vertex indices in visiting order (a permutation of 0..V-1).
    """
    key = id(spec)
    if key in _CACHE and _CACHE[key][0] is spec:
        return _CACHE[key][1]
    vf = spec.free_index[spec.vertex_cells]
    vdist = patrol_distances(spec)[np.ix_(vf, vf)].astype(np.int64)         # (V, V)
    V = spec.n_vertices
    tour = [0]
    left = np.ones(V, dtype=bool)
    left[0] = False
    for _ in range(V - 1):
        d = np.where(left, vdist[tour[-1]], np.iinfo(np.int64).max)
        nxt = int(np.argmin(d))
        tour.append(nxt)
        left[nxt] = False
    tour = np.array(tour, dtype=np.int64)
    improved = True
    while improved and V > 3:
        improved = False
        for i in range(V - 2):
            a, b = tour[i], tour[i + 1]
            c, d = tour[i + 2:], np.roll(tour, -1)[i + 2:]
            delta = vdist[a, c] + vdist[b, d] - vdist[a, b] - vdist[c, d]    # (V - i - 2,)
            if i == 0:
                delta = delta[:-1]   # the edge (last, first) shares vertex a
            j = int(np.argmin(delta)) if len(delta) else 0
            if len(delta) and delta[j] < 0:
                tour[i + 1:i + 3 + j] = tour[i + 1:i + 3 + j][::-1].copy()
                improved = True
    tour.setflags(write=False)
    _CACHE[key] = (spec, tour)
    return tour


class CyclicPolicy(HeuristicPolicy):
    """One shared tour, agents spread evenly (see module docstring)."""

    name = "CYCLIC"

    def __init__(self, spec, n_agents, cfg=None, seed=0):
        super().__init__(spec, n_agents, cfg, seed)
        self.tour = build_tour(self.spec)                                     # (V,) vertex order
        self.tour_cells = self.spec.vertex_cells[self.tour]                   # (V,)
        vf = self.spec.free_index[self.tour_cells]
        hop = self.nav.dist[vf, np.roll(vf, -1)].astype(np.int64)             # (V,) steps to next
        self.length = int(hop.sum())
        self.arc = np.concatenate([[0], np.cumsum(hop)[:-1]])                 # (V,) arc of each tour vertex
        nearest = np.argmin(self.nav.dist[:, vf], axis=1)                     # (F,) tour index nearest a cell
        self.nearest_index = np.zeros(self.spec.kinds.size, dtype=np.int64)
        self.nearest_index[self.spec.free_cells] = nearest

    def init_memory(self, sim):
        memory = super().init_memory(sim)
        memory["index"] = np.full(sim.pos.shape, -1, dtype=np.int64)        # (E, A) next tour index
        return memory

    def patrol_moves(self, sim, memory, mask, patrolling):
        index = memory["index"]
        index[~patrolling] = -1
        joining = patrolling & (index < 0)
        index[joining] = self.nearest_index[sim.pos[joining]]
        arrived = patrolling & (self.tour_cells[np.maximum(index, 0)] == sim.pos)
        index[arrived] = (index[arrived] + 1) % len(self.tour)
        goal = np.where(patrolling, self.tour_cells[np.maximum(index, 0)], sim.pos)
        moves, stuck = self.nav.toward(sim.pos, goal, mask)
        # spacing: arc position = arc of the next tour vertex minus the steps left to it
        L = self.length
        arc = (self.arc[np.maximum(index, 0)] - self.nav.distance(sim.pos, goal)) % L      # (E, A)
        ahead = (arc[:, None, :] - arc[:, :, None]) % L                       # (E, A, A) j ahead of i
        A = arc.shape[1]
        on_tour = patrolling[:, None, :] & ~np.eye(A, dtype=bool)[None]
        lower_slot = np.tril(np.ones((A, A), dtype=bool), -1)[None]          # j < i: ahead on a tie
        tie = ahead == 0
        to_ahead = np.where(tie, np.where(lower_slot, 0, L), ahead)           # (E, A, A)
        to_behind = np.where(tie, np.where(lower_slot, L, 0), L - ahead)
        gap_ahead = np.where(on_tour, to_ahead, L).min(axis=2)                # (E, A)
        gap_behind = np.where(on_tour, to_behind, L).min(axis=2)
        wait = patrolling & (on_tour.any(axis=2)) & (gap_ahead + SPACING_SLACK < gap_behind)
        moves = np.where(wait, STAY, moves)
        return moves, stuck & ~wait
