"""Running a strategy's episodes: a heuristic or a zoo model over batched episodes, summarised
by :mod:`patrolsb3.summary`.

All episodes of one configuration (tests x episodes) step together on the batched core:
``policy.predict(sim_state, memory, episode_start)`` -> actions (E, A, 2), then
``core.step(spec, cfg, sim, actions[..., 1], messages=actions[..., 0], compute_reward=False)``
with ``invalid_action='raise'``. A heuristic (``patrolsb3.strategies``) and a zoo model
(``zoo:<variant>``, loaded by ``patrolsb3.zoo.load(map, variant)``; ``zoo:<variant>:<shelf>`` for
an entry on a shelf of the zoo, e.g. behind the return guard) are treated the same way.

Tests: episode e belongs to test ``e // episodes`` (:func:`patrolsb3.summary.summarize`).
"""
from __future__ import annotations


import numpy as np

from . import strategies, zoo
from .core.config import make_config
from .core.maps import load_map
from .core.metrics import EpisodeMetrics, idleness_lower_bounds
from .core.state import reset_state
from .core.step import step
from .core.streams import STREAMS_VERSION
from .names import canonical_name, is_learned
from .summary import summarize



def load_policy(name: str, spec, n_agents: int, cfg, seed: int = 0, device: str = "cpu"):
    """A heuristic by name, or ``zoo:<variant>`` through ``patrolsb3.zoo.load(map, variant)``
    (``zoo:<variant>:<shelf>``: the entry on that shelf of the zoo, e.g. ``zoo:rl-msg:guarded``
    behind the return guard; its network on ``device``:
    auto, cpu or cuda).

    Raises:
        ValueError: unknown strategy, or a zoo strategy when no zoo module or model exists.
    """
    if is_learned(name):
        try:
            variant, shelf = zoo.parse_strategy(name)
            return zoo.load(spec.name, variant, spec=spec, device=device, shelf=shelf)
        except (ValueError, FileNotFoundError) as exc:
            raise ValueError(f"strategy {name!r}: {exc}") from exc
    return strategies.get(name, spec, n_agents, cfg=cfg, seed=seed)


def team_batch(team_sizes, episodes: int) -> tuple[np.ndarray, np.ndarray]:
    """One batch of ``episodes`` episodes for each team size, paired: episode j of every size has
    the id j, so it meets the same draws (:mod:`patrolsb3.core.streams`).

    Returns:
        team (len(team_sizes) * episodes,) int64 team size of each episode, and its episode ids.
    """
    sizes = np.asarray(team_sizes, dtype=np.int64)
    return np.repeat(sizes, episodes), np.tile(np.arange(episodes), len(sizes))


def run_episodes(policy, spec, cfg, n_agents: int, n_envs: int, seed: int = 0, progress=False,
                 desc: str = "", deterministic: bool = True, episode_ids=None) -> dict:
    """Run ``n_envs`` episodes of ``cfg.episode_steps`` steps together.

    Args:
        policy: any object with SB3's ``predict(sim_state, state, episode_start, deterministic)``.
        spec: the map.
        cfg: environment parameters (its ``faults`` also set the metric segments).
        n_agents: team size of every episode.
        n_envs: episodes E.
        seed: seed of the simulator.
        episode_ids: (E,) int, each episode's id (default 0 .. E-1): episode ``i`` of ``seed``
            meets the same starts, wind, drains, swap times and faults in every batch
            (:mod:`patrolsb3.core.streams`); a batch of several team sizes gives episode j of
            each size the id j, so that they are paired.
        progress: show a tqdm progress bar over steps.
        desc: label of the progress bar.
        deterministic: passed to ``predict``: a learned policy takes its most likely legal
            action (True) or samples one (False); heuristics ignore it.

    Returns:
        The per-episode figures of :meth:`EpisodeMetrics.result` plus ``segments``.
    """
    sim = reset_state(spec, cfg, n_agents, n_envs=n_envs, seed=seed, episode_ids=episode_ids)
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


def evaluate(strategy: str, map_name="A", n_agents: int = 3, episodes: int = 100, tests: int = 1,
             steps: int = 14400, seed: int = 0, faults=(), progress: bool = True, deterministic: bool = True,
             device: str = "cpu", **env) -> dict:
    """Evaluate one strategy on one map and team size (the ``patrolsb3 evaluate`` command).

    Args:
        strategy: RANDOM, CR, PART, SEBS, CYCLIC, zoo:<variant> or zoo:<variant>:<shelf>.
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
        settings it acts under, ``ZooPolicy.env_settings``), ``summary`` (see :func:`patrolsb3.summary.summarize`)
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
            "env": cfg.to_dict(), "draws": STREAMS_VERSION}


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


