"""Intervals of the figures: the bootstrap interval of a mean, and the exact interval of a rate.

One rule a figure: a mean over episodes (idleness, collisions, battery at swap) gets scipy's
percentile bootstrap (:func:`mean_interval`); a rate (the share of episodes with a battery
failure: each episode a 0 or a 1) gets the exact binomial (Clopper-Pearson) interval from
scipy (:func:`rate_interval`), which gives a rate of 0 in 30 episodes the interval [0, 0.116],
where a bootstrap gives [0, 0] and would call it clearly below 0.05.
"""
from __future__ import annotations

from dataclasses import dataclass

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
    [257.1, 529.3]
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


@dataclass(frozen=True)
class Difference:
    """A paired comparison of two strategies in one cell: the mean of ``a - b``, its 95 % interval
    and the two-sided p-value of "no difference" (:func:`paired_difference`), with the t test's
    standard error and degrees of freedom (nan for a difference that is the same everywhere)."""
    mean: float
    low: float
    high: float
    p: float
    unit: str            # what the interval is over: "episodes", "training seeds" or "training seeds (Welch)"
    se: float = float("nan")
    df: float = float("nan")

    def text(self, digits: int = 1) -> str:
        return f"{self.mean:+.{digits}f} [{self.low:+.{digits}f}, {self.high:+.{digits}f}]"

    def p_below(self, bound: float) -> float:
        """One-sided p-value of "the difference is at least ``bound``" (small when the data show
        that a - b is below ``bound``): Student's t with this difference's standard error and
        degrees of freedom; a difference that is the same everywhere gives 0 or 1."""
        from scipy.stats import t as student_t
        if not np.isfinite(self.se) or self.se <= 0:
            return 0.0 if self.mean < bound else 1.0
        return float(student_t.cdf((self.mean - bound) / self.se, self.df))

    def p_above(self, bound: float) -> float:
        """One-sided p-value of "the difference is at most ``bound``" (small when the data show
        that a - b is above ``bound``); the mirror of :meth:`p_below`."""
        from scipy.stats import t as student_t
        if not np.isfinite(self.se) or self.se <= 0:
            return 0.0 if self.mean > bound else 1.0
        return float(student_t.sf((self.mean - bound) / self.se, self.df))


def paired_difference(a_units, b_units) -> Difference | None:
    """How strategy a differs from b on paired episodes (the same draws: :mod:`patrolsb3.core.streams`).

    Each strategy comes as its units: one list of per-episode values per training seed (a
    heuristic, or one model: a single unit), aligned by episode, NaN where an episode does not
    count. The training seed is the unit wherever there are several:

    - one unit each: the per-episode differences (episodes counted by both), Student's t over them;
    - several units against one: each unit's mean difference to the other's episodes, t over units;
    - several against several: each unit's mean over the episodes counted by every unit of both
      (the same episodes, so what they share cancels), Welch's t between the two sets of means.

    Returns:
        The :class:`Difference`, or None when fewer than two values stand behind it. A difference
        that is exactly 0 everywhere has p = 1 and the interval [0, 0].
    """
    from scipy.stats import ttest_1samp, ttest_ind
    a = [np.asarray(u, dtype=np.float64) for u in a_units]
    b = [np.asarray(u, dtype=np.float64) for u in b_units]
    if len(a) > 1 and len(b) > 1:
        shared = np.logical_and.reduce([np.isfinite(u) for u in a + b])          # (N,) counted by all
        means_a = np.array([u[shared].mean() for u in a]) if shared.any() else np.array([])
        means_b = np.array([u[shared].mean() for u in b]) if shared.any() else np.array([])
        if len(means_a) < 2 or len(means_b) < 2:
            return None
        if np.ptp(means_a) == 0 and np.ptp(means_b) == 0:
            diff = float(means_a[0] - means_b[0])
            return Difference(diff, diff, diff, 1.0 if diff == 0 else 0.0, "training seeds (Welch)")
        test = ttest_ind(means_a, means_b, equal_var=False)
        ci = test.confidence_interval(0.95)
        diff = float(means_a.mean() - means_b.mean())
        se = float(np.sqrt(means_a.var(ddof=1) / len(means_a) + means_b.var(ddof=1) / len(means_b)))
        return Difference(diff, float(ci.low), float(ci.high), float(test.pvalue), "training seeds (Welch)",
                          se=se, df=float(test.df))
    flip = len(b) > 1                                  # several units on b's side: a - b = -(b - a)
    many, one = (b, a[0]) if flip else (a, b[0])
    if len(many) > 1:
        values = [np.nanmean(u - one) if np.isfinite(u - one).any() else np.nan for u in many]
        unit = "training seeds"
    else:
        values = many[0] - one
        unit = "episodes"
    values = np.asarray(values, dtype=np.float64)
    values = values[np.isfinite(values)]
    if flip:
        values = -values
    if len(values) < 2:
        return None
    mean = float(values.mean())
    if np.ptp(values) <= 1e-9 * max(1.0, abs(mean)):     # the same difference in every episode (or seed)
        return Difference(mean, mean, mean, 1.0 if abs(mean) <= 1e-9 else 0.0, unit)
    test = ttest_1samp(values, 0.0)
    ci = test.confidence_interval(0.95)
    return Difference(mean, float(ci.low), float(ci.high), float(test.pvalue), unit,
                      se=float(values.std(ddof=1) / np.sqrt(len(values))), df=float(len(values) - 1))


FAMILY_ALPHA = 0.05
"""The family-wise error rate of a claim's comparisons (Holm)."""


def holm(p_values, alpha: float = FAMILY_ALPHA) -> list[bool]:
    """Which of a family's hypotheses Holm's step-down procedure rejects at family-wise ``alpha``.

    The p-values sorted from the smallest, the k-th (0-based) of m is rejected while
    ``p <= alpha / (m - k)``; the first that is not stops the procedure (Holm 1979). scipy has
    no Holm (its ``false_discovery_control`` controls the false discovery rate, a weaker promise).

    >>> holm([0.01, 0.04, 0.03, 0.005])
    [True, False, False, True]
    """
    p = np.asarray(p_values, dtype=np.float64)
    rejected = [False] * len(p)
    for k, i in enumerate(np.argsort(p, kind="stable")):
        if not p[i] <= alpha / (len(p) - k):
            break
        rejected[i] = True
    return rejected
