"""An entry's stored evaluation figures: one seed's eval.json result for a protocol, the
figures of every training seed pooled with the training seed as the unit, and how the seeds
of a zoo column were trained (their recipe)."""
from __future__ import annotations

import numpy as np

from ..core.streams import STREAMS_VERSION
from ..names import GUARDED, strategy_name
from ..outputs import read_eval_file
from ..runs import ZooEntry
from ..stats import RATE_METRICS, rate_interval, seed_interval
from .folders import entry_dir, read_entry, seeds


def cached_result(map_name: str, variant: str, n_agents: int, episodes: int, steps: int, seed: int,
                  tests: int = 1, zoo_dir=None, deterministic: bool = True, shelf: str = "",
                  training_seed: int | None = None):
    """One entry's eval.json result for exactly this protocol and action mode, or None: the
    default seed's, or ``training_seed``'s (of the main zoo, or of ``shelf``)."""
    path = ZooEntry(entry_dir(map_name, variant, zoo_dir, seed=training_seed, shelf=shelf)).evaluation_file
    if not path.is_file():
        return None
    data = read_eval_file(path)
    if (data.get("episodes"), data.get("steps"), data.get("seed"), data.get("tests"),
            data.get("deterministic", True), data.get("draws")) != (episodes, steps, seed, tests, deterministic,
                                                                     STREAMS_VERSION):
        return None
    found = next((r for r in data.get("results", []) if r["n_agents"] == n_agents), None)
    return None if found is None else {**found, "strategy": strategy_name(variant, shelf)}


def pooled_result(map_name: str, variant: str, n_agents: int, episodes: int, steps: int, seed: int,
                  tests: int = 1, zoo_dir=None, deterministic: bool = True, shelf: str = ""):
    """The entry's figures pooled over its training seeds, from their eval.json (the main zoo, or
    a recipe ``shelf``).

    Every seed whose eval.json holds this protocol and per-episode figures contributes. The
    training seed is the unit: a mean metric's figure is the mean of the seeds' means and its 95 %
    interval Student's t over them (:func:`patrolsb3.stats.seed_interval`), so two seeds far
    apart give a wide interval that contains both. A rate (the battery failure rate) pools the
    seeds' episodes and takes the exact binomial interval (:func:`patrolsb3.stats.rate_interval`):
    with three seeds of 10 episodes, a t over three rates of 0 would say [0, 0].
    ``summary[metric]["tests"]`` holds the seeds' own means, ``["episodes"]`` every episode and
    ``["units"]`` each seed's episodes (what :mod:`patrolsb3.claims` pairs episode by episode). With
    one usable seed this is that seed's result unchanged (its intervals are over its episodes:
    a figure, not a verdict; ``claims`` tests no cell below three seeds).

    Returns:
        The result dict (like :func:`cached_result`) with ``training_seeds`` (the seeds pooled)
        and ``unpooled_seeds`` (seeds left out: no eval.json for this protocol, or one written
        before per-episode figures were stored), or None when no seed has such a result.
    """
    usable, left_out = [], []
    for k in seeds(map_name, variant, zoo_dir, shelf):
        r = cached_result(map_name, variant, n_agents, episodes, steps, seed, tests, zoo_dir,
                          deterministic, shelf=shelf, training_seed=k)
        if r is not None and all("episodes" in v for v in r["summary"].values() if isinstance(v, dict) and "ci95" in v):
            usable.append((k, r))
        else:
            left_out.append(k)
    if not usable:
        return None
    if len(usable) == 1:
        return {**usable[0][1], "training_seeds": [usable[0][0]], "unpooled_seeds": left_out}
    first = usable[0][1]
    summary = {}
    for metric, value in first["summary"].items():
        if isinstance(value, dict) and "episodes" in value:
            pooled = np.concatenate([np.asarray(r["summary"][metric]["episodes"], dtype=np.float64)
                                     for _, r in usable])                     # (seeds x episodes,)
            seed_means = [float(r["summary"][metric]["mean"]) for _, r in usable]
            finite_means = [m for m in seed_means if np.isfinite(m)]
            if metric in RATE_METRICS:        # a rate: every episode a 0 or a 1, the exact interval
                finite = pooled[np.isfinite(pooled)]
                mean, ci = (float(finite.mean()) if len(finite) else float("nan")), rate_interval(pooled)
            else:                             # a mean: the training seed is the unit
                mean = float(np.mean(finite_means)) if finite_means else float("nan")
                ci = seed_interval(seed_means)
            summary[metric] = {"mean": mean, "std": float(np.nanstd(seed_means)), "tests": seed_means,
                               "ci95": ci, "episodes": [float(v) for v in pooled],
                               "units": [list(r["summary"][metric]["episodes"]) for _, r in usable]}
        elif metric == "clean_episodes":
            summary[metric] = [int(sum(r["summary"][metric])) for _, r in usable]
        else:
            summary[metric] = value
    return {**first, "summary": summary, "training_seeds": [k for k, _ in usable], "unpooled_seeds": left_out}


def recipe_of(config: dict) -> str:
    """How one entry was trained, in a phrase: its recipe (config.yml's ``recipe``; "recipe not
    recorded" for entries made before runs recorded it) and the three settings on which the
    zoo's recipe and the paper's differ most (docs/training.md): the difference-reward weight
    c_d, gamma and the training episodes' length.

    Example: ``zoo-stage2 (c_d 200, gamma 0.99, 1,500-step episodes)``.
    """
    env, hp = config.get("env") or {}, config.get("hyperparams") or {}
    c_d = env.get("c_d")
    c_d = 50.0 / env.get("max_agents", 5) if c_d is None else c_d      # EnvConfig.difference_weight
    steps = env.get("episode_steps")
    length = f"{steps:,}-step episodes" if isinstance(steps, int) else "episodes of unrecorded length"
    return f"{config.get('recipe') or 'recipe not recorded'} (c_d {c_d:g}, gamma {hp.get('gamma', '?')}, {length})"


def trained_with(map_name: str, variant: str, zoo_dir=None, shelf: str = "") -> str:
    """How the entries of a zoo column were trained: each distinct :func:`recipe_of` with the
    training seeds that have it, e.g. ``zoo-stage2 (c_d 200, gamma 0.99, 1,500-step episodes):
    seeds 0, 1, 2``. The entry behind the guard has one folder and no seeds."""
    if shelf == GUARDED:
        return recipe_of(read_entry(entry_dir(map_name, variant, zoo_dir, shelf=GUARDED))["config"])
    by_recipe: dict[str, list[int]] = {}
    for seed in seeds(map_name, variant, zoo_dir, shelf):
        config = read_entry(entry_dir(map_name, variant, zoo_dir, seed=seed, shelf=shelf))["config"]
        by_recipe.setdefault(recipe_of(config), []).append(seed)
    return "; ".join(f"{phrase}: seed{'s' if len(found) > 1 else ''} {', '.join(map(str, found))}"
                     for phrase, found in by_recipe.items())
