"""``patrolsb3 bench env``: batched core and PettingZoo env speed with random valid actions."""
from __future__ import annotations

import itertools
import statistics
import time

import numpy as np

from ..core import action_mask, load_map, make_config, reset_state, step
from ..core.protocol import MOVE_PHASE
from ..env import parallel_env


def random_valid_moves(mask: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """One uniformly random valid move per slot from an (..., 5) bool mask."""
    return np.argmax(rng.random(mask.shape) * mask, axis=-1)


def core_steps_per_s(map_name="A", n_envs=1024, n_agents=5, n_steps=100, seed=0) -> float:
    """Env-steps per second of the batched core (rewards on, random valid moves)."""
    spec = load_map(map_name)
    cfg = make_config(spec.name, max_agents=n_agents, episode_steps=10**9)
    state = reset_state(spec, cfg, n_agents, n_envs=n_envs, seed=seed)
    rng = np.random.default_rng(seed)
    start = time.perf_counter()
    for _ in range(n_steps):
        step(spec, cfg, state, random_valid_moves(action_mask(spec, state), rng))
    return n_envs * n_steps / (time.perf_counter() - start)


def pettingzoo_steps_per_s(map_name="A", n_agents=5, n_steps=1000, seed=0) -> float:
    """Simulator steps per second of the PettingZoo env (message + move phase = one step).

    The agents pick uniformly random legal actions from their info's ``action_mask`` with
    random numbers drawn in advance, so that the figure is the env's time, not the sampler's
    (a legal index costs one ``flatnonzero`` per mask half)."""
    env = parallel_env(map_name, n_agents=n_agents, seed=seed)
    obs, infos = env.reset(seed=seed)
    draws = itertools.cycle(np.random.default_rng(seed).random(4099).tolist())
    sim_steps = 0
    start = time.perf_counter()
    while sim_steps < n_steps:
        actions = {}
        for agent in env.agents:
            legal_messages, legal_moves = (np.flatnonzero(m) for m in infos[agent]["action_mask"])
            actions[agent] = (int(legal_messages[int(next(draws) * len(legal_messages))]),
                              int(legal_moves[int(next(draws) * len(legal_moves))]))
        phase = infos[env.agents[0]]["phase"]
        obs, rewards, terms, truncs, infos = env.step(actions)
        sim_steps += phase == MOVE_PHASE
        if not env.agents:
            obs, infos = env.reset()
    return n_steps / (time.perf_counter() - start)


def run(repeats: int = 5, quick: bool = False) -> dict:
    """Median figures over ``repeats`` runs: the batched core (1,024 episodes x 5 agents on map
    A) and the PettingZoo env (one episode of 5 agents, and of 3: the issue's figure), learned
    messages (a simulator step is a message phase and a move phase)."""
    n_envs, n_steps, pz_steps = (64, 20, 100) if quick else (1024, 100, 1000)
    core = [core_steps_per_s(n_envs=n_envs, n_steps=n_steps, seed=r) for r in range(repeats)]
    pz = [pettingzoo_steps_per_s(n_steps=pz_steps, seed=r) for r in range(repeats)]
    pz3 = [pettingzoo_steps_per_s(n_agents=3, n_steps=pz_steps, seed=r) for r in range(repeats)]
    core_med = statistics.median(core)
    return {"core_env_steps_per_s": round(core_med), "core_agent_steps_per_s": round(core_med * 5),
            "pettingzoo_env_steps_per_s": round(statistics.median(pz)),
            "pettingzoo_env_steps_per_s_3_agents": round(statistics.median(pz3)),
            "n_envs": n_envs, "n_agents": 5, "map": "A", "repeats": repeats}
