"""SEBS, State Exchange Bayesian Strategy (Portugal & Rocha 2013, as in patrolling_sim).

Agents share their visits (they all read the true, rate-weighted idleness ``state.idle``)
and announce the vertex they head for next. For each neighbouring vertex v_i (a valid move,
never a station) of agent k:

* gain ``g_i = I(v_i) / max(cost_i, 1)`` with ``cost_i = 1`` (one grid step);
* ``P_i = G1 exp(ln(1/G1) g_i / G2)`` if ``g_i < G2`` else 1, with ``G1 = 0.1`` and
  ``G2 = max_v rate(v) * |V|`` — the idleness a top-priority vertex reaches when one agent
  needs a whole sweep of the map to come back to it (map-scaled; large enough that gains
  rarely saturate at P = 1, where the choice would turn random);
* if ``n_i > 0`` other agents announced v_i as their next vertex,
  ``P_i <- P_i 2^(R - n_i) / (2^R - 1)`` with R the team size of the episode;
* the agent takes the argmax, ties at random, and announces that vertex.

Announcements within a step: slots decide in order 0, 1, ...; each sees what the slots before
it announced this step (the others are still standing on the vertex they announced last).
Recharge and deadlock rules: the shared ones (:mod:`.recharge`).
"""
from __future__ import annotations

import numpy as np

from ..core.maps import STAY
from .base import HeuristicPolicy

G1 = 0.1
"""SEBS's probability of a zero gain."""


def sebs_g2(spec) -> float:
    """The map-scaled constant G2 = max rate * |V| (see module docstring)."""
    return float(spec.rate.max() * spec.n_vertices)


def sebs_probability(gain: np.ndarray, g1: float, g2: float) -> np.ndarray:
    """P(move | g) = g1 exp(ln(1/g1) g / g2) for g < g2, else 1."""
    gain = np.asarray(gain, dtype=np.float64)
    return np.where(gain < g2, g1 * np.exp(np.log(1.0 / g1) * gain / g2), 1.0)


def intention_discount(n_intents: np.ndarray, team: np.ndarray) -> np.ndarray:
    """Factor 2^(R - n) / (2^R - 1) where n > 0 agents announced the vertex, else 1."""
    n = np.asarray(n_intents, dtype=np.float64)
    r = np.asarray(team, dtype=np.float64)
    return np.where(n > 0, 2.0 ** (r - n) / np.maximum(2.0 ** r - 1.0, 1.0), 1.0)


class SEBSPolicy(HeuristicPolicy):
    """State Exchange Bayesian Strategy (see module docstring)."""

    name = "SEBS"

    def __init__(self, spec, n_agents, cfg=None, seed=0):
        super().__init__(spec, n_agents, cfg, seed)
        self.g1 = G1
        self.g2 = sebs_g2(self.spec)

    def patrol_moves(self, sim, memory, mask, patrolling):
        spec = self.spec
        E, A = sim.pos.shape
        nb_cell = spec.neighbour[sim.pos]                                     # (E, A, 5)
        nb_vertex = spec.vertex_of_cell[nb_cell]                               # (E, A, 5)
        ok = mask & (nb_vertex >= 0)
        ok[..., STAY] = False
        gain = np.take_along_axis(sim.idle, np.maximum(nb_vertex, 0).reshape(E, -1),
                                  axis=1).reshape(E, A, 5)                     # (E, A, 5) cost 1
        prob = sebs_probability(gain, self.g1, self.g2)                        # (E, A, 5)
        team = sim.n_agents                                                    # (E,)
        intent = np.full((E, A), -1, dtype=np.int64)                           # (E, A) announced cell
        moves = np.full((E, A), STAY, dtype=np.int64)
        noise = self.rng.random((E, A, 5)) * 1e-9
        for a in range(A):
            if not patrolling[:, a].any():
                continue
            n_i = (nb_cell[:, a, :, None] == intent[:, None, :]).sum(axis=2)  # (E, 5)
            p = prob[:, a] * intention_discount(n_i, team[:, None])
            score = np.where(ok[:, a], p + noise[:, a], -np.inf)
            choice = np.where(ok[:, a].any(axis=1), np.argmax(score, axis=1), STAY)
            choice = np.where(patrolling[:, a], choice, STAY)
            moves[:, a] = choice
            intent[:, a] = np.where(patrolling[:, a] & (choice != STAY),
                                    nb_cell[np.arange(E), a, choice], -1)
        return moves, np.zeros((E, A), dtype=bool)
