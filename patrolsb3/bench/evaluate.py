"""``patrolsb3 bench evaluate``: env-steps per second of each heuristic on the batched core
(5 agents, map A, 1,000 episodes in one batch; policy + step + metrics, as in evaluation)."""
from __future__ import annotations

import statistics
import time

from ..core import load_map, make_config, reset_state, step
from ..core.metrics import EpisodeMetrics
from ..strategies import get, names


def strategy_steps_per_s(name: str, map_name="A", n_envs=1000, n_agents=5, n_steps=300,
                         warmup=20, seed=0) -> float:
    """Env-steps per second of one heuristic over ``n_steps`` steps after ``warmup`` steps."""
    spec = load_map(map_name)
    cfg = make_config(spec.name, max_agents=n_agents, episode_steps=10**9)
    policy = get(name, spec, n_agents, cfg=cfg, seed=seed)
    sim = reset_state(spec, cfg, n_agents, n_envs=n_envs, seed=seed)
    metrics = EpisodeMetrics(n_envs, spec.n_vertices)
    memory = None
    for i in range(warmup + n_steps):
        if i == warmup:
            start = time.perf_counter()
        actions, memory = policy.predict(sim, memory)
        info = step(spec, cfg, sim, actions[..., 1], messages=actions[..., 0], compute_reward=False)
        metrics.update(sim, info)
    return n_envs * n_steps / (time.perf_counter() - start)


def run(repeats: int = 5, quick: bool = False) -> dict:
    """Median env-steps/s per heuristic over ``repeats`` runs."""
    n_envs, n_steps = (64, 20) if quick else (1000, 300)
    out = {}
    for name in names():
        runs = [strategy_steps_per_s(name, n_envs=n_envs, n_steps=n_steps, seed=r) for r in range(repeats)]
        out[name] = round(statistics.median(runs))
    out.update({"n_envs": n_envs, "n_agents": 5, "map": "A", "steps": n_steps, "repeats": repeats})
    return out
