"""patrolsb3.core.step: scripted steps on tiny maps with exact positions, rewards and idleness."""
import numpy as np
import pytest

from patrolsb3.core.maps import DOWN, LEFT, RIGHT, STAY, UP
from patrolsb3.core.masks import action_mask
from patrolsb3.core.state import ABSENT, ACTIVE, FAILED, SWAPPING, reset_state
from patrolsb3.core.step import InvalidActionError, resolve_collisions, step

from conftest import cell, deterministic_config, place, streams_drawing_pushes


def moves(*m):
    """(1, A) move array."""
    return np.array([m], dtype=np.int64)


# ---------------------------------------------------------------- plain moves, idleness
def test_free_moves_land_where_expected(non_square_map):
    spec = non_square_map
    cfg = deterministic_config(max_agents=2)
    state = place(spec, cfg, [(1, 2), (2, 5)])
    info = step(spec, cfg, state, moves(RIGHT, UP))
    assert list(state.pos[0]) == [cell(spec, 1, 3), cell(spec, 1, 5)]
    assert info.collisions[0] == 0 and not info.collided.any() and not info.pushed.any()
    assert list(state.battery[0]) == [cfg.b_max - 1.0, cfg.b_max - 1.0]
    assert state.t[0] == 1


def test_idleness_grows_by_one_plus_priority_and_resets_under_agents(room_map):
    spec = room_map                                   # "3..\n.S.\n..." : priority 3 at (0, 0)
    cfg = deterministic_config(max_agents=1)
    state = place(spec, cfg, [(2, 2)])
    assert spec.rate[spec.vertex_of_cell[0]] == 4.0
    for _ in range(3):
        info = step(spec, cfg, state, moves(STAY))
    expected = 3 * spec.rate.copy()
    expected[spec.vertex_of_cell[cell(spec, 2, 2)]] = 0.0
    assert np.array_equal(state.idle[0], expected)
    assert expected[spec.vertex_of_cell[0]] == 12.0
    assert info.mean_idleness[0] == pytest.approx(expected.mean())
    assert info.max_idleness[0] == 12.0
    info = step(spec, cfg, state, moves(UP))          # (2, 2) -> (1, 2)
    expected = expected + spec.rate
    expected[spec.vertex_of_cell[cell(spec, 1, 2)]] = 0.0
    assert np.array_equal(state.idle[0], expected)
    assert state.idle[0, spec.vertex_of_cell[cell(spec, 2, 2)]] == 1.0
    assert state.idle[0, spec.vertex_of_cell[0]] == 16.0


def test_reset_starts_on_distinct_vertices_with_idleness_zero(non_square_map):
    spec = non_square_map
    cfg = deterministic_config(max_agents=5)
    state = reset_state(spec, cfg, [5, 2], n_envs=2, seed=3)
    assert state.pos.shape == (2, 5)
    for e, n in enumerate([5, 2]):
        cells = state.pos[e, :n]
        assert len(set(cells.tolist())) == n
        assert (spec.vertex_of_cell[cells] >= 0).all()           # vertices, not the station
        assert list(state.status[e]) == [ACTIVE] * n + [ABSENT] * (5 - n)
        assert (state.battery[e, :n] >= 0.9 * cfg.b_max).all()
        assert (state.battery[e, :n] <= cfg.b_max).all()
        visited = np.zeros(spec.n_vertices, dtype=bool)
        visited[spec.vertex_of_cell[cells]] = True
        assert np.array_equal(state.visited[e], visited)
    assert (state.idle == 0).all()


def test_team_larger_than_slots_or_vertices_is_refused(line_map):
    with pytest.raises(ValueError, match="n_agents=4 is larger than max_agents=3"):
        reset_state(line_map, deterministic_config(max_agents=3), 4)
    with pytest.raises(ValueError, match="n_agents=6 is larger than the 5 vertices of map line"):
        reset_state(line_map, deterministic_config(max_agents=8), 6)
    with pytest.raises(ValueError, match="n_agents must be >= 1"):
        reset_state(line_map, deterministic_config(max_agents=3), 0)


# ---------------------------------------------------------------- masked moves
def test_masked_move_raises_a_clear_error(line_map):
    spec = line_map
    cfg = deterministic_config(max_agents=2)
    state = place(spec, cfg, [(0, 1), (0, 2)])
    with pytest.raises(InvalidActionError,
                       match=r"agent 0 at \(row 0, col 1\) chose Right, which its action mask forbids"):
        step(spec, cfg, state, moves(RIGHT, STAY))
    with pytest.raises(InvalidActionError, match="chose Up"):
        step(spec, cfg, state, moves(UP, STAY))     # out of the 1-row grid
    with pytest.raises(InvalidActionError, match="move 7 outside 0..4"):
        step(spec, cfg, state, moves(7, STAY))
    with pytest.raises(ValueError, match=r"moves must have shape \(1, 2\)"):
        step(spec, cfg, state, np.array([RIGHT]))
    assert state.t[0] == 0                           # nothing happened


def test_masked_move_is_stay_when_configured(line_map):
    spec = line_map
    cfg = deterministic_config(max_agents=2, invalid_action="stay")
    state = place(spec, cfg, [(0, 1), (0, 2)])
    info = step(spec, cfg, state, moves(RIGHT, UP))
    assert list(state.pos[0]) == [1, 2]
    assert info.collisions[0] == 0


def test_inactive_slots_are_forced_to_stay(line_map):
    spec = line_map
    cfg = deterministic_config(max_agents=3)
    state = place(spec, cfg, [(0, 3)])               # slots 1 and 2 absent, parked on the station
    step(spec, cfg, state, moves(LEFT, RIGHT, DOWN))
    assert list(state.pos[0]) == [2, 0, 0]
    assert list(state.status[0]) == [ACTIVE, ABSENT, ABSENT]


# ---------------------------------------------------------------- collisions
def test_vertex_conflict_one_random_winner_one_event_both_penalised(line_map):
    spec = line_map
    cfg = deterministic_config(max_agents=2)
    wins = [0, 0]
    for seed in range(200):
        state = place(spec, cfg, [(0, 1), (0, 3)], seed=seed)
        info = step(spec, cfg, state, moves(RIGHT, LEFT))    # both head for (0, 2)
        pos = list(state.pos[0])
        assert pos in ([2, 3], [1, 2])
        wins[pos.index(2)] += 1
        assert info.collisions[0] == 1
        assert list(info.collided[0]) == [True, True]
        assert list(info.reward_collision[0]) == [-cfg.c_pc, -cfg.c_pc]
        assert np.allclose(info.reward[0], info.reward_patrol[0] - cfg.c_pc)
    assert 70 <= wins[0] <= 130 and wins[0] + wins[1] == 200   # uniform winner


def test_contested_cell_with_three_movers_is_one_event():
    from patrolsb3.core import parse_map
    spec = parse_map(".#.\n...\nS..")               # (1, 1) reached from three sides
    cfg = deterministic_config(max_agents=3)
    state = place(spec, cfg, [(1, 0), (1, 2), (2, 1)], seed=1)
    info = step(spec, cfg, state, moves(RIGHT, LEFT, UP))
    assert info.collisions[0] == 1
    assert info.collided[0].all()
    assert (state.pos[0] == cell(spec, 1, 1)).sum() == 1
    assert set(state.pos[0].tolist()) <= {cell(spec, 1, 0), cell(spec, 1, 2), cell(spec, 2, 1), cell(spec, 1, 1)}


def test_swap_conflict_by_two_pushes_both_stay(line_map):
    spec = line_map
    cfg = deterministic_config(max_agents=2)
    state = place(spec, cfg, [(0, 2), (0, 3)])
    state.p_dyn[0] = 1.0
    state.streams = streams_drawing_pushes(2, {0: RIGHT, 1: LEFT})
    info = step(spec, cfg, state, moves(STAY, STAY))
    assert list(info.pushed[0]) == [True, True]
    assert list(state.pos[0]) == [2, 3]
    assert info.collisions[0] == 1
    assert list(info.reward_collision[0]) == [-1.0, -1.0]
    assert list(state.battery[0]) == [cfg.b_max - 1.5, cfg.b_max - 1.5]   # pushed drain x 1.5


def test_swap_conflict_rule_directly(line_map):
    pos = np.array([[2, 3, 5]])
    target = np.array([[3, 2, 4]])
    new_pos, collided, events = resolve_collisions(line_map, pos, target, np.ones((1, 3), bool),
                                                   np.random.default_rng(0).random((1, 3)))
    assert list(new_pos[0]) == [2, 3, 4]
    assert list(collided[0]) == [True, True, False]
    assert events[0] == 1


def test_chain_moves_when_the_front_agent_moves(line_map):
    spec = line_map
    cfg = deterministic_config(max_agents=2)
    state = place(spec, cfg, [(0, 1), (0, 2)])
    state.p_dyn[0, 0] = 1.0                        # slot 0 is pushed into slot 1's cell
    state.streams = streams_drawing_pushes(2, {0: RIGHT})
    info = step(spec, cfg, state, moves(STAY, RIGHT))
    assert list(info.pushed[0]) == [True, False]
    assert list(state.pos[0]) == [2, 3]
    assert info.collisions[0] == 0 and not info.collided.any()
    assert list(state.battery[0]) == [cfg.b_max - 1.5, cfg.b_max - 1.0]


def test_chain_blocked_when_the_front_agent_stays(line_map):
    spec = line_map
    cfg = deterministic_config(max_agents=2)
    state = place(spec, cfg, [(0, 1), (0, 2)])
    state.p_dyn[0, 0] = 1.0
    state.streams = streams_drawing_pushes(2, {0: RIGHT})
    info = step(spec, cfg, state, moves(STAY, STAY))
    assert info.pushed[0, 0]
    assert list(state.pos[0]) == [1, 2]
    assert info.collisions[0] == 0 and not info.collided.any()


def test_chain_behind_a_contest_follows_its_front_agent(line_map):
    # slot 0 follows slot 1, which contests cell 3 with slot 2: slot 0 moves iff slot 1 wins
    outcomes = set()
    for seed in range(40):
        new_pos, collided, events = resolve_collisions(
            line_map, np.array([[1, 2, 4]]), np.array([[2, 3, 3]]), np.ones((1, 3), bool),
            np.random.default_rng(seed).random((1, 3)))
        outcomes.add(tuple(new_pos[0]))
        assert list(collided[0]) == [False, True, True] and events[0] == 1
    assert outcomes == {(2, 3, 4), (1, 2, 3)}


def test_push_into_a_wall_leaves_the_agent_in_place(non_square_map):
    spec = non_square_map                          # (0, 3) is an obstacle
    cfg = deterministic_config(max_agents=1)
    state = place(spec, cfg, [(0, 2)])
    state.p_dyn[0, 0] = 1.0
    state.streams = streams_drawing_pushes(1, {0: RIGHT})
    info = step(spec, cfg, state, moves(LEFT))     # the push replaces the chosen move
    assert info.pushed[0, 0]
    assert state.pos[0, 0] == cell(spec, 0, 2)
    assert state.battery[0, 0] == cfg.b_max - 1.5


def test_push_out_of_the_grid_leaves_the_agent_in_place(non_square_map):
    spec = non_square_map
    cfg = deterministic_config(max_agents=1)
    state = place(spec, cfg, [(0, 5)])
    state.p_dyn[0, 0] = 1.0
    state.streams = streams_drawing_pushes(1, {0: UP})
    step(spec, cfg, state, moves(DOWN))
    assert state.pos[0, 0] == cell(spec, 0, 5)


def test_push_direction_is_the_drawn_one(non_square_map):
    spec = non_square_map
    cfg = deterministic_config(max_agents=1)
    for direction, expected in [(UP, (0, 4)), (DOWN, (2, 4)), (LEFT, (1, 3)), (RIGHT, (1, 5))]:
        state = place(spec, cfg, [(1, 4)])
        state.p_dyn[0, 0] = 1.0
        state.streams = streams_drawing_pushes(1, {0: direction})
        step(spec, cfg, state, moves(STAY))
        assert state.pos[0, 0] == cell(spec, *expected)


# ---------------------------------------------------------------- hot swaps, station
def test_hot_swap_starts_and_ends_after_the_drawn_time(line_map):
    spec = line_map
    cfg = deterministic_config(max_agents=1)
    state = place(spec, cfg, [(0, 1)], battery=[300.0])
    info = step(spec, cfg, state, moves(LEFT))
    assert state.pos[0, 0] == spec.station
    assert state.status[0, 0] == SWAPPING
    assert info.swap_started[0, 0]
    assert info.swap_battery[0, 0] == pytest.approx(299.0 / cfg.b_max)
    duration = int(state.swap_left[0, 0])
    assert cfg.swap_time[0] <= duration <= cfg.swap_time[1]
    for k in range(duration - 1):
        info = step(spec, cfg, state, moves(RIGHT))      # offline: any move is forced to Stay
        assert state.status[0, 0] == SWAPPING and not info.swap_ended[0, 0]
        assert info.reward[0, 0] == 0.0 and not info.acted[0, 0]
    assert state.battery[0, 0] == 299.0                  # no drain while offline
    info = step(spec, cfg, state, moves(STAY))
    assert info.swap_ended[0, 0]
    assert state.status[0, 0] == ACTIVE
    assert state.battery[0, 0] == cfg.b_max
    assert state.pos[0, 0] == spec.station
    assert state.t[0] == duration + 1
    # the fresh agent is on the grid again: it may leave the station, which costs a unit
    step(spec, cfg, state, moves(RIGHT))
    assert state.pos[0, 0] == 1 and state.battery[0, 0] == cfg.b_max - 1.0


def test_swap_time_bounds_are_respected():
    from patrolsb3.core import parse_map
    spec = parse_map("S.")
    cfg = deterministic_config(max_agents=1, swap_time=(3, 3))
    state = place(spec, cfg, [(0, 1)])
    step(spec, cfg, state, moves(LEFT))
    assert state.swap_left[0, 0] == 3
    statuses = []
    for _ in range(3):
        step(spec, cfg, state, moves(STAY))
        statuses.append(int(state.status[0, 0]))
    assert statuses == [SWAPPING, SWAPPING, ACTIVE]


def test_pushed_arrival_on_the_station_does_not_swap(line_map):
    spec = line_map
    cfg = deterministic_config(max_agents=1)
    state = place(spec, cfg, [(0, 1)])
    state.p_dyn[0, 0] = 1.0
    state.streams = streams_drawing_pushes(1, {0: LEFT})
    info = step(spec, cfg, state, moves(RIGHT))
    assert state.pos[0, 0] == spec.station
    assert state.status[0, 0] == ACTIVE and not info.swap_started[0, 0]
    state.p_dyn[0, 0] = 0.0
    info = step(spec, cfg, state, moves(STAY))            # staying on the station is no arrival
    assert state.status[0, 0] == ACTIVE and not info.swap_started[0, 0]


def test_station_is_shared(middle_station_map):
    spec = middle_station_map                            # "..S.."
    cfg = deterministic_config(max_agents=3)
    state = place(spec, cfg, [(0, 1), (0, 3), (0, 4)])
    state.pos[0, 2] = spec.station                       # a fresh agent already on the station
    mask = action_mask(spec, state)[0]
    assert list(mask[0]) == [False, False, True, True, True]   # Right into the occupied station
    assert list(mask[1]) == [False, False, True, True, True]
    assert list(mask[2]) == [False, False, False, False, True]  # (0, 1), (0, 3) taken
    info = step(spec, cfg, state, moves(RIGHT, LEFT, STAY))
    assert list(state.pos[0]) == [2, 2, 2]
    assert info.collisions[0] == 0 and not info.collided.any()
    assert list(info.swap_started[0]) == [True, True, False]
    assert list(state.status[0]) == [SWAPPING, SWAPPING, ACTIVE]


# ---------------------------------------------------------------- failures
def test_battery_failure_penalised_once_then_slot_inactive(line_map):
    spec = line_map
    cfg = deterministic_config(max_agents=2)
    state = place(spec, cfg, [(0, 2), (0, 4)], battery=[0.5, cfg.b_max])
    info = step(spec, cfg, state, moves(STAY, STAY))
    assert list(info.battery_failed[0]) == [True, False]
    assert list(state.status[0]) == [FAILED, ACTIVE]
    assert state.battery[0, 0] == 0.0
    assert info.reward_battery[0, 0] == -cfg.c_pb
    assert info.reward[0, 0] == pytest.approx(info.reward_patrol[0, 0] - cfg.c_pb)
    assert not info.terminated[0]
    # the failed agent blocks nothing: slot 1 may walk through its cell
    info = step(spec, cfg, state, moves(STAY, LEFT))
    info = step(spec, cfg, state, moves(STAY, LEFT))
    assert state.pos[0, 1] == 2
    assert info.reward[0, 0] == 0.0 and not info.battery_failed[0, 0] and not info.acted[0, 0]
    assert state.status[0, 0] == FAILED


def test_last_failure_terminates_the_episode(line_map):
    spec = line_map
    cfg = deterministic_config(max_agents=2)
    state = place(spec, cfg, [(0, 3)], battery=[1.0])
    info = step(spec, cfg, state, moves(STAY, STAY))
    assert info.battery_failed[0, 0] and info.terminated[0]


def test_arriving_on_the_station_with_the_last_unit_is_a_swap_not_a_failure(line_map):
    spec = line_map
    cfg = deterministic_config(max_agents=1)
    state = place(spec, cfg, [(0, 1)], battery=[0.5])
    info = step(spec, cfg, state, moves(LEFT))
    assert info.swap_started[0, 0] and not info.battery_failed[0, 0]
    assert state.status[0, 0] == SWAPPING


def test_scheduled_fault_removes_k_agents_at_that_step(line_map):
    spec = line_map
    cfg = deterministic_config(max_agents=3, faults=((2, 1),))
    state = place(spec, cfg, [(0, 1), (0, 3), (0, 5)])
    for t in range(5):
        info = step(spec, cfg, state, moves(STAY, STAY, STAY))
        assert info.fault_failed[0].sum() == (1 if t == 2 else 0)
        assert (state.status[0] == FAILED).sum() == (0 if t < 2 else 1)
        assert not info.battery_failed.any()
    failed = int(np.flatnonzero(state.status[0] == FAILED)[0])
    # the failed slot earns nothing afterwards, the others keep patrolling
    assert info.reward[0, failed] == 0.0
    assert all(info.reward[0, k] > 0 for k in range(3) if k != failed)


def test_fault_of_the_whole_team_terminates(line_map):
    spec = line_map
    cfg = deterministic_config(max_agents=3, faults=((0, 5),))
    state = place(spec, cfg, [(0, 1), (0, 3)])
    info = step(spec, cfg, state, moves(STAY, STAY, STAY))
    assert list(info.fault_failed[0]) == [True, True, False]   # the absent slot cannot fail
    assert info.terminated[0]


def test_fault_probability_one_fails_every_active_agent(line_map):
    spec = line_map
    cfg = deterministic_config(max_agents=2, fault_prob=1.0)
    state = place(spec, cfg, [(0, 1), (0, 3)])
    info = step(spec, cfg, state, moves(STAY, STAY))
    assert info.fault_failed[0].all() and info.terminated[0]


def test_truncation_after_episode_steps(line_map):
    spec = line_map
    cfg = deterministic_config(max_agents=1, episode_steps=3)
    state = place(spec, cfg, [(0, 1)])
    flags = [bool(step(spec, cfg, state, moves(STAY)).truncated[0]) for _ in range(3)]
    assert flags == [False, False, True]


def test_batched_episodes_are_independent(line_map):
    spec = line_map
    cfg = deterministic_config(max_agents=1)
    state = reset_state(spec, cfg, 1, n_envs=3, seed=0)
    state.pos[:, 0] = [1, 3, 5]
    state.p_dyn[:] = 0.0
    step(spec, cfg, state, np.array([[LEFT], [RIGHT], [LEFT]]))
    assert list(state.pos[:, 0]) == [0, 4, 4]
    assert list(state.status[:, 0]) == [SWAPPING, ACTIVE, ACTIVE]
