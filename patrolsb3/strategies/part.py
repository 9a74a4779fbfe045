"""PART: one connected part of the map per agent.

Partition (built once per map and team size, :func:`partition`): the vertices are split into
k connected parts of about equal priority-weighted size (weight of a vertex = its rate
``1 + priority``). Seeds are spread by farthest-point sampling; parts grow together, the
lightest part taking its frontier vertex nearest to its seed; then boundary vertices move from
the heaviest part to a lighter neighbouring part while that lowers the heavier weight and
keeps the donor connected. The best of several seeded restarts (smallest heaviest part) is
kept. Connectivity is through vertices only (never through a station). Balance achieved on
the shipped maps: see :data:`BALANCE_TOLERANCE`.

Patrol rule: agent i patrols part i (slot order). When it stands on its target (or has none)
it picks the vertex of highest idleness in its part — plus lent parts — (ties: the nearest,
then at random) and walks there by a shortest path *inside its part* (so agents of different
parts do not meet head-on in corridors); when it or its target is outside its part (pushed
out, lent parts) it takes a station-avoiding shortest path of the whole map, which brings a
pushed-out agent straight back. Lending: the part of an owner that is swapping or
failed is lent to the active owners of adjacent parts (to every active agent when no adjacent
owner is active). Recharge and deadlock rules: the shared ones (:mod:`.recharge`).
"""
from __future__ import annotations

import numpy as np

from ..core.maps import MapSpec
from ..core.state import ACTIVE
from .base import HeuristicPolicy
from .navigation import patrol_distances, restricted_distances

BALANCE_TOLERANCE = 0.25
"""Guaranteed by tests on the shipped maps: every part weighs within 25 % of total / k,
or within one vertex of the heaviest rate of it where priority vertices make that impossible."""

_CACHE: dict[tuple, tuple] = {}


def vertex_adjacency(spec: MapSpec) -> list[list[int]]:
    """Grid-neighbour lists of the vertices (vertex indices; stations excluded)."""
    nb = spec.vertex_of_cell[spec.neighbour[spec.vertex_cells, :4]]          # (V, 4)
    return [[int(u) for u in row if u >= 0] for row in nb]


def _connected(members: set, adjacency) -> bool:
    if not members:
        return True
    start = next(iter(members))
    seen, stack = {start}, [start]
    while stack:
        v = stack.pop()
        for u in adjacency[v]:
            if u in members and u not in seen:
                seen.add(u)
                stack.append(u)
    return len(seen) == len(members)


def _grow(spec, k, rng, vdist, adjacency, weight):
    V = spec.n_vertices
    seeds = [int(rng.integers(V))]
    for _ in range(1, k):
        seeds.append(int(np.argmax(vdist[:, seeds].min(axis=1))))
    owner = np.full(V, -1, dtype=np.int64)
    load = np.zeros(k)
    for i, s in enumerate(seeds):
        owner[s] = i
        load[i] = weight[s]
    while (owner < 0).any():
        grown = False
        for i in np.argsort(load, kind="stable"):
            frontier = {u for v in np.flatnonzero(owner == i) for u in adjacency[v] if owner[u] < 0}
            if frontier:
                f = np.array(sorted(frontier))
                v = int(f[np.argmin(vdist[seeds[i], f])])
                owner[v] = i
                load[i] += weight[v]
                grown = True
                break
        if not grown:   # vertices unreachable without crossing a station: nearest seed
            rest = np.flatnonzero(owner < 0)
            owner[rest] = np.argmin(vdist[np.ix_(rest, seeds)], axis=1)
            break
    return owner, seeds


def _refine(owner, k, adjacency, weight, seeds, vdist, max_moves=2000):
    load = np.bincount(owner, weights=weight, minlength=k)
    for _ in range(max_moves):
        moved = False
        for h in np.argsort(-load):
            members = set(np.flatnonzero(owner == h).tolist())
            candidates = []
            for v in members:
                for u in adjacency[v]:
                    light = owner[u]
                    if light != h and load[light] + weight[v] < load[h]:
                        candidates.append((-vdist[seeds[h], v], v, light))
            for _, v, light in sorted(candidates):
                if len(members) > 1 and _connected(members - {v}, adjacency):
                    owner[v] = light
                    load[h] -= weight[v]
                    load[light] += weight[v]
                    moved = True
                    break
            if moved:
                break
        if not moved:
            break
    return owner


def partition(spec: MapSpec, k: int, restarts: int = 8, seed: int = 0) -> np.ndarray:
    """Split the vertices into k connected parts of about equal rate-weighted size.

    Args:
        spec: the map.
        k: number of parts (1 <= k <= |V|).
        restarts: seeded restarts; the one with the lightest heaviest part wins.
        seed: seed of the restarts.

    Returns:
        (V,) int64 part index 0..k-1 of every vertex.
    """
    key = (id(spec), k, restarts, seed)
    if key in _CACHE and _CACHE[key][0] is spec:
        return _CACHE[key][1]
    if not 1 <= k <= spec.n_vertices:
        raise ValueError(f"cannot split {spec.n_vertices} vertices into {k} parts")
    dist = patrol_distances(spec)
    vf = spec.free_index[spec.vertex_cells]
    vdist = dist[np.ix_(vf, vf)].astype(np.float64)                           # (V, V)
    adjacency = vertex_adjacency(spec)
    weight = spec.rate
    rng = np.random.default_rng(seed)
    best, best_key = None, None
    for _ in range(restarts):
        owner, seeds = _grow(spec, k, rng, vdist, adjacency, weight)
        owner = _refine(owner, k, adjacency, weight, seeds, vdist)
        load = np.bincount(owner, weights=weight, minlength=k)
        spread = sum(vdist[np.ix_(owner == i, owner == i)].max() for i in range(k))
        rank = (load.max(), spread)
        if best_key is None or rank < best_key:
            best, best_key = owner.copy(), rank
    best.setflags(write=False)
    _CACHE[key] = (spec, best)
    return best


def part_adjacency(spec: MapSpec, owner: np.ndarray, k: int) -> np.ndarray:
    """(k, k) bool, parts that touch (a vertex of one is a grid neighbour of the other)."""
    adj = np.zeros((k, k), dtype=bool)
    for v, nbs in enumerate(vertex_adjacency(spec)):
        for u in nbs:
            adj[owner[v], owner[u]] = True
    np.fill_diagonal(adj, False)
    return adj


def _part_table(spec: MapSpec, part: np.ndarray, fallback: np.ndarray) -> np.ndarray:
    """(F, F) path lengths inside one part (``part``: (V,) bool); ``fallback`` + a large
    penalty where the part does not join two cells (moves that leave the part)."""
    key = (id(spec), part.tobytes())
    if key not in _CACHE or _CACHE[key][0] is not spec:
        cells = np.zeros(spec.kinds.size, dtype=bool)
        cells[spec.vertex_cells[part]] = True
        dist = restricted_distances(spec, cells)
        table = np.where(dist < 0, fallback + spec.kinds.size, dist).astype(np.int32)
        _CACHE[key] = (spec, table)
    return _CACHE[key][1]


class PARTPolicy(HeuristicPolicy):
    """Partition-based patrolling (see module docstring)."""

    name = "PART"

    def __init__(self, spec, n_agents, cfg=None, seed=0):
        super().__init__(spec, n_agents, cfg, seed)
        A, V = self.cfg.max_agents, self.spec.n_vertices
        self.parts = np.zeros((A + 1, A, V), dtype=bool)    # (k, slot, V) part of slot for team size k
        self.touch = np.zeros((A + 1, A, A), dtype=bool)    # (k, slot, slot) parts that touch
        for k in range(1, min(A, V) + 1):
            owner = partition(self.spec, k)
            self.parts[k, :k] = owner[None, :] == np.arange(k)[:, None]
            self.touch[k, :k, :k] = part_adjacency(self.spec, owner, k)
        self.vertex_free = self.spec.free_index[self.spec.vertex_cells]      # (V,)
        to_vertex = self.nav.dist[:, self.vertex_free]                       # (F, V)
        # (F, V) target-choice penalty: -1e-3 x path length, -inf for the cell the agent is on
        self.vertex_penalty = np.where(to_vertex == 0, -np.inf, -1e-3 * to_vertex)
        # table 0: the patrol table; table 1 + k * A + a: paths inside part a of a team of k
        F = len(self.spec.free_cells)
        self.tables = np.zeros((1 + (A + 1) * A, F, F), dtype=np.int32)      # (T, F, F)
        self.tables[0] = self.nav.dist
        for k in range(1, min(A, V) + 1):
            for a in range(k):
                self.tables[1 + k * A + a] = _part_table(self.spec, self.parts[k, a], self.nav.dist)
        self.part_cell = np.zeros((A + 1, A, self.spec.kinds.size), dtype=bool)   # (k, slot, H*W)
        self.part_cell[:, :, self.spec.vertex_cells] = self.parts

    def init_memory(self, sim):
        memory = super().init_memory(sim)
        memory["target"] = np.full(sim.pos.shape, -1, dtype=np.int64)       # (E, A) target cell
        return memory

    def allowed_vertices(self, sim, e_idx, a_idx) -> np.ndarray:
        """(n, V) bool: own part plus lent parts for the (episode, slot) pairs given."""
        k = sim.n_agents[e_idx]                                               # (n,)
        own = self.parts[k, a_idx]                                            # (n, V)
        active = sim.status[e_idx] == ACTIVE                                  # (n, A)
        deployed = np.arange(sim.pos.shape[1])[None, :] < k[:, None]
        away = deployed & ~active                                             # (n, A) owners absent
        if not away.any():                                                    # nothing to lend
            return own
        touch = self.touch[k]                                                 # (n, A, A)
        owner_near = (touch & active[:, None, :]).any(axis=2)                 # (n, A) part b has an active neighbour
        n = len(e_idx)
        lent = away & (touch[np.arange(n), a_idx] | ~owner_near)              # (n, A) parts lent to a
        return own | (lent[:, :, None] & self.parts[k]).any(axis=1)

    def patrol_moves(self, sim, memory, mask, patrolling):
        target = memory["target"]
        need = patrolling & ((target < 0) | (target == sim.pos))
        if need.any():
            e_idx, a_idx = np.nonzero(need)
            allowed = self.allowed_vertices(sim, e_idx, a_idx)                # (n, V)
            here = self.spec.free_index[sim.pos[e_idx, a_idx]]
            # highest idleness, then nearest, then a random order of the vertices drawn
            # once per step (idleness differs by >= 1, 1e-3 * dist stays below 1)
            score = sim.idle[e_idx]                                           # (n, V)
            score += self.vertex_penalty[here]                                # nearest first, never here
            score += 1e-6 * self.rng.random(score.shape[1])
            np.copyto(score, -np.inf, where=~allowed)
            best = np.argmax(score, axis=1)
            found = score[np.arange(len(best)), best] > -np.inf
            target[e_idx, a_idx] = np.where(found, self.spec.vertex_cells[best], sim.pos[e_idx, a_idx])
        target[~patrolling] = -1
        goal = np.where(patrolling, target, sim.pos)
        # inside its own part an agent keeps to the part; otherwise any station-free path
        E, A = sim.pos.shape
        k = sim.n_agents[:, None]                                             # (E, 1)
        slot = np.arange(A)[None, :]
        inside = self.part_cell[k, slot, sim.pos] & self.part_cell[k, slot, goal]   # (E, A)
        which = np.where(inside, 1 + k * A + slot, 0)
        return self.nav.toward(sim.pos, goal, mask, tables=self.tables, which=which)
