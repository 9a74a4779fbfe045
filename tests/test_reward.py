"""patrolsb3.core.reward: the paper's rewards computed by hand (plain math, no vectorised formula)."""
import math

import numpy as np
import pytest

from patrolsb3.core import make_config
from patrolsb3.core.maps import STAY
from patrolsb3.core.reward import (battery_reward, collision_reward, difference_reward,
                                   home_potential, normalised_idleness, team_patrol_reward)
from patrolsb3.core.step import step

from conftest import deterministic_config, place


def f(i, c_norm=200.0):
    return 1.0 - math.exp(-i / c_norm)


def team(fs):
    return (2.0 - sum(fs) / len(fs) - max(fs)) / 2.0


def test_normalised_idleness_and_never_visited():
    out = normalised_idleness(np.array([[0.0, 200.0, 50.0]]), np.array([[True, True, False]]), 200.0)
    assert out[0, 0] == 0.0
    assert out[0, 1] == pytest.approx(1.0 - math.exp(-1.0))
    assert out[0, 2] == 1.0


def test_team_patrol_reward_by_hand():
    fs = [0.0, 0.5, 0.25, 1.0]
    rp, mean_f, max_f = team_patrol_reward(np.array([fs]))
    assert rp[0] == pytest.approx((2 - 0.4375 - 1.0) / 2)
    assert mean_f[0] == 0.4375 and max_f[0] == 1.0


@pytest.mark.parametrize("idle_before, visited", [
    ([10, 20, 30, 40, 50], [True] * 5),          # agent's vertex is not the maximum
    ([300, 20, 30, 40, 50], [True] * 5),         # had it not been reset, it would be the maximum
    ([10, 20, 30, 40, 50], [True, True, True, True, False]),   # an unvisited vertex has f = 1
])
def test_patrol_reward_with_difference_term_by_hand(line_map, idle_before, visited):
    spec = line_map                              # "S.....": vertices (0, 1) .. (0, 5), rate 1
    cfg = deterministic_config(max_agents=1)     # c_d = 50 / 1, c_rp = 0.5
    state = place(spec, cfg, [(0, 1)])           # the agent stands on vertex 0
    state.idle[0] = idle_before
    state.visited[0] = visited
    info = step(spec, cfg, state, np.array([[STAY]]))
    grown = [i + 1 for i in idle_before]
    f_after = [0.0] + [f(i) if v else 1.0 for i, v in zip(grown[1:], visited[1:])]
    f_without_k = [f(grown[0])] + f_after[1:]
    rp = team(f_after)
    d = rp - team(f_without_k)
    assert info.team_patrol[0] == pytest.approx(rp, rel=1e-12)
    assert info.reward_patrol[0, 0] == pytest.approx(0.5 * rp + 50.0 * d, rel=1e-12)
    assert info.reward[0, 0] == pytest.approx(0.5 * rp + 50.0 * d, rel=1e-12)
    assert d > 0


def test_difference_reward_of_two_agents_by_hand(line_map):
    spec = line_map
    cfg = deterministic_config(max_agents=2)     # c_d = 25
    state = place(spec, cfg, [(0, 2), (0, 5)])   # vertices 1 and 4
    state.idle[0] = [100, 7, 60, 80, 3]
    info = step(spec, cfg, state, np.array([[STAY, STAY]]))
    grown = [101, 8, 61, 81, 4]
    f_after = [f(grown[0]), 0.0, f(grown[2]), f(grown[3]), 0.0]
    rp = team(f_after)
    for k, v in enumerate([1, 4]):
        without = list(f_after)
        without[v] = f(grown[v])
        d = rp - team(without)
        assert info.reward_patrol[0, k] == pytest.approx(0.5 * rp + 25.0 * d, rel=1e-12)


def test_difference_reward_is_zero_off_vertices(line_map):
    spec = line_map
    cfg = deterministic_config(max_agents=1)
    state = place(spec, cfg, [(0, 1)])
    state.idle[0] = [5, 5, 5, 5, 5]
    state.pos[0, 0] = spec.station               # an active agent standing on the station
    info = step(spec, cfg, state, np.array([[STAY]]))
    fs = [f(6)] * 5
    assert info.reward_patrol[0, 0] == pytest.approx(0.5 * team(fs), rel=1e-12)


def test_difference_reward_closed_form_matches_definition():
    rng = np.random.default_rng(0)
    V = 7
    for _ in range(50):
        f_after = rng.random(V)
        k = rng.integers(V)
        f_after[k] = 0.0
        f_k = rng.random()
        without = f_after.copy()
        without[k] = f_k
        d = difference_reward(np.array([[f_k]]), np.array([[True]]), np.array([f_after.mean()]),
                              np.array([f_after.max()]), V)
        assert d[0, 0] == pytest.approx(team(list(f_after)) - team(list(without)), abs=1e-12)


def test_battery_penalty_by_hand():
    cfg = make_config()                          # b_max 550, b_l = 110, c_pbb 1, c_pbm 20, c_pb 50
    battery = np.array([[550.0, 110.5, 110.0, 55.0, 1.0, 0.0, -0.3]])
    expected = [0.0, 0.0, -1.0, -(1 + 20 * 55 / 110), -(1 + 20 * 109 / 110), -50.0, -50.0]
    assert battery_reward(battery, cfg)[0] == pytest.approx(expected)
    # the penalty grows as the battery falls (SPEC's reading of the paper)
    low = battery_reward(np.linspace(110, 1, 50)[None], cfg)[0]
    assert (np.diff(low) < 0).all()


def test_battery_penalty_on_map_b_uses_its_base():
    cfg = make_config("B")
    assert cfg.c_pbb == 0.5
    assert battery_reward(np.array([[55.0]]), cfg)[0, 0] == pytest.approx(-(0.5 + 10.0))


def test_battery_penalty_in_a_step(line_map):
    spec = line_map
    cfg = deterministic_config(max_agents=2)
    state = place(spec, cfg, [(0, 1), (0, 3)], battery=[56.0, 200.0])
    info = step(spec, cfg, state, np.array([[STAY, STAY]]))
    assert list(info.reward_battery[0]) == pytest.approx([-(1 + 20 * 55 / 110), 0.0])


def test_collision_reward():
    cfg = make_config(c_pc=2.0)
    assert list(collision_reward(np.array([[True, False]]), cfg)[0]) == [-2.0, 0.0]


def test_inactive_slot_reward_is_zero(line_map):
    spec = line_map
    cfg = deterministic_config(max_agents=3)
    state = place(spec, cfg, [(0, 1)])
    info = step(spec, cfg, state, np.array([[STAY, STAY, STAY]]))
    assert list(info.reward[0, 1:]) == [0.0, 0.0]
    assert info.reward[0, 0] != 0.0


def test_an_agent_saved_by_its_arrival_gets_the_low_battery_penalty_not_the_failure_one():
    from patrolsb3.core import parse_map, reset_state, step
    from patrolsb3.core.config import make_config
    spec = parse_map("S..")
    cfg = make_config(None, max_agents=1, p_dyn_max=0.0, drain=(1.0, 1.0))
    state = reset_state(spec, cfg, 1, seed=0)
    state.pos[0, 0] = 1                                   # next to the station
    state.battery[0, 0] = 0.5                             # runs out during the move home
    info = step(spec, cfg, state, [[2]])                  # Left, onto the station
    assert info.swap_started[0, 0] and not info.battery_failed[0, 0]
    assert info.reward_battery[0, 0] == pytest.approx(-(cfg.c_pbb + cfg.c_pbm), rel=1e-6)


def test_home_potential_by_hand():
    cfg = make_config(c_home=50.0)               # b_l = 110: urgency from 220 units down
    battery = np.array([[550.0, 220.0, 165.0, 110.0, 0.0]])
    steps = np.array([[6, 6, 6, 6, 6]])
    expected = [0.0, 0.0, -50 * 0.25 * 0.25, -50 * 0.25 * 0.5, -50 * 0.25 * 1.0]
    assert home_potential(steps, battery, cfg, 24.0)[0] == pytest.approx(expected)
    assert home_potential(np.zeros((1, 5)), battery, cfg, 24.0)[0] == pytest.approx([0.0] * 5)


def test_home_shaping_is_off_by_default(line_map):
    spec = line_map
    cfg = deterministic_config(max_agents=1)
    state = place(spec, cfg, [(0, 3)], battery=[20.0])
    info = step(spec, cfg, state, np.array([[2]]))   # Left, toward the station
    assert info.reward_home[0, 0] == 0.0


def test_home_shaping_in_a_step_by_hand(line_map):
    spec = line_map                              # "S.....", 1 x 6: H + W = 7
    cfg = deterministic_config(max_agents=2, c_home=70.0)
    state = place(spec, cfg, [(0, 3), (0, 4)], battery=[110.0, 110.0])
    info = step(spec, cfg, state, np.array([[2, 3]]))  # slot 0 Left (home), slot 1 Right (away)
    urgency_before, urgency_after = 110 / 220, 111 / 220  # one unit drained
    toward = -70 * (2 / 7) * urgency_after + 70 * (3 / 7) * urgency_before
    away = -70 * (5 / 7) * urgency_after + 70 * (4 / 7) * urgency_before
    assert info.reward_home[0] == pytest.approx([toward, away])
    assert toward > 0 > away
    assert info.reward[0] == pytest.approx(info.reward_patrol[0] + info.reward_battery[0]
                                           + info.reward_home[0])


def test_home_shaping_pays_back_the_trip_on_arrival_and_nothing_on_failure(line_map):
    spec = line_map
    cfg = deterministic_config(max_agents=2, c_home=70.0)
    state = place(spec, cfg, [(0, 1), (0, 4)], battery=[50.0, 1.0])
    info = step(spec, cfg, state, np.array([[2, 2]]))  # slot 0 onto the station, slot 1 runs dry
    assert info.swap_started[0, 0] and info.battery_failed[0, 1]
    assert info.reward_home[0, 0] == pytest.approx(70 * (1 / 7) * (170 / 220))
    assert info.reward_home[0, 1] == 0.0


def test_a_negative_home_shaping_weight_is_refused():
    with pytest.raises(ValueError, match="c_home must be a finite number >= 0, got -1"):
        make_config(c_home=-1.0)
