"""Intervals of the figures: the bootstrap interval of a mean, and the exact interval of a rate.

One rule a figure: a mean over episodes (idleness, collisions, battery at swap) gets scipy's
percentile bootstrap (:func:`mean_interval`); a rate (the share of episodes with a battery
failure: each episode a 0 or a 1) gets the exact binomial (Clopper-Pearson) interval from
scipy (:func:`rate_interval`), which gives a rate of 0 in 30 episodes the interval [0, 0.116],
where a bootstrap gives [0, 0] and would call it clearly below 0.05.
"""
from __future__ import annotations

import numpy as np

RATE_METRICS = ("battery_failure_rate",)
"""Summary metrics whose per-episode values are 0 or 1 (their mean is a rate)."""


def mean_interval(values, resamples: int = 2000) -> list:
    """95 % interval of the mean of ``values`` (per-episode figures): scipy's percentile bootstrap
    (seeded, so a table is reproducible); [mean, mean] for fewer than 2 finite values or no
    spread, [nan, nan] for none."""
    values = np.asarray(values, dtype=np.float64)
    values = values[np.isfinite(values)]
    if len(values) == 0:
        return [float("nan"), float("nan")]
    if len(values) < 2 or values.min() == values.max():
        return [float(values.mean()), float(values.mean())]
    from scipy.stats import bootstrap
    ci = bootstrap((values,), np.mean, confidence_level=0.95, n_resamples=resamples, method="percentile",
                   random_state=0).confidence_interval
    return [float(ci.low), float(ci.high)]


def rate_interval(values) -> list:
    """95 % exact (Clopper-Pearson) interval of a rate from per-episode 0/1 values (scipy's
    ``binomtest``); [nan, nan] for no finite value.

    Raises:
        ValueError: a value other than 0 or 1.
    """
    values = np.asarray(values, dtype=np.float64)
    values = values[np.isfinite(values)]
    if len(values) == 0:
        return [float("nan"), float("nan")]
    if not np.isin(values, (0.0, 1.0)).all():
        raise ValueError("rate_interval takes per-episode values of 0 or 1")
    from scipy.stats import binomtest
    ci = binomtest(int(values.sum()), len(values)).proportion_ci(confidence_level=0.95, method="exact")
    return [float(ci.low), float(ci.high)]


def interval(metric: str, values) -> list:
    """The 95 % interval of a summary metric's per-episode ``values``: exact for a rate
    (:data:`RATE_METRICS`), the bootstrap of the mean otherwise."""
    return rate_interval(values) if metric in RATE_METRICS else mean_interval(values)


MIN_SEEDS = 3
"""Training seeds a learned column needs before its figures can decide a comparison."""
MIN_EPISODES = 10
"""Episodes a cell needs before its figures can decide a comparison."""


def seed_interval(seed_means) -> list:
    """95 % interval of the mean over training seeds, each seed's mean one draw (Student's t with
    seeds - 1 degrees of freedom, scipy): the training seed is the unit, so a seed far from the
    others widens the interval instead of being outvoted by its episodes. [nan, nan] below two
    finite seed means.

    >>> [round(v, 1) for v in seed_interval([425.1, 424.5, 329.9])]
    [257.0, 529.3]
    """
    values = np.asarray(seed_means, dtype=np.float64)
    values = values[np.isfinite(values)]
    if len(values) < 2:
        return [float("nan"), float("nan")]
    mean = float(values.mean())
    sem = float(values.std(ddof=1) / np.sqrt(len(values)))
    if sem == 0.0:
        return [mean, mean]
    from scipy.stats import t
    low, high = t.interval(0.95, len(values) - 1, loc=mean, scale=sem)
    return [float(low), float(high)]


def testable(episodes: int, training_seeds: int | None) -> bool:
    """Whether a cell's figures may decide a comparison: at least :data:`MIN_EPISODES` episodes
    and, for a learned column (``training_seeds`` not None), :data:`MIN_SEEDS` training seeds."""
    return episodes >= MIN_EPISODES and (training_seeds is None or training_seeds >= MIN_SEEDS)
