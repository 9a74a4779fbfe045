"""The batched simulator state: a dataclass of arrays with leading axes (n_envs, n_agents)."""
from __future__ import annotations

import dataclasses

import numpy as np

from .config import EnvConfig
from .maps import MapSpec
from .streams import EpisodeStreams

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
    streams: EpisodeStreams    # each episode's random streams (core/streams.py)

    @property
    def n_envs(self) -> int:
        """Number of episodes E stepped together."""
        return self.pos.shape[0]

    @property
    def active(self) -> np.ndarray:
        """(E, A) bool, slots on the grid this step."""
        return self.status == ACTIVE

    def copy(self) -> "State":
        """Deep copy of the arrays (the random streams are shared)."""
        return dataclasses.replace(self, **{f.name: getattr(self, f.name).copy()
                                            for f in dataclasses.fields(self) if f.name != "streams"})


def reset_state(spec: MapSpec, cfg: EnvConfig, n_agents, n_envs: int = 1, seed=None,
                rng: np.random.Generator | None = None, episode_ids=None) -> State:
    """Start ``n_envs`` episodes: agents on distinct random vertices, battery ~ U[init_battery].

    Each episode draws from streams of its own (:mod:`patrolsb3.core.streams`), set by the seed
    and its id: episode ``i`` of seed ``s`` starts, and meets wind, drains, swap times and faults,
    alike whatever its team, its strategy or the other episodes of the batch.

    Args:
        spec: the map.
        cfg: environment parameters.
        n_agents: agents per episode, an int or a sequence of length n_envs.
        n_envs: number of episodes E.
        seed: the batch's seed (None: fresh entropy; ignored if ``rng`` is given).
        rng: a generator that draws the batch's seed instead (the training env's, which resets
            again and again from one seed).
        episode_ids: (E,) int, each episode's id (default 0 .. E-1); give the same id to the
            episodes that must be paired, e.g. episode j of every team size.

    Raises:
        ValueError: a team larger than ``max_agents`` or than the number of vertices, or
            ``episode_ids`` of another length than ``n_envs``.
    """
    if rng is not None:
        seed = int(rng.integers(2 ** 63))
    ids = np.arange(n_envs) if episode_ids is None else np.asarray(episode_ids, dtype=np.int64)
    if ids.shape != (n_envs,):
        raise ValueError(f"episode_ids: one id per episode, {n_envs} of them; got shape {ids.shape}")
    streams = EpisodeStreams(seed, ids, cfg.max_agents)
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
    fields = _start(spec, cfg, n_agents, *streams.starts(V))
    return State(**fields, streams=streams)


def _start(spec: MapSpec, cfg: EnvConfig, n_agents: np.ndarray, vertex_keys: np.ndarray,
           battery_draws: np.ndarray, push_draws: np.ndarray) -> dict:
    """The arrays of episodes at their start, from their start draws (k, V), (k, A), (k, A)."""
    n_envs, (A, V) = len(n_agents), (cfg.max_agents, spec.n_vertices)
    order = np.argsort(vertex_keys, axis=1)                                   # (k, V) a random order
    start_vertex = order[:, :A] if V >= A else \
        np.concatenate([order, np.zeros((n_envs, A - V), dtype=np.int64)], axis=1)
    deployed = np.arange(A)[None, :] < n_agents[:, None]  # (E, A)
    pos = np.where(deployed, spec.vertex_cells[start_vertex], spec.station)
    low, high = cfg.init_battery
    battery = np.where(deployed, (low + battery_draws * (high - low)) * cfg.b_max, cfg.b_max)
    status = np.where(deployed, ACTIVE, ABSENT).astype(np.int8)
    p_dyn = np.where(deployed, push_draws * cfg.p_dyn_max, 0.0)
    idle = np.zeros((n_envs, V))
    visited = np.zeros((n_envs, V), dtype=bool)
    # the start cells count as visited at t = 0
    e_idx = np.repeat(np.arange(n_envs)[:, None], A, axis=1)
    v_at = spec.vertex_of_cell[pos]
    visited[e_idx[deployed], v_at[deployed]] = True
    return dict(pos=pos.astype(np.int64), battery=battery, status=status,
                swap_left=np.zeros((n_envs, A), dtype=np.int64), p_dyn=p_dyn,
                messages=np.zeros((n_envs, A), dtype=np.int64), idle=idle, visited=visited,
                t=np.zeros(n_envs, dtype=np.int64), n_agents=n_agents)


def reset_episodes(spec: MapSpec, cfg: EnvConfig, state: State, episodes: np.ndarray,
                   n_agents) -> None:
    """Restart some episodes of a batch in place (the others go on), each a new episode with
    streams of its own: how one batched call serves parallel episodes that end at different steps.

    Args:
        spec: the map.
        cfg: environment parameters.
        state: batched state, modified in place.
        episodes: (k,) int indices of the episodes to restart.
        n_agents: agents of each restarted episode, an int or (k,).
    """
    episodes = np.asarray(episodes, dtype=np.int64)
    n_agents = np.broadcast_to(np.asarray(n_agents, dtype=np.int64), (len(episodes),)).copy()
    state.streams.restart(episodes)
    fresh = _start(spec, cfg, n_agents, *state.streams.starts(spec.n_vertices, rows=episodes))
    for name, values in fresh.items():
        getattr(state, name)[episodes] = values
