"""``patrolsb3 bench train``: training speed of the default config (MaskableRecurrentPPO on map
A, 8 parallel episodes at the last curriculum stage 1,1,1,1,2,3,4,5, paper network).

Three counts of the same wall time:

* ``agent_steps_per_s``: vec-env rows (8 episodes x 5 slots) x env steps, as SB3's
  ``num_timesteps`` counts them (padded slots and message phases included);
* ``deployed_agent_sim_steps_per_s``: simulator steps of deployed agents (18 of the 40 rows,
  one per simulator step whatever the phases);
* ``useful_decisions_per_s``: rows with more than one legal (message, move) action, the
  decisions a policy gradient can learn from.

The wall time of a short ``learn()`` is split into ``env_s`` (inside ``env.step``),
``forward_s`` (policy forward passes during collection) and ``update_s`` (``train()``: the PPO
epochs); the rest (masks, buffer, callbacks) is ``other_s``. Figures are printed for
``torch_threads`` 1 (the default) and 2, with the training precision (``--precision``), the
CPU's name and whether it computes bf16 natively.
"""
from __future__ import annotations

import statistics
import time

import numpy as np


def _timed(fn, timers: dict, key: str):
    def wrapper(*args, **kwargs):
        start = time.perf_counter()
        try:
            return fn(*args, **kwargs)
        finally:
            timers[key] += time.perf_counter() - start
    return wrapper


def _useful(masks: np.ndarray, nvec) -> int:
    """Rows of (n, sum(nvec)) masks with more than one legal composite action."""
    bounds = np.concatenate([[0], np.cumsum(nvec)])
    choices = np.prod([masks[:, a:b].sum(axis=1) for a, b in zip(bounds[:-1], bounds[1:])], axis=0)
    return int((choices > 1).sum())


def measure(n_rollouts: int = 2, n_steps: int | None = None, seed: int = 0, overrides: dict | None = None,
            device: str = "cpu") -> dict:
    """One instrumented ``learn()`` of ``n_rollouts`` rollouts with the default hyperparameters.

    Args:
        n_rollouts: rollouts (collection + update) to time.
        n_steps: env steps per row per rollout (default: the hyperparameters').
        seed: seed of env and model.
        overrides: hyperparameter overrides (e.g. {"batch_size": 512, "torch_threads": 2}).
        device: "auto", "cpu" or "cuda".

    Returns:
        Seconds of env, forward, update, other and total, and the three speeds (module docstring).
    """
    import torch

    from ..sb3.algorithms import get_algorithm, torch_device
    from ..sb3.hyperparams import merge
    from ..sb3.precision import resolve_precision
    from ..sb3.train import algorithm_kwargs, resolve_hyperparams
    from ..sb3.vec_env import DEFAULT_AGENTS, make_vec_env

    device = torch_device(device)
    hp = resolve_hyperparams("A", overrides=merge(overrides or {}, {"n_steps": n_steps} if n_steps else {}))
    torch.set_num_threads(int(hp.get("torch_threads", 1)))
    spec = get_algorithm(hp["algo"])
    cls, policy_cls = spec.classes()
    vec_env = make_vec_env("A", agents=DEFAULT_AGENTS, variant="rl-msg", seed=seed, strict=spec.masked,
                           **(hp.get("env") or {}))
    rows = vec_env.num_envs
    model = cls(policy_cls, vec_env, seed=seed, device=device,
                **algorithm_kwargs(hp, spec, vec_env.layout, vec_env.phases_per_step, rows))
    model.policy.precision = resolve_precision(hp.get("precision", "auto"), model.device.type)
    timers = {"env_s": 0.0, "forward_s": 0.0, "update_s": 0.0}
    counts = {"useful": 0}
    step = vec_env.step

    def counted_step(actions):
        counts["useful"] += _useful(vec_env.action_masks(), vec_env.action_space.nvec)
        return step(actions)

    vec_env.step = _timed(counted_step, timers, "env_s")
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
    out["useful_decisions_per_s"] = round(counts["useful"] / total)
    out["batch_size"] = int(model.update_batch_size()) if hasattr(model, "update_batch_size") else int(model.batch_size)
    out["n_steps"] = int(model.n_steps)
    out["torch_threads"] = int(hp.get("torch_threads", 1))
    out["device"] = str(model.device)
    out["precision"] = model.policy.precision
    return out


def _median_run(runs: list[dict]) -> dict:
    median = statistics.median(r["agent_steps_per_s"] for r in runs)
    best = dict(min(runs, key=lambda r: abs(r["agent_steps_per_s"] - median)))
    best["agent_steps_per_s"] = round(best["agent_steps_per_s"])
    return best


def run(repeats: int = 5, quick: bool = False, device: str = "cpu", threads=(1, 2),
        overrides: dict | None = None) -> dict:
    """The median run (by agent_steps_per_s) of ``repeats`` measurements, for each number of
    torch threads; ``quick``: one short rollout of 32 env steps.

    Returns:
        The figures of the first thread count, and ``threads_<k>`` entries with the others'.
    """
    from ..sb3.precision import cpu_info
    out = {}
    for k in threads:
        hp = {**(overrides or {}), "torch_threads": int(k)}
        runs = [measure(n_rollouts=1, n_steps=32, seed=r, overrides=hp, device=device) if quick
                else measure(seed=r, overrides=hp, device=device) for r in range(repeats)]
        best = _median_run(runs)
        if not out:
            out = best
            out.update({"algo": "MaskableRecurrentPPO", "map": "A", "rows": 40, "repeats": repeats,
                        "cpu": cpu_info()["name"], "cpu_native_bf16": cpu_info()["native_bf16"]})
        else:
            out[f"threads_{k}"] = {key: best[key] for key in ("agent_steps_per_s", "deployed_agent_sim_steps_per_s",
                                                              "useful_decisions_per_s", "update_s", "total_s")}
    return out
