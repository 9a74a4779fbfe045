"""RANDOM: the floor. Each patrolling agent takes a uniformly random valid move (Stay
included, never onto a station); the shared recharge planner brings it home."""
from __future__ import annotations

import numpy as np

from .base import HeuristicPolicy


class RandomPolicy(HeuristicPolicy):
    """Uniform random valid move per agent and step (see module docstring)."""

    name = "RANDOM"

    def patrol_moves(self, sim, memory, mask, patrolling):
        moves = self.nav.random_moves(sim.pos, mask, include_stay=True)
        return moves, np.zeros(moves.shape, dtype=bool)
