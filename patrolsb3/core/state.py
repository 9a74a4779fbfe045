"""The batched simulator state: a dataclass of arrays with leading axes (n_envs, n_agents)."""
from __future__ import annotations

import dataclasses

import numpy as np

from .config import EnvConfig
from .maps import MapSpec

# Slot status codes.
ACTIVE, SWAPPING, FAILED, ABSENT = 0, 1, 2, 3
STATUS_NAMES = ("active", "swapping", "failed", "absent")


@dataclasses.dataclass
class State:
    """State of ``E`` episodes with ``A = max_agents`` slots each.

    Slots ``n_agents[e] .. A-1`` of episode ``e`` are ABSENT for the whole episode.
    """

    pos: np.ndarray            # (E, A) int64 cell index (row * W + col); the station while swapping
    battery: np.ndarray        # (E, A) float64 battery units left
    status: np.ndarray         # (E, A) int8 ACTIVE / SWAPPING / FAILED / ABSENT
    swap_left: np.ndarray      # (E, A) int64 steps left in the current hot swap (0 if none)
    p_dyn: np.ndarray          # (E, A) float64 per-episode push probability of each slot
    messages: np.ndarray       # (E, A) int64 symbol shown this step, 0 = silent
    idle: np.ndarray           # (E, V) float64 rate-weighted idleness, 0 at t = 0 (metrics)
    visited: np.ndarray        # (E, V) bool, vertex visited since the start (else f = 1 in obs/reward)
    t: np.ndarray              # (E,) int64 steps done in the episode
    n_agents: np.ndarray       # (E,) int64 agents deployed in the episode
    rng: np.random.Generator   # one generator for the whole batch

    @property
    def n_envs(self) -> int:
        """Number of episodes E stepped together."""
        return self.pos.shape[0]

    @property
    def active(self) -> np.ndarray:
        """(E, A) bool, slots on the grid this step."""
        return self.status == ACTIVE

    def copy(self) -> "State":
        """Deep copy of the arrays (the generator is shared)."""
        return dataclasses.replace(self, **{f.name: getattr(self, f.name).copy()
                                            for f in dataclasses.fields(self) if f.name != "rng"})


def reset_state(spec: MapSpec, cfg: EnvConfig, n_agents, n_envs: int = 1, seed=None,
                rng: np.random.Generator | None = None) -> State:
    """Start ``n_envs`` episodes: agents on distinct random vertices, battery ~ U[init_battery].

    Args:
        spec: the map.
        cfg: environment parameters.
        n_agents: agents per episode, an int or a sequence of length n_envs.
        n_envs: number of episodes E.
        seed: seed of the batch's generator (ignored if ``rng`` is given).
        rng: an existing generator to draw from.

    Raises:
        ValueError: a team larger than ``max_agents`` or than the number of vertices.
    """
    rng = rng if rng is not None else np.random.default_rng(seed)
    n_agents = np.broadcast_to(np.asarray(n_agents, dtype=np.int64), (n_envs,)).copy()
    A, V = cfg.max_agents, spec.n_vertices
    if n_agents.min() < 1:
        raise ValueError(f"n_agents must be >= 1, got {n_agents.min()}")
    if n_agents.max() > A:
        raise ValueError(f"n_agents={n_agents.max()} is larger than max_agents={A}; "
                         f"raise max_agents to deploy more agents")
    if n_agents.max() > V:
        raise ValueError(f"n_agents={n_agents.max()} is larger than the {V} vertices of map "
                         f"{spec.name}; agents start on distinct vertices")
    start_vertex = np.argsort(rng.random((n_envs, V)), axis=1)[:, :A] if V >= A else \
        np.concatenate([np.argsort(rng.random((n_envs, V)), axis=1),
                        np.zeros((n_envs, A - V), dtype=np.int64)], axis=1)
    deployed = np.arange(A)[None, :] < n_agents[:, None]  # (E, A)
    pos = np.where(deployed, spec.vertex_cells[start_vertex], spec.station)
    low, high = cfg.init_battery
    battery = np.where(deployed, rng.uniform(low, high, (n_envs, A)) * cfg.b_max, cfg.b_max)
    status = np.where(deployed, ACTIVE, ABSENT).astype(np.int8)
    p_dyn = np.where(deployed, rng.uniform(0.0, cfg.p_dyn_max, (n_envs, A)), 0.0)
    idle = np.zeros((n_envs, V))
    visited = np.zeros((n_envs, V), dtype=bool)
    # the start cells count as visited at t = 0
    e_idx = np.repeat(np.arange(n_envs)[:, None], A, axis=1)
    v_at = spec.vertex_of_cell[pos]
    visited[e_idx[deployed], v_at[deployed]] = True
    return State(pos=pos.astype(np.int64), battery=battery, status=status,
                 swap_left=np.zeros((n_envs, A), dtype=np.int64), p_dyn=p_dyn,
                 messages=np.zeros((n_envs, A), dtype=np.int64), idle=idle, visited=visited,
                 t=np.zeros(n_envs, dtype=np.int64), n_agents=n_agents, rng=rng)


def reset_episodes(spec: MapSpec, cfg: EnvConfig, state: State, episodes: np.ndarray,
                   n_agents) -> None:
    """Restart some episodes of a batch in place (the others go on), drawing from the batch's
    generator: how one batched call serves parallel episodes that end at different steps.

    Args:
        spec: the map.
        cfg: environment parameters.
        state: batched state, modified in place.
        episodes: (k,) int indices of the episodes to restart.
        n_agents: agents of each restarted episode, an int or (k,).
    """
    episodes = np.asarray(episodes, dtype=np.int64)
    fresh = reset_state(spec, cfg, n_agents, n_envs=len(episodes), rng=state.rng)
    for field in dataclasses.fields(State):
        if field.name != "rng":
            getattr(state, field.name)[episodes] = getattr(fresh, field.name)
