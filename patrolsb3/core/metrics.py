"""Per-episode accumulators of the paper's metrics over a batch of episodes (docs/model.md, section 5).

Feed :meth:`EpisodeMetrics.update` the state and the ``StepInfo`` after every step. Idleness
is the simulator's ``state.idle`` after the step (0 at t = 0, rate-weighted). Over h steps:

* ``avg_idleness``  AVG^h = (1/h) sum_t mean_v Idle(v, t);
* ``max_idleness``  MAX^h = max_v (1/h) sum_t Idle(v, t)  (a *time-averaged* idleness);
* ``worst_idleness`` max_t max_v Idle(v, t), the worst instantaneous idleness;
* ``std_idleness``  std dev across vertices of the per-vertex time average;
* ``collisions``, ``battery_failures`` per episode, ``failed`` (>= 1 battery failure),
  ``swap_battery`` mean battery fraction at the start of the episode's swaps (nan if none);
* segments: with boundaries (step counts), AVG and MAX over each stretch between them.

Lower bounds (:func:`idleness_lower_bounds`): each step at most k vertices are reset, so after
t steps at most k vertices have idleness j for each j < t and the rest have more. With uniform
rates (and any rates >= 1) no strategy gets the worst instantaneous idleness below about
|V|/k - 1, nor AVG^h (hence MAX^h) below about (|V|/k - 1)/2: a vertex revisited every P steps
has a *time-averaged* idleness of (P - 1)/2, so one agent on a tour of L steps reaches
worst ~ L - 1 and MAX^h ~ (L - 1)/2.
"""
from __future__ import annotations

import numpy as np


def idleness_lower_bounds(n_vertices: int, k: int, h: int) -> dict:
    """Lower bounds of the idleness metrics for k agents on |V| vertices over h steps.

    Returns:
        dict with ``v_over_k`` (|V|/k, the paper-style figure), ``worst`` (bound on the worst
        instantaneous idleness) and ``avg`` (bound on AVG^h and so on MAX^h), exact for the
        idleness-starts-at-0 convention.
    """
    V = n_vertices
    t = np.arange(1, h + 1, dtype=np.float64)                          # (h,)
    m, r = divmod(V, k)
    # smallest possible sum of idleness after step t: k vertices at each value 0..t-1
    early = k * t * (t - 1) / 2 + np.maximum(V - k * t, 0) * t
    late = k * m * (m - 1) / 2 + r * m
    total = np.where(t <= m, early, late)
    worst = min(float(h), float(np.ceil(V / k) - 1))
    return {"v_over_k": V / k, "worst": worst, "avg": float(total.mean() / V)}


class EpisodeMetrics:
    """Accumulators for E episodes stepped together.

    Args:
        n_envs: number of episodes E.
        n_vertices: number of vertices V.
        boundaries: step counts after which a new segment starts (e.g. fault steps + 1).
    """

    def __init__(self, n_envs: int, n_vertices: int, boundaries=()):
        self.idle_sum = np.zeros((n_envs, n_vertices))      # (E, V) sum over t of Idle(v, t)
        self.worst = np.zeros(n_envs)                        # (E,) max over t, v of Idle
        self.collisions = np.zeros(n_envs, dtype=np.int64)   # (E,)
        self.battery_failures = np.zeros(n_envs, dtype=np.int64)  # (E,)
        self.swap_battery_sum = np.zeros(n_envs)             # (E,) sum of battery fractions at swap start
        self.swaps = np.zeros(n_envs, dtype=np.int64)        # (E,)
        self.steps = 0
        self.boundaries = sorted({int(b) for b in boundaries if b > 0})
        self.snapshots: dict[int, np.ndarray] = {}           # step count -> (E, V) idle_sum copy

    def update(self, state, info) -> None:
        """Add one step: ``state`` after the step, ``info`` the ``StepInfo`` it returned."""
        self.idle_sum += state.idle
        np.maximum(self.worst, info.max_idleness, out=self.worst)
        self.collisions += info.collisions
        self.battery_failures += info.battery_failed.sum(axis=1)
        started = info.swap_started
        if started.any():
            self.swap_battery_sum += np.where(started, info.swap_battery, 0.0).sum(axis=1)
            self.swaps += started.sum(axis=1)
        self.steps += 1
        if self.steps in self.boundaries:
            self.snapshots[self.steps] = self.idle_sum.copy()

    def segments(self) -> list[dict]:
        """AVG and MAX idleness over each stretch between boundaries.

        Returns:
            list of dicts ``start`` (first step count, exclusive), ``end``, ``avg`` (E,), ``max`` (E,).
        """
        edges = [0] + [b for b in self.boundaries if b in self.snapshots] + [self.steps]
        sums = {0: np.zeros_like(self.idle_sum), self.steps: self.idle_sum, **self.snapshots}
        out = []
        for start, end in zip(edges[:-1], edges[1:]):
            if end <= start:
                continue
            part = (sums[end] - sums[start]) / (end - start)                    # (E, V)
            out.append({"start": start, "end": end, "avg": part.mean(axis=1), "max": part.max(axis=1)})
        return out

    def result(self) -> dict:
        """Per-episode figures, each an (E,) array (see module docstring)."""
        h = max(self.steps, 1)
        per_vertex = self.idle_sum / h                                          # (E, V)
        with np.errstate(invalid="ignore", divide="ignore"):
            swap_battery = np.where(self.swaps > 0, self.swap_battery_sum / self.swaps, np.nan)
        return {"avg_idleness": per_vertex.mean(axis=1), "max_idleness": per_vertex.max(axis=1),
                "worst_idleness": self.worst.copy(), "std_idleness": per_vertex.std(axis=1),
                "collisions": self.collisions.astype(np.float64),
                "battery_failures": self.battery_failures.astype(np.float64),
                "failed": self.battery_failures > 0, "swap_battery": swap_battery,
                "swaps": self.swaps.copy()}
