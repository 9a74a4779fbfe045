"""The paper's figures of a batch of evaluation episodes: per test, then mean and std over tests,
with each figure's 95 % interval over its episodes (:mod:`patrolsb3.stats`).

Tests: episode e belongs to test ``e // episodes``. Per test, idleness and collision figures
average over the episodes *without* a battery failure (as in the paper; the count is kept),
the battery failure rate is the share of episodes with >= 1 failure, and the battery level at
recharge averages over every swap of the test.
"""
from __future__ import annotations

import warnings

import numpy as np

from .stats import interval

CLEAN_METRICS = ("avg_idleness", "max_idleness", "worst_idleness", "std_idleness", "collisions")
"""Averaged over episodes without a battery failure."""
ALL_METRICS = ("battery_failures", "battery_failure_rate", "swap_battery_pct")
"""Averaged over every episode (or swap)."""


def summarize(per_episode: dict, tests: int) -> dict:
    """Per-test figures and their mean / std over tests.

    Args:
        per_episode: output of :func:`run_episodes` (E = tests x episodes).
        tests: number of tests.

    Returns:
        dict metric -> {"mean", "std", "tests": [per-test values], "ci95": [low, high],
        "episodes": [per-episode values]}: std over tests, and a 95 % interval over the episodes
        the metric counts (:func:`patrolsb3.stats.interval`: exact for the battery failure rate,
        the bootstrap of the mean otherwise). ``episodes`` has one value per episode, in episode
        order (episode e: test ``e // episodes``), NaN where the metric does not count it (an
        episode with a battery failure for the clean metrics, one without a swap for the battery
        at swap): what pools a zoo entry's seeds (``patrolsb3.zoo.pooled_result``) and pairs two
        strategies episode by episode (:mod:`patrolsb3.claims`). Plus ``clean_episodes`` (per-test
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
        out[name] = stats(clean_mean(values), np.where(clean.reshape(-1), values, np.nan))
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
                                        np.where(swaps.reshape(-1) > 0, 100.0 * np.asarray(per_episode["swap_battery"]),
                                                 np.nan))
    out["clean_episodes"] = [int(n) for n in clean.sum(axis=1)]
    out["segments"] = [{"start": s["start"], "end": s["end"],
                        "avg_idleness": stats(clean_mean(s["avg"])),
                        "max_idleness": stats(clean_mean(s["max"]))}
                       for s in per_episode.get("segments", [])]
    return out
