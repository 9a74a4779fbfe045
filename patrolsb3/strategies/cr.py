"""CR, conscientious reactive (Machado et al. 2002).

Rule: each agent moves to the neighbouring vertex with the highest idleness *as it
remembers it* — the time since it itself last stood there (or since the start), times the
vertex's rate ``1 + priority`` — ties at random. No communication: visits by other agents
are unknown to it. Only valid moves count (the core's action mask); a station is never a
patrol move (entering it starts a swap). If no neighbouring vertex is valid, it stays. The
recharge rule and the deadlock rule are the shared ones (:mod:`.recharge`).
"""
from __future__ import annotations

import numpy as np

from ..core.maps import STAY
from .base import HeuristicPolicy


def remembered_idleness(last_visit: np.ndarray, t: np.ndarray, rate: np.ndarray) -> np.ndarray:
    """Idleness an agent believes each vertex has.

    Args:
        last_visit: (E, A, V) step of the agent's own last visit (0 = the start).
        t: (E,) current step.
        rate: (V,) idleness growth per step.

    Returns:
        (E, A, V) float64.
    """
    return (t[:, None, None] - last_visit) * rate


class CRPolicy(HeuristicPolicy):
    """Conscientious reactive patrolling (see module docstring)."""

    name = "CR"

    def init_memory(self, sim):
        memory = super().init_memory(sim)
        E, A = sim.pos.shape
        memory["last_visit"] = np.zeros((E, A, self.spec.n_vertices), dtype=np.int64)  # (E, A, V)
        return memory

    def patrol_moves(self, sim, memory, mask, patrolling):
        spec = self.spec
        last = memory["last_visit"]                                           # (E, A, V)
        E, A = sim.pos.shape
        t = sim.t
        here = spec.vertex_of_cell[sim.pos]                                    # (E, A)
        seen = patrolling & (here >= 0)
        e_idx, a_idx = np.nonzero(seen)
        last[e_idx, a_idx, here[seen]] = t[e_idx]
        nb_vertex = spec.vertex_of_cell[spec.neighbour[sim.pos]]               # (E, A, 5)
        ok = mask & (nb_vertex >= 0)
        ok[..., STAY] = False
        v = np.maximum(nb_vertex, 0)
        believed = ((t[:, None, None] - np.take_along_axis(last, v, axis=2)) * spec.rate[v])
        score = np.where(ok, believed + 0.5 * self.rng.random(ok.shape), -np.inf)  # (E, A, 5)
        moves = np.argmax(score, axis=-1)
        moves = np.where(ok.any(axis=-1), moves, STAY)
        return moves, np.zeros((E, A), dtype=bool)
