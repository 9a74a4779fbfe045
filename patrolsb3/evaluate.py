"""Run a strategy over batched episodes and summarise the paper's metrics over tests.

All episodes of one configuration (tests x episodes) step together on the batched core:
``policy.predict(sim_state, memory, episode_start)`` -> actions (E, A, 2), then
``core.step(spec, cfg, sim, actions[..., 1], messages=actions[..., 0], compute_reward=False)``
with ``invalid_action='raise'``. A heuristic (``patrolsb3.strategies``) and a zoo model
(``zoo:<variant>``, loaded by ``patrolsb3.zoo.load(map, variant)``; ``zoo:<variant>:guarded`` for
the entries behind the return guard) are treated the same way.

Tests: episode e belongs to test ``e // episodes``. Per test, idleness and collision figures
average over the episodes *without* a battery failure (as in the paper; the count is kept),
the battery failure rate is the share of episodes with >= 1 failure, and the battery level at
recharge averages over every swap of the test. The summary is mean and std over tests.
"""
from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from . import zoo
from .names import is_learned
from .core.config import make_config
from .core.maps import load_map
from .core.metrics import EpisodeMetrics, idleness_lower_bounds
from .core.state import reset_state
from .core.step import step
from .stats import interval

CLEAN_METRICS = ("avg_idleness", "max_idleness", "worst_idleness", "std_idleness", "collisions")
"""Averaged over episodes without a battery failure."""
ALL_METRICS = ("battery_failures", "battery_failure_rate", "swap_battery_pct")
"""Averaged over every episode (or swap)."""


def parse_faults(texts) -> tuple:
    """Parse ``STEP:K`` strings into ((step, k), ...).

    Raises:
        ValueError: a string not of the form STEP:K with integers STEP >= 0 and K >= 1.
    """
    faults = []
    for text in texts or ():
        parts = str(text).split(":")
        try:
            if len(parts) != 2:
                raise ValueError
            fault_step, k = int(parts[0]), int(parts[1])
        except ValueError:
            raise ValueError(f"bad --faults {text!r}: expected STEP:K with integers, e.g. 7200:1 "
                             f"(K agents fail for good at step STEP)") from None
        if fault_step < 0 or k < 1:
            raise ValueError(f"bad --faults {text!r}: STEP must be >= 0 and K >= 1")
        faults.append((fault_step, k))
    return tuple(sorted(faults))


def canonical_name(name: str) -> str:
    """The name tables use: heuristics in capitals ('sebs' -> 'SEBS'), zoo models as
    'zoo:<variant>' (or 'zoo:<variant>:guarded') in lower case."""
    name = str(name).strip()
    if is_learned(name):
        return name.lower()
    return name.upper()


def load_policy(name: str, spec, n_agents: int, cfg, seed: int = 0, device: str = "cpu"):
    """A heuristic by name, or ``zoo:<variant>`` through ``patrolsb3.zoo.load(map, variant)``
    (``zoo:<variant>:guarded``: the entry behind the return guard; its network on ``device``:
    auto, cpu or cuda).

    Raises:
        ValueError: unknown strategy, or a zoo strategy when no zoo module or model exists.
    """
    if is_learned(name):
        try:
            variant, guard = zoo.parse_strategy(name)
            return zoo.load(spec.name, variant, spec=spec, device=device, guard=guard)
        except (ValueError, FileNotFoundError) as exc:
            raise ValueError(f"strategy {name!r}: {exc}") from exc
    from . import strategies
    return strategies.get(name, spec, n_agents, cfg=cfg, seed=seed)


def run_episodes(policy, spec, cfg, n_agents: int, n_envs: int, seed: int = 0, progress=False,
                 desc: str = "", deterministic: bool = True) -> dict:
    """Run ``n_envs`` episodes of ``cfg.episode_steps`` steps together.

    Args:
        policy: any object with SB3's ``predict(sim_state, state, episode_start, deterministic)``.
        spec: the map.
        cfg: environment parameters (its ``faults`` also set the metric segments).
        n_agents: team size of every episode.
        n_envs: episodes E.
        seed: seed of the simulator.
        progress: show a tqdm progress bar over steps.
        desc: label of the progress bar.
        deterministic: passed to ``predict``: a learned policy takes its most likely legal
            action (True) or samples one (False); heuristics ignore it.

    Returns:
        The per-episode figures of :meth:`EpisodeMetrics.result` plus ``segments``.
    """
    sim = reset_state(spec, cfg, n_agents, n_envs=n_envs, seed=seed)
    metrics = EpisodeMetrics(n_envs, spec.n_vertices, boundaries=[s + 1 for s, _ in cfg.faults])
    if not deterministic and hasattr(policy, "seed_sampling"):
        policy.seed_sampling(seed)                     # sampled actions reproducible per seed
    memory = None
    episode_start = np.ones(n_envs, dtype=bool)
    steps = range(cfg.episode_steps)
    if progress:
        from tqdm import tqdm
        steps = tqdm(steps, desc=desc, unit="step", leave=False, mininterval=0.5)
    for _ in steps:
        actions, memory = policy.predict(sim, state=memory, episode_start=episode_start,
                                         deterministic=deterministic)
        info = step(spec, cfg, sim, actions[..., 1], messages=actions[..., 0], compute_reward=False)
        metrics.update(sim, info)
        episode_start[:] = False
    result = metrics.result()
    result["segments"] = metrics.segments() if cfg.faults else []
    return result


def interval95(values, resamples: int = 2000) -> list:
    """95 % bootstrap interval of the mean of per-episode ``values``
    (:func:`patrolsb3.stats.mean_interval`)."""
    from .stats import mean_interval
    return mean_interval(values, resamples)


def summarize(per_episode: dict, tests: int) -> dict:
    """Per-test figures and their mean / std over tests.

    Args:
        per_episode: output of :func:`run_episodes` (E = tests x episodes).
        tests: number of tests.

    Returns:
        dict metric -> {"mean", "std", "tests": [per-test values], "ci95": [low, high],
        "episodes": [per-episode values]}: std over tests, and a 95 % interval over the episodes
        themselves (:func:`patrolsb3.stats.interval`: exact for the battery failure rate, the
        bootstrap of the mean otherwise; the episodes a metric counts,
        kept so that the seeds of a zoo entry can be pooled: ``patrolsb3.zoo.pooled_result``), plus ``clean_episodes`` (per-test
        counts of episodes without a battery failure) and ``segments``.
    """
    failed = per_episode["failed"].reshape(tests, -1)                        # (T, N)
    clean = ~failed
    out = {}

    def stats(values, episodes=None, metric=""):
        values = np.asarray(values, dtype=np.float64)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            result = {"mean": float(np.nanmean(values)) if np.isfinite(values).any() else float("nan"),
                      "std": float(np.nanstd(values)) if np.isfinite(values).any() else float("nan"),
                      "tests": [float(v) for v in values]}
        if episodes is not None:
            episodes = np.asarray(episodes, dtype=np.float64)
            result["ci95"] = interval(metric, episodes)          # exact for a rate
            result["episodes"] = [float(v) for v in episodes]    # what seeds are pooled from
        return result

    def clean_mean(x):
        x = x.reshape(tests, -1)
        n = clean.sum(axis=1)
        return np.where(n > 0, np.where(clean, x, 0.0).sum(axis=1) / np.maximum(n, 1), np.nan)

    for name in CLEAN_METRICS:
        values = np.asarray(per_episode[name], dtype=np.float64)
        out[name] = stats(clean_mean(values), values[clean.reshape(-1)])
        # the same over every episode, failed ones included (not in the paper's tables; it
        # keeps a strategy whose every episode fails from having no idleness figure at all)
        out[f"{name}_all"] = stats(values.reshape(tests, -1).mean(axis=1), values)
    out["battery_failures"] = stats(per_episode["battery_failures"].reshape(tests, -1).mean(axis=1),
                                    per_episode["battery_failures"])
    out["battery_failure_rate"] = stats(failed.mean(axis=1), failed.reshape(-1).astype(np.float64),
                                        metric="battery_failure_rate")
    swaps = per_episode["swaps"].reshape(tests, -1)
    level = np.nan_to_num(per_episode["swap_battery"]).reshape(tests, -1) * swaps
    with np.errstate(invalid="ignore", divide="ignore"):
        out["swap_battery_pct"] = stats(100.0 * level.sum(axis=1) / swaps.sum(axis=1),
                                        100.0 * np.asarray(per_episode["swap_battery"])[swaps.reshape(-1) > 0])
    out["clean_episodes"] = [int(n) for n in clean.sum(axis=1)]
    out["segments"] = [{"start": s["start"], "end": s["end"],
                        "avg_idleness": stats(clean_mean(s["avg"])),
                        "max_idleness": stats(clean_mean(s["max"]))}
                       for s in per_episode.get("segments", [])]
    return out


def evaluate(strategy: str, map_name="A", n_agents: int = 3, episodes: int = 100, tests: int = 1,
             steps: int = 14400, seed: int = 0, faults=(), progress: bool = True, deterministic: bool = True,
             device: str = "cpu", **env) -> dict:
    """Evaluate one strategy on one map and team size (the ``patrolsb3 evaluate`` command).

    Args:
        strategy: RANDOM, CR, PART, SEBS, CYCLIC, zoo:<variant> or zoo:<variant>:guarded.
        map_name: a shipped map name or a map file.
        n_agents: team size.
        episodes: episodes per test.
        tests: tests (the summary is mean +- std over them).
        steps: steps per episode (14,400 = 24 h).
        seed: seed of the simulator and the strategy.
        faults: ((step, k), ...) scheduled hardware failures.
        progress: show a progress bar.
        deterministic: a zoo model takes its most likely legal action (True, SB3's evaluation
            default) or samples from its policy (False); heuristics are unaffected.
        device: where a zoo model's network runs: auto (cuda when torch sees one), cpu
            (default: the figures of the zoo's eval.json were computed there) or cuda.
        **env: other EnvConfig fields (e.g. p_dyn_max=0).

    Returns:
        A JSON-friendly dict: the configuration (``env``: the simulator's, the paper's values for
        the map; for a zoo model also ``policy_settings``, the observation, message and guard
        settings it acts under, ``ZooPolicy.env_settings``), ``summary`` (see :func:`summarize`)
        and ``bounds`` (:func:`idleness_lower_bounds`).
    """
    spec, cfg = evaluation_setup(map_name, n_agents, episodes, tests, steps, faults, **env)
    policy = load_policy(strategy, spec, n_agents, cfg, seed=seed, device=device)
    policy_cfg = getattr(policy, "cfg", None)
    if policy_cfg is not None and policy_cfg.max_agents != cfg.max_agents:
        cfg = make_config(None, **{**cfg.to_dict(), "max_agents": policy_cfg.max_agents})
    per_episode = run_episodes(policy, spec, cfg, n_agents, tests * episodes, seed=seed,
                               progress=progress, desc=f"{strategy} map {spec.name} n={n_agents}",
                               deterministic=deterministic)
    acts_under = {"policy_settings": policy.env_settings()} if hasattr(policy, "env_settings") else {}
    return {**request_of(strategy, spec, n_agents, episodes, tests, steps, seed, cfg, deterministic),
            **acts_under, "summary": summarize(per_episode, tests),
            "bounds": idleness_lower_bounds(spec.n_vertices, n_agents, steps)}


def request_of(strategy: str, spec, n_agents: int, episodes: int, tests: int, steps: int, seed: int,
               cfg, deterministic: bool = True) -> dict:
    """The fields of an :func:`evaluate` result that say what was run (everything but the
    figures): what ``patrolsb3.result_store`` compares to reuse a stored result."""
    return {"strategy": canonical_name(strategy), "map": spec.name, "n_agents": int(n_agents),
            "episodes": int(episodes), "tests": int(tests), "steps": int(steps), "seed": int(seed),
            "faults": [list(f) for f in cfg.faults], "deterministic": bool(deterministic),
            "env": cfg.to_dict()}


def evaluation_setup(map_name, n_agents: int, episodes: int, tests: int, steps: int, faults=(), **env):
    """Check an evaluation's arguments and build its map and env config (see :func:`evaluate`).

    Returns:
        ``(spec, cfg)``: the loaded map and the :class:`EnvConfig` the episodes run with.

    Raises:
        ValueError: a fault outside the episode, a count below 1, or a team that does not fit.
    """
    spec = load_map(map_name)
    late = [f for f in faults if f[0] >= steps]
    if late:
        raise ValueError(f"--faults {late[0][0]}:{late[0][1]} is outside the episode: STEP must be "
                         f"< --steps ({steps})")
    if episodes < 1 or tests < 1 or steps < 1:
        raise ValueError(f"episodes, tests and steps must be >= 1 (got {episodes}, {tests}, {steps})")
    max_agents = env.pop("max_agents", 5)
    if not 1 <= n_agents <= max_agents:
        raise ValueError(f"team of {n_agents} agents does not fit: 1 <= agents <= max_agents={max_agents}")
    cfg = make_config(spec.name, max_agents=max_agents,
                      episode_steps=steps, faults=tuple(faults), invalid_action="raise", **env)
    return spec, cfg


def write_zoo_eval(folder, episodes: int = 10, steps: int = 14400, seed: int = 0, tests: int = 1,
               progress: bool = True, deterministic: bool = True) -> Path:
    """Evaluate a zoo entry for 1..max_agents agents and write ``eval.json`` beside it.

    All team sizes run in one batch (episodes x tests per size) so the policy's forward passes
    are shared; each size's figures are summarised like ``patrolsb3.evaluate.evaluate`` does,
    so ``patrolsb3 compare`` can reuse them (:func:`cached_result`).

    Args:
        folder: the entry folder (``zoo/<map>/<variant>``).
        episodes: episodes per test and team size.
        steps: steps per episode (14,400 = the paper's 24 h).
        seed: simulator seed.
        tests: tests per team size.
        progress: progress bar.
        deterministic: most likely legal actions (True) or sampled ones (False).

    Returns:
        Path of eval.json: {"map", "strategy", "episodes", "tests", "steps", "seed", "deterministic",
        "results": [evaluate()-style dict per team size]}.
    """
    folder = Path(folder)
    policy = zoo.load_entry(folder)
    config = policy.info["config"]
    max_agents = policy.cfg.max_agents
    cfg = zoo.evaluation_config(policy, steps)
    per_size = episodes * tests
    team = np.repeat(np.arange(1, max_agents + 1), per_size)                # (max_agents * per_size,)
    per_episode = run_episodes(policy, policy.spec, cfg, team, len(team), seed=seed, progress=progress,
                               desc=f"zoo {config['map']}/{config['variant']} n=1..{max_agents}",
                               deterministic=deterministic)
    strategy = zoo.strategy_name(config["variant"], guard=policy.cfg.return_guard)
    results = []
    for n in range(1, max_agents + 1):
        rows = team == n
        part = {k: v[rows] for k, v in per_episode.items() if isinstance(v, np.ndarray)}
        results.append({"strategy": strategy, "map": config["map"], "n_agents": n, "episodes": episodes,
                        "tests": tests, "steps": steps, "seed": seed, "faults": [],
                        "deterministic": bool(deterministic), "env": cfg.to_dict(),
                        "policy_settings": policy.env_settings(),
                        "summary": summarize(part, tests),
                        "bounds": idleness_lower_bounds(policy.spec.n_vertices, n, steps)})
    out = {"map": config["map"], "strategy": strategy, "episodes": episodes, "tests": tests,
           "steps": steps, "seed": seed, "deterministic": bool(deterministic),
           "note": "all team sizes stepped in one batch; episodes of size n are rows n-1 of the batch",
           "results": results}
    from .outputs import write_json
    return write_json(folder / "eval.json", out, indent=2)
