"""patrolsb3.stats: a rate gets its exact (Clopper-Pearson) interval everywhere it is summarised
or read back, a mean its bootstrap interval."""
import numpy as np
import pytest

from patrolsb3.outputs import read_results
from patrolsb3.stats import interval, mean_interval, rate_interval


def test_a_rate_of_0_in_30_has_an_exact_upper_bound_near_0_12():
    low, high = rate_interval([0.0] * 30)
    assert low == 0.0 and high == pytest.approx(0.1157, abs=1e-4)        # 1 - 0.025 ** (1 / 30)
    assert high > 0.05                       # so it is not "clearly at most 0.05"
    low, high = rate_interval([1.0] * 3 + [0.0] * 27)
    assert low == pytest.approx(0.0211, abs=1e-3) and high == pytest.approx(0.2653, abs=1e-3)
    assert rate_interval([]) != rate_interval([])                            # [nan, nan]
    with pytest.raises(ValueError, match="0 or 1"):
        rate_interval([0.5, 1.0])


def test_each_metric_gets_its_interval():
    values = [0.0, 1.0, 0.0, 0.0]
    assert interval("battery_failure_rate", values) == rate_interval(values)
    assert interval("avg_idleness", values) == mean_interval(values)
    assert mean_interval([3.0] * 30) == [3.0, 3.0]


def test_a_stored_rate_is_read_back_with_its_exact_interval():
    stored = [{"strategy": "CR", "summary": {"battery_failure_rate": {"mean": 0.0, "ci95": [0.0, 0.0],
                                                                      "episodes": [0.0] * 30},
                                             "avg_idleness": {"mean": 5.0, "ci95": [4.0, 6.0],
                                                              "episodes": [5.0] * 30}}}]
    summary = read_results(stored)[0]["summary"]
    assert summary["battery_failure_rate"]["ci95"][1] == pytest.approx(0.1157, abs=1e-4)
    assert summary["avg_idleness"]["ci95"] == [4.0, 6.0]                      # a mean's stays as stored


def test_an_interval_over_seeds_contains_the_seed_means_of_a_bimodal_case():
    from patrolsb3.stats import seed_interval
    seeds = [425.1, 424.5, 329.9]                      # A, rl-msg, one agent, MAX^h
    low, high = seed_interval(seeds)
    assert low < min(seeds) and high > max(seeds)
    # what the pooled-episode bootstrap said: an interval that excludes a seed's own mean
    rng = np.random.default_rng(0)
    episodes = np.concatenate([rng.normal(m, 5.0, 10) for m in seeds])
    pooled = mean_interval(episodes)
    assert not pooled[0] <= 329.9 <= pooled[1]
    assert np.isnan(seed_interval([400.0])[0])        # one seed: no interval over seeds


def test_too_few_to_test_below_the_floor():
    from patrolsb3.claims import Figure, lowest
    from patrolsb3.stats import testable
    assert testable(10, None) and testable(10, 3)
    assert not testable(9, None) and not testable(10, 2) and not testable(10, 1)
    low = (tuple(np.linspace(0.9, 1.1, 12)),)
    high = Figure(5.0, 4.9, 5.1, units=(tuple(np.linspace(4.9, 5.1, 12)[::-1]),))
    clear = {("A", 1, "zoo:rl-msg", "max_idleness"): Figure(1.0, 0.9, 1.1, units=low), ("A", 1, "CR", "max_idleness"): high}
    assert lowest(clear, "zoo:rl-msg", ["CR"], "max_idleness")["verdict"] == "holds"
    figures = {("A", 1, "zoo:rl-msg", "max_idleness"): Figure(1.0, 0.9, 1.1, testable=False, units=low),
               ("A", 1, "CR", "max_idleness"): high}                # clearly apart, but too few
    result = lowest(figures, "zoo:rl-msg", ["CR"], "max_idleness")
    assert result["verdict"] == "inconclusive" and "1 cells too few to test" in result["figure"]


def test_one_sided_p_values_against_a_bound_mirror_each_other():
    from scipy.stats import t as student_t

    from patrolsb3.stats import Difference
    d = Difference(0.0, -1.0, 1.0, 1.0, "episodes", se=1.0, df=10.0)
    assert d.p_below(2.0) == pytest.approx(student_t.cdf(-2.0, 10))       # about 0.037: shown below 2
    assert d.p_above(-2.0) == pytest.approx(d.p_below(2.0))
    assert d.p_below(-2.0) > 0.95 and d.p_above(2.0) > 0.95
    same_everywhere = Difference(1.0, 1.0, 1.0, 0.0, "episodes")          # no spread: decided outright
    assert same_everywhere.p_below(1.5) == 0.0 and same_everywhere.p_above(1.5) == 1.0
