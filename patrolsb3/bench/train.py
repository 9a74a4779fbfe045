"""``patrolsb3 bench train``: training speed of the default config (MaskableRecurrentPPO on map
A, 8 parallel episodes at the last curriculum stage 1,1,1,1,2,3,4,5, paper network).

``agent_steps_per_s`` counts vec-env rows (8 episodes x 5 slots) x env steps, as SB3's
``num_timesteps`` does; ``deployed_agent_sim_steps_per_s`` is the same time counted in
simulator steps of deployed agents only (19 of the 40 rows, one of the two phases). The wall time of a short ``learn()`` is split into ``env_s`` (inside
``env.step``), ``forward_s`` (policy forward passes during collection) and ``update_s``
(``train()``: the PPO epochs); the rest (masks, buffer, callbacks) is ``other_s``.
"""
from __future__ import annotations

import statistics
import time


def _timed(fn, timers: dict, key: str):
    def wrapper(*args, **kwargs):
        start = time.perf_counter()
        try:
            return fn(*args, **kwargs)
        finally:
            timers[key] += time.perf_counter() - start
    return wrapper


def measure(n_rollouts: int = 2, n_steps: int | None = None, seed: int = 0, overrides: dict | None = None) -> dict:
    """One instrumented ``learn()`` of ``n_rollouts`` rollouts with the default hyperparameters.

    Args:
        n_rollouts: rollouts (collection + update) to time.
        n_steps: env steps per row per rollout (default: the hyperparameters').
        seed: seed of env and model.
        overrides: hyperparameter overrides (e.g. {"n_minibatches": 10}).

    Returns:
        Seconds of env, forward, update, other and total, and agent-steps per second.
    """
    import torch

    from ..sb3.algorithms import get_algorithm
    from ..sb3.hyperparams import merge
    from ..sb3.train import algorithm_kwargs, resolve_hyperparams
    from ..sb3.vec_env import DEFAULT_AGENTS, make_vec_env

    hp = resolve_hyperparams("A", overrides=merge(overrides or {}, {"n_steps": n_steps} if n_steps else {}))
    torch.set_num_threads(int(hp.get("torch_threads", 1)))
    spec = get_algorithm(hp["algo"])
    cls, policy_cls = spec.classes()
    vec_env = make_vec_env("A", agents=DEFAULT_AGENTS, variant="rl-msg", seed=seed, strict=spec.masked,
                           **(hp.get("env") or {}))
    rows = vec_env.num_envs
    model = cls(policy_cls, vec_env, seed=seed, device="cpu",
                **algorithm_kwargs(hp, spec, vec_env.layout, vec_env.phases_per_step, rows))
    timers = {"env_s": 0.0, "forward_s": 0.0, "update_s": 0.0}
    vec_env.step = _timed(vec_env.step, timers, "env_s")
    model.policy.forward = _timed(model.policy.forward, timers, "forward_s")
    model.train = _timed(model.train, timers, "update_s")
    start = time.perf_counter()
    model.learn(n_rollouts * model.n_steps * rows)
    total = time.perf_counter() - start
    vec_env.close()
    out = {k: round(v, 3) for k, v in timers.items()}
    out["other_s"] = round(total - sum(timers.values()), 3)
    out["total_s"] = round(total, 3)
    out["agent_steps"] = int(model.num_timesteps)
    out["agent_steps_per_s"] = model.num_timesteps / total
    # the same time in simulator steps of deployed agents (no padded slots, no message phases)
    deployed = sum(DEFAULT_AGENTS) / rows
    out["deployed_agent_sim_steps_per_s"] = round(out["agent_steps_per_s"] * deployed / vec_env.phases_per_step)
    out["batch_size"] = int(model.batch_size)
    out["n_steps"] = int(model.n_steps)
    return out


def run(repeats: int = 5, quick: bool = False) -> dict:
    """The median run (by agent_steps_per_s) of ``repeats`` measurements; ``quick``: one short
    rollout of 32 env steps."""
    runs = [measure(n_rollouts=1, n_steps=32, seed=r) if quick else measure(seed=r) for r in range(repeats)]
    median = statistics.median(r["agent_steps_per_s"] for r in runs)
    best = min(runs, key=lambda r: abs(r["agent_steps_per_s"] - median))
    best["agent_steps_per_s"] = round(best["agent_steps_per_s"])
    best.update({"algo": "MaskableRecurrentPPO", "map": "A", "rows": 40, "repeats": repeats})
    return best
