"""Evaluation of a trained policy on the paper's metrics, keeping the LSTM state.

sb3-contrib's maskable ``evaluate_policy`` drops the recurrent state and its recurrent
counterpart ignores masks; this loop does both: masks from the env at every step, the LSTM
state carried from step to step and reset by ``episode_start``. Metrics come from the
``team_episode`` info of :func:`patrolsb3.sb3.make_vec_env` at each episode's end.
"""
from __future__ import annotations

import inspect

import numpy as np

METRICS = ("reward", "mean_idleness", "max_idleness", "collisions", "battery_failures")
"""Per-episode figures averaged by :func:`summarize` (keys of ``team_episode``)."""


class RandomMaskedPolicy:
    """The RANDOM floor: a uniformly random legal (message, move), SB3's predict() protocol.

    Args:
        action_dims: sizes of the MultiDiscrete action, e.g. (16, 5).
        seed: seed of the generator.
    """

    def __init__(self, action_dims=(16, 5), seed: int | None = 0):
        self.action_dims = tuple(int(d) for d in action_dims)
        self.rng = np.random.default_rng(seed)

    def predict(self, observation, state=None, episode_start=None, deterministic=False, action_masks=None):
        """(n, len(action_dims)) random legal actions; ``action_masks`` (n, sum(dims)) required."""
        if action_masks is None:
            raise ValueError("RandomMaskedPolicy needs action_masks to pick legal actions")
        masks = np.asarray(action_masks, dtype=bool)
        out, start = [], 0
        for d in self.action_dims:
            part = masks[:, start:start + d]                                # (n, d)
            out.append(np.argmax(self.rng.random(part.shape) * part, axis=1))
            start += d
        return np.stack(out, axis=1), None


def _takes_masks(model) -> bool:
    return "action_masks" in inspect.signature(model.predict).parameters


def _is_recurrent(model) -> bool:
    return hasattr(getattr(model, "policy", None), "lstm_actor")


def evaluate(model, vec_env, deterministic: bool = True, max_env_steps: int | None = None) -> list[dict]:
    """Play every parallel episode of ``vec_env`` to its end once.

    Args:
        model: an SB3 model (recurrent or not, masked or not) or any object with SB3's
            ``predict``; masks are passed when its ``predict`` takes ``action_masks``.
        vec_env: a vec env of :func:`patrolsb3.sb3.make_vec_env` (its team sizes are the
            episodes to evaluate). It is reset first.
        deterministic: most likely legal actions instead of samples.
        max_env_steps: safety limit on env steps (default: 2 x episode length x phases + 10).

    Returns:
        One ``team_episode`` dict per parallel episode, in order (reward, n_agents,
        mean_idleness, max_idleness, collisions, battery_failures, sim_steps).
    """
    max_agents = vec_env.layout.max_agents
    n_episodes = vec_env.num_envs // max_agents
    if max_env_steps is None:
        horizon = max(vec_env.episode_config(e).episode_steps for e in range(n_episodes))
        max_env_steps = 2 * horizon * getattr(vec_env, "phases_per_step", 2) + 10
    masked, recurrent = _takes_masks(model), _is_recurrent(model)
    obs = vec_env.reset()
    starts = np.ones(vec_env.num_envs, dtype=bool)                          # (num_envs,)
    state = None
    results: list[dict | None] = [None] * n_episodes
    for _ in range(max_env_steps):
        kwargs = {"action_masks": vec_env.action_masks()} if masked else {}
        if recurrent:
            actions, state = model.predict(obs, state=state, episode_start=starts, deterministic=deterministic, **kwargs)
        else:
            actions, _ = model.predict(obs, deterministic=deterministic, **kwargs)
        obs, _, dones, infos = vec_env.step(actions)
        starts = dones
        for row in np.flatnonzero(dones):
            episode = row // max_agents
            if results[episode] is None and "team_episode" in infos[row]:
                results[episode] = dict(infos[row]["team_episode"])
        if all(r is not None for r in results):
            return results
    raise RuntimeError(f"evaluation did not finish every episode within {max_env_steps} env steps")


def summarize(results: list[dict]) -> list[dict]:
    """Mean of :data:`METRICS` per team size: one dict per n_agents, sorted, with ``episodes``."""
    rows = []
    for n in sorted({int(r["n_agents"]) for r in results}):
        group = [r for r in results if int(r["n_agents"]) == n]
        row = {"n_agents": n, "episodes": len(group)}
        row.update({k: float(np.mean([r[k] for r in group])) for k in METRICS})
        rows.append(row)
    return rows
