"""What every heuristic shares: SB3's ``predict()`` on the batched simulator state, the
per-episode memory carried in the ``state`` argument, the recharge planner and the
deadlock rule.

``predict(observation, state=None, episode_start=None, deterministic=True)``:

* ``observation`` is the batched simulator :class:`patrolsb3.core.State` itself (E episodes,
  A = max_agents slots). A heuristic reads positions, statuses, batteries, the team size of
  each episode (``n_agents``) and the shared idleness ``idle`` from it; CR only uses its own
  visits (it keeps its own memory), SEBS the shared idleness, PART its own part's idleness.
* ``state`` is the policy's memory, a dict of arrays with leading axis E (None at the first
  call); it is returned updated, like an SB3 recurrent state. Rows where ``episode_start``
  (E,) is True are reset.
* The returned actions are (E, A, 2) int64: (message symbol, 0 for heuristics; move 0..4).
  Moves are always valid under ``core.masks.action_mask``; inactive slots stay.
"""
from __future__ import annotations

import numpy as np

from ..core.config import EnvConfig, make_config
from ..core.maps import STAY, MapSpec, load_map
from ..core.masks import action_mask
from ..core.state import ACTIVE, State
from .navigation import Navigator
from .recharge import HOME_PATIENCE, PATROL_PATIENCE, RechargePlanner


class HeuristicPolicy:
    """Base class of the batched heuristics.

    Subclasses implement :meth:`patrol_moves` (and :meth:`init_memory` for their own memory).

    Args:
        spec: the map (a :class:`MapSpec` or a map name).
        n_agents: the team size the strategy prepares for (PART builds its parts for every
            size up to ``max(n_agents, cfg.max_agents)``; the actual size of each episode is
            read from the state).
        cfg: environment parameters (default: the map's defaults with enough slots).
        seed: seed of the strategy's own random draws (ties, moves aside).
    """

    name = "BASE"

    def __init__(self, spec, n_agents: int, cfg: EnvConfig | None = None, seed: int = 0):
        self.spec: MapSpec = load_map(spec)
        self.cfg = cfg if cfg is not None else make_config(self.spec.name)
        if n_agents < 1 or n_agents > self.cfg.max_agents:
            raise ValueError(f"team of {n_agents} agents does not fit max_agents={self.cfg.max_agents}")
        self.n_agents = int(n_agents)
        self.rng = np.random.default_rng(seed)
        self.nav = Navigator(self.spec, self.rng)
        self.recharge = RechargePlanner(self.spec, self.cfg)

    # -- memory -----------------------------------------------------------------------------
    def init_memory(self, sim: State) -> dict:
        """Fresh memory for every episode of ``sim`` (arrays with leading axis E)."""
        E, A = sim.pos.shape
        return {"returning": np.zeros((E, A), dtype=bool),   # (E, A) heading for a station
                "blocked": np.zeros((E, A), dtype=np.int64)}  # (E, A) stuck steps in a row

    def _memory(self, sim: State, state, episode_start) -> dict:
        if state is None or state["returning"].shape != sim.pos.shape:
            return self.init_memory(sim)
        if episode_start is not None:
            rows = np.asarray(episode_start, dtype=bool)
            if rows.any():
                fresh = self.init_memory(sim)
                for key, value in fresh.items():
                    state[key][rows] = value[rows]
        return state

    # -- acting -----------------------------------------------------------------------------
    def patrol_moves(self, sim: State, memory: dict, mask: np.ndarray, patrolling: np.ndarray):
        """Moves of the patrolling (active, not heading home) slots.

        Args:
            sim: the batched simulator state.
            memory: the policy memory (may be updated in place).
            mask: (E, A, 5) valid moves.
            patrolling: (E, A) bool, slots to decide for.

        Returns:
            moves (E, A) int64 (valid under ``mask``) and stuck (E, A) bool.
        """
        raise NotImplementedError

    def predict(self, observation: State, state=None, episode_start=None, deterministic=True):
        """Act for every slot of a batch of episodes (SB3's PolicyPredictor signature).

        Args:
            observation: the batched simulator ``State``.
            state: memory returned by the previous call, or None.
            episode_start: (E,) bool, episodes just reset (their memory is cleared).
            deterministic: unused (heuristics break ties at random either way).

        Returns:
            actions (E, A, 2) int64 (message 0, move) and the memory to pass back.
        """
        sim = observation
        if sim.idle.shape[1] != self.spec.n_vertices or sim.pos.shape[1] != self.cfg.max_agents:
            raise ValueError(f"{type(self).__name__} was built for map {self.spec.name} ({self.spec.n_vertices} vertices, "
                             f"{self.cfg.max_agents} slots); this state has {sim.idle.shape[1]} vertices and "
                             f"{sim.pos.shape[1]} slots: build the heuristic with the env's map and config")
        memory = self._memory(sim, state, episode_start)
        mask = action_mask(self.spec, sim)                                     # (E, A, 5)
        active = sim.status == ACTIVE
        returning = self.recharge.update(sim, memory["returning"])            # (E, A)
        moves, stuck = self.patrol_moves(sim, memory, mask, active & ~returning)
        if returning.any():
            home, home_stuck = self.recharge.moves(self.nav, sim, mask)
            moves = np.where(returning, home, moves)
            stuck = np.where(returning, home_stuck, stuck)
            give_way = self.recharge.give_way(self.nav, sim, returning, home_stuck, mask)
            if give_way.any():   # right of way for agents heading home
                moves = np.where(give_way, self.nav.retreat_moves(sim.pos, mask), moves)
                stuck = stuck & ~give_way
        leaving = active & ~returning & self.recharge.is_station[sim.pos]
        if leaving.any():   # station exit rule: let agents heading home in first
            moves = np.where(leaving & self.recharge.home_traffic(sim, returning)[:, None], STAY, moves)
        patience = np.where(returning, HOME_PATIENCE, PATROL_PATIENCE)
        moves = self.nav.unblock(moves, stuck & active, memory["blocked"], patience, sim.pos, mask)
        moves = np.where(active, moves, STAY)
        actions = np.zeros(moves.shape + (2,), dtype=np.int64)
        actions[..., 1] = moves
        return actions, memory
