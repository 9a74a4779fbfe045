"""The random streams of a batch of episodes: what chance decides, drawn per episode so that
episodes can be paired.

Every episode of a batch has streams of its own, derived from the batch's seed and the
episode's id (numpy ``SeedSequence`` spawn keys), never from its position in the batch:

- **start** (key ``(id, 0)``): the agents' start vertices, starting batteries and push
  probabilities, drawn once for :data:`STREAM_SLOTS` slots (or ``max_agents`` if more);
- **world** (key ``(id, 1)``): what the environment does each step, for every slot whether it
  is deployed, acting or not: whether a push happens and its direction, the battery drain, the
  hot-swap time, a chance fault and the order of scheduled faults (:data:`WORLD_DRAWS` uniforms
  per slot per step);
- **tie-breaks** (key ``(id, 2)``): who wins a contested cell, one uniform per slot per step.

So episode ``i`` of seed ``s`` meets the same starts, wind, drains, swap times and faults under
every strategy and team size (the first ``n`` slots of an ``n``-agent team), whichever other
episodes share its batch: comparisons between strategies are paired by episode. What the agents
do changes only which draws matter, never which values are drawn. Policies and heuristics draw
from generators of their own.

Each stream is read ahead in blocks of :data:`BLOCK` steps (one numpy call per episode per
block); numpy fills a block in the same order as step-by-step calls, so the values do not depend
on the block size.
"""
from __future__ import annotations

import numpy as np

STREAMS_VERSION = "per-episode-1"
"""Which draws an episode meets: results evaluated under other streams (before this module, one
generator for the whole batch) are not reused for, nor paired with, these."""
STREAM_SLOTS = 16
"""Slots drawn for per step and at the start, whatever ``max_agents`` (more if it is larger), so
that slot ``j`` draws alike in a 5-slot evaluation and a 12-slot model's."""
WORLD_DRAWS = 6
"""Uniforms per slot per step in the world stream, in this order: push, push direction, drain,
swap time, chance fault, scheduled-fault order (:class:`StepDraws`)."""
BLOCK = 64
"""Steps read ahead per call."""
START, WORLD, TIE_BREAK = 0, 1, 2
"""The second element of each stream's spawn key."""


class StepDraws:
    """One step's uniforms for every slot of every episode.

    Attributes:
        world: (E, A, WORLD_DRAWS) float64 in [0, 1), the world stream's.
        tie_break: (E, A) float64 in [0, 1), the tie-break stream's.
    """

    def __init__(self, world: np.ndarray, tie_break: np.ndarray):
        self.world = world
        self.tie_break = tie_break

    @property
    def push(self) -> np.ndarray:
        """(E, A) uniforms compared with each slot's push probability."""
        return self.world[..., 0]

    def push_direction(self) -> np.ndarray:
        """(E, A) int64 in 0..3."""
        return np.minimum((self.world[..., 1] * 4).astype(np.int64), 3)

    def drain(self, low: float, high: float) -> np.ndarray:
        """(E, A) battery drain, uniform in [low, high)."""
        return low + self.world[..., 2] * (high - low)

    def swap_time(self, low: int, high: int) -> np.ndarray:
        """(E, A) int64 hot-swap steps, uniform in low..high."""
        return np.minimum(low + (self.world[..., 3] * (high - low + 1)).astype(np.int64), high)

    @property
    def chance_fault(self) -> np.ndarray:
        """(E, A) uniforms compared with the fault probability."""
        return self.world[..., 4]

    @property
    def fault_order(self) -> np.ndarray:
        """(E, A) uniforms ranking the slots for a scheduled fault (lowest first)."""
        return self.world[..., 5]


class EpisodeStreams:
    """The start, world and tie-break streams of each episode of a batch (module docstring).

    Args:
        entropy: the batch's seed (an int), or None for fresh entropy.
        episode_ids: (E,) int, each episode's id; episodes with the same seed and id draw the same.
        n_slots: slots per episode (``max_agents``); :data:`STREAM_SLOTS` or more are drawn for.
    """

    def __init__(self, entropy, episode_ids, n_slots: int):
        self.entropy = np.random.SeedSequence(entropy).entropy
        self.ids = np.asarray(episode_ids, dtype=np.int64).copy()           # (E,)
        self.n_slots = int(n_slots)
        self.drawn_slots = max(self.n_slots, STREAM_SLOTS)
        E, A = len(self.ids), self.n_slots
        self._world = [self._generator(i, WORLD) for i in self.ids]
        self._ties = [self._generator(i, TIE_BREAK) for i in self.ids]
        self._world_block = np.empty((BLOCK, E, A, WORLD_DRAWS))               # (BLOCK, E, A, W) slots in use
        self._tie_block = np.empty((BLOCK, E, A))                              # (BLOCK, E, A)
        self._next = BLOCK                                                     # step of the block to read

    def _generator(self, episode_id: int, stream: int) -> np.random.Generator:
        return np.random.default_rng(np.random.SeedSequence(self.entropy, spawn_key=(int(episode_id), stream)))

    def starts(self, n_vertices: int, rows=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The start draws of some episodes (all by default): uniforms (k, V) ranking the start
        vertices, (k, A) for the starting battery and (k, A) for the push probability."""
        ids = self.ids if rows is None else self.ids[np.asarray(rows)]
        V, A, S = n_vertices, self.n_slots, self.drawn_slots
        draws = [self._generator(i, START).random(V + 2 * S) for i in ids]
        block = np.array(draws).reshape(len(ids), -1)                           # (k, V + 2S)
        return block[:, :V], block[:, V:V + A], block[:, V + S:V + S + A]

    def step(self) -> StepDraws:
        """The next step's draws of every episode."""
        if self._next == BLOCK:
            for e in range(len(self.ids)):
                self._fill(e, 0)
            self._next = 0
        t = self._next
        self._next += 1
        return StepDraws(self._world_block[t], self._tie_block[t])

    def _fill(self, e: int, start: int) -> None:
        steps, A = BLOCK - start, self.n_slots        # every drawn slot is drawn; the ones in use kept
        self._world_block[start:, e] = self._world[e].random((steps, self.drawn_slots, WORLD_DRAWS))[:, :A]
        self._tie_block[start:, e] = self._ties[e].random((steps, self.drawn_slots))[:, :A]

    def restart(self, rows) -> None:
        """New episodes in ``rows`` (a parallel episode of training that ended): each takes the
        next unused id (its id + E) and fresh streams from the next step on."""
        E = len(self.ids)
        for e in np.asarray(rows, dtype=np.int64):
            self.ids[e] += E
            self._world[e] = self._generator(self.ids[e], WORLD)
            self._ties[e] = self._generator(self.ids[e], TIE_BREAK)
            if self._next < BLOCK:
                self._fill(int(e), self._next)
