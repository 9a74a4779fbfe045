"""Metrics accumulators against a recorded trace, and the idleness lower bounds."""
import numpy as np
import pytest

from patrolsb3.core import load_map, make_config, reset_state, step
from patrolsb3.core.metrics import EpisodeMetrics, idleness_lower_bounds
from patrolsb3.strategies import get


def test_accumulators_match_recorded_trace():
    spec = load_map("D")
    # short batteries so that swaps and failures happen within the trace
    cfg = make_config("D", episode_steps=200, b_max=60.0, b_low_frac=0.05, p_dyn_max=0.3)
    E, h = 6, 120
    sim = reset_state(spec, cfg, [1, 2, 3, 4, 5, 5], n_envs=E, seed=3)
    policy = get("RANDOM", spec, 5, cfg, seed=1)
    metrics = EpisodeMetrics(E, spec.n_vertices, boundaries=[40])
    idle, collisions, failures, swap_levels = [], [], [], [[] for _ in range(E)]
    memory = None
    for _ in range(h):
        actions, memory = policy.predict(sim, memory)
        info = step(spec, cfg, sim, actions[..., 1], compute_reward=False)
        metrics.update(sim, info)
        idle.append(sim.idle.copy())
        collisions.append(info.collisions.copy())
        failures.append(info.battery_failed.sum(axis=1))
        for e, a in zip(*np.nonzero(info.swap_started)):
            swap_levels[e].append(info.swap_battery[e, a])
    trace = np.stack(idle)                                   # (h, E, V)
    r = metrics.result()
    np.testing.assert_allclose(r["avg_idleness"], trace.mean(axis=(0, 2)))
    np.testing.assert_allclose(r["max_idleness"], trace.mean(axis=0).max(axis=1))
    np.testing.assert_allclose(r["worst_idleness"], trace.max(axis=(0, 2)))
    np.testing.assert_allclose(r["std_idleness"], trace.mean(axis=0).std(axis=1))
    np.testing.assert_array_equal(r["collisions"], np.sum(collisions, axis=0))
    np.testing.assert_array_equal(r["battery_failures"], np.sum(failures, axis=0))
    assert r["battery_failures"].sum() > 0 and r["swaps"].sum() > 0   # the trace exercises both
    expected_swap = [np.mean(v) if v else np.nan for v in swap_levels]
    np.testing.assert_allclose(r["swap_battery"], expected_swap)
    before, after = metrics.segments()
    assert (before["start"], before["end"], after["start"], after["end"]) == (0, 40, 40, h)
    np.testing.assert_allclose(before["avg"], trace[:40].mean(axis=(0, 2)))
    np.testing.assert_allclose(after["max"], trace[40:].mean(axis=0).max(axis=1))


def test_lower_bounds_by_hand():
    # V = 4, k = 2, h = 3: best case sums of idleness after steps 1, 2, 3 are 2, 2, 2
    b = idleness_lower_bounds(4, 2, 3)
    assert b == {"v_over_k": 2.0, "worst": 1.0, "avg": pytest.approx(0.5)}
    # V = 5, k = 2, long run: values {0, 0, 1, 1, 2} -> mean 0.8 once t >= 2
    b = idleness_lower_bounds(5, 2, 10_000)
    assert b["worst"] == 2.0
    assert b["avg"] == pytest.approx(0.8, abs=1e-3)
