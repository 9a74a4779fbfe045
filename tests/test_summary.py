"""patrolsb3.summary: the paper's figures of a batch of episodes, per test and over tests."""
import numpy as np
import pytest

from patrolsb3.summary import summarize


def test_summarize_over_tests_by_hand():
    per_episode = {
        "avg_idleness": np.array([10.0, 20.0, 30.0, 50.0]),
        "max_idleness": np.array([1.0, 2.0, 3.0, 5.0]),
        "worst_idleness": np.zeros(4), "std_idleness": np.zeros(4),
        "collisions": np.array([1.0, 3.0, 5.0, 7.0]),
        "battery_failures": np.array([0.0, 2.0, 0.0, 0.0]),
        "failed": np.array([False, True, False, False]),
        "swap_battery": np.array([0.2, np.nan, 0.3, 0.1]),
        "swaps": np.array([1, 0, 2, 2]),
    }
    s = summarize(per_episode, tests=2)
    # test 0: only episode 0 is clean; test 1: both
    assert s["avg_idleness"]["tests"] == [10.0, 40.0]
    assert s["avg_idleness"]["mean"] == 25.0 and s["avg_idleness"]["std"] == 15.0
    assert s["collisions"]["tests"] == [1.0, 6.0]
    assert s["battery_failure_rate"]["tests"] == [0.5, 0.0]
    assert s["battery_failures"]["tests"] == [1.0, 0.0]
    assert s["swap_battery_pct"]["tests"] == pytest.approx([20.0, 20.0])
    assert s["clean_episodes"] == [1, 2]


def test_summary_also_averages_over_every_episode():
    per_episode = {"failed": np.array([True, False, False, True]),
                   "battery_failures": np.array([1, 0, 0, 2]), "swaps": np.array([0, 1, 1, 0]),
                   "swap_battery": np.array([np.nan, 0.2, 0.3, np.nan])}
    for name in ("avg_idleness", "max_idleness", "worst_idleness", "std_idleness", "collisions"):
        per_episode[name] = np.array([10.0, 2.0, 4.0, 20.0])
    s = summarize(per_episode, tests=2)
    assert s["avg_idleness"]["tests"] == [2.0, 4.0]              # clean episodes only
    assert s["avg_idleness_all"]["tests"] == [6.0, 12.0]         # every episode
    # every episode's value is kept in episode order (NaN where the figure does not count it), so
    # that training seeds can be pooled and two strategies paired episode by episode
    assert s["avg_idleness"]["episodes"] == pytest.approx([np.nan, 2.0, 4.0, np.nan], nan_ok=True)
    assert s["avg_idleness_all"]["episodes"] == [10.0, 2.0, 4.0, 20.0]
    assert s["swap_battery_pct"]["episodes"] == pytest.approx([np.nan, 20.0, 30.0, np.nan], nan_ok=True)
    assert s["avg_idleness"]["ci95"][0] >= 2.0 and s["avg_idleness"]["ci95"][1] <= 4.0


def test_an_evaluation_summarises_its_failure_rate_exactly():
    per_episode = {"failed": np.zeros(20, dtype=bool), "battery_failures": np.zeros(20), "swaps": np.zeros(20),
                   "swap_battery": np.full(20, np.nan),
                   **{k: np.ones(20) for k in ("avg_idleness", "max_idleness", "worst_idleness",
                                               "std_idleness", "collisions")}}
    rate = summarize(per_episode, tests=1)["battery_failure_rate"]
    assert rate["mean"] == 0.0 and rate["ci95"][1] == pytest.approx(0.1684, abs=1e-3)   # 0 in 20
