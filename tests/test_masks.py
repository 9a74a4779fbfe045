"""patrolsb3.core.masks: move masks on a non-square map, and the composite (message, move) masks."""
import numpy as np

from patrolsb3.bench.env import random_valid_moves
from patrolsb3.core import load_map, make_config, step
from patrolsb3.core.masks import action_mask, composite_action_mask, move_allowed, return_threshold
from patrolsb3.core.observe import actor_observation
from patrolsb3.core.state import FAILED, SWAPPING, reset_state

from conftest import cell, deterministic_config, place

#                     Up     Down   Left   Right  Stay
ONLY_STAY = [False, False, False, False, True]


def test_masks_on_a_non_square_map(non_square_map):
    spec = non_square_map            # "S..#..2" / ".#....." / "...#5.."
    cfg = deterministic_config(max_agents=4)
    state = place(spec, cfg, [(1, 4), (1, 5), (1, 0), (0, 6)])
    mask = action_mask(spec, state)
    assert mask.shape == (1, 4, 5) and mask.dtype == bool
    assert list(mask[0, 0]) == [True, True, True, False, True]     # Right: (1, 5) occupied
    assert list(mask[0, 1]) == [True, True, False, True, True]     # Left: (1, 4) occupied
    assert list(mask[0, 2]) == [True, True, False, False, True]    # Left: border, Right: obstacle
    assert list(mask[0, 3]) == [False, True, True, False, True]    # Up and Right: border


def test_occupied_station_stays_enterable(non_square_map):
    spec = non_square_map
    cfg = deterministic_config(max_agents=3)
    state = place(spec, cfg, [(0, 1), (1, 0), (2, 0)])
    state.pos[0, 2] = spec.station
    mask = action_mask(spec, state)[0]
    assert mask[0, 2] and mask[1, 0]       # Left from (0, 1), Up from (1, 0): both into S
    assert not mask[2, 1]                  # Down from the station: (1, 0) is occupied


def test_inactive_agents_block_nothing_and_may_only_stay(line_map):
    spec = line_map
    cfg = deterministic_config(max_agents=3)
    state = place(spec, cfg, [(0, 1), (0, 2), (0, 4)])
    state.status[0, 1] = FAILED
    state.status[0, 2] = SWAPPING
    mask = action_mask(spec, state)[0]
    assert list(mask[0]) == [False, False, True, True, True]        # into the failed agent's cell
    assert list(mask[1]) == ONLY_STAY
    assert list(mask[2]) == ONLY_STAY


def test_batched_masks_follow_each_episode(line_map):
    spec = line_map
    cfg = deterministic_config(max_agents=2)
    two = reset_state(spec, cfg, 2, n_envs=2, seed=0)
    two.pos[:] = [[cell(spec, 0, 3), cell(spec, 0, 4)], [cell(spec, 0, 3), cell(spec, 0, 1)]]
    mask = action_mask(spec, two)
    assert list(mask[0, 0]) == [False, False, True, False, True]
    assert list(mask[1, 0]) == [False, False, True, True, True]


def test_composite_masks_by_phase_and_mode(line_map):
    spec = line_map
    state_cfg = deterministic_config(max_agents=2)
    state = place(spec, state_cfg, [(0, 1)])                       # slot 1 absent
    move_mask = action_mask(spec, state)

    cfg = deterministic_config(max_agents=2, comm="learned")
    message, move = composite_action_mask(spec, cfg, state, message_phase=True)
    assert message.shape == (1, 2, 16) and move.shape == (1, 2, 5)
    assert message[0, 0].all()
    assert list(move[0, 0]) == ONLY_STAY
    assert list(np.flatnonzero(message[0, 1])) == [0] and list(move[0, 1]) == ONLY_STAY
    message, move = composite_action_mask(spec, cfg, state, message_phase=False)
    assert list(np.flatnonzero(message[0, 0])) == [0]
    assert np.array_equal(move, move_mask)

    cfg = deterministic_config(max_agents=2, comm="intention")
    message, move = composite_action_mask(spec, cfg, state, message_phase=True)
    assert list(message[0, 0, :5]) == list(move_mask[0, 0]) and not message[0, 0, 5:].any()

    cfg = deterministic_config(max_agents=2, comm="learned", message_timing="delayed")
    message, move = composite_action_mask(spec, cfg, state, message_phase=False)
    assert message[0, 0].all() and np.array_equal(move, move_mask)
    assert list(np.flatnonzero(message[0, 1])) == [0]

    cfg = deterministic_config(max_agents=2, comm="none")
    message, move = composite_action_mask(spec, cfg, state, message_phase=False)
    assert list(np.flatnonzero(message[0, 0])) == [0] and np.array_equal(move, move_mask)


def _mask_by_the_rule(spec, state):
    """The mask rule written out agent by agent (reference for the vectorised one)."""
    E, A = state.pos.shape
    station = spec.kinds.ravel() == 2
    mask = np.zeros((E, A, 5), dtype=bool)
    for e in range(E):
        for i in range(A):
            if not state.active[e, i]:
                mask[e, i, 4] = True
                continue
            for a in range(5):
                t = spec.neighbour[state.pos[e, i], a]
                taken = any(state.active[e, j] and state.pos[e, j] == t for j in range(A) if j != i)
                mask[e, i, a] = a == 4 or (spec.move_ok[state.pos[e, i], a] and (not taken or station[t]))
    return mask


def test_vectorised_mask_matches_the_rule_on_crowded_random_states():
    from patrolsb3.core import load_map, make_config
    from patrolsb3.core.maps import STATION
    assert STATION == 2
    rng = np.random.default_rng(0)
    for name in "ABCD":
        spec = load_map(name)
        state = reset_state(spec, make_config(name), 5, n_envs=200, seed=1)
        state.pos[:] = spec.free_cells[rng.integers(0, len(spec.free_cells), state.pos.shape)]
        for i in range(1, 5):   # crowd: each agent next to (or on) the one before it
            state.pos[:, i] = spec.neighbour[state.pos[:, i - 1], rng.integers(0, 5, len(state.pos))]
        state.status[rng.random(state.status.shape) < 0.2] = FAILED
        mask = action_mask(spec, state)
        assert np.array_equal(mask, _mask_by_the_rule(spec, state))
        assert 0.2 < mask[..., :4].mean() < 0.9     # the states exercise both outcomes
        for move in range(5):                        # the one-move check agrees with the mask
            moves = np.full(state.pos.shape, move)
            assert np.array_equal(move_allowed(spec, state, moves), mask[..., move])
        moves = rng.integers(0, 5, state.pos.shape)
        assert np.array_equal(move_allowed(spec, state, moves),
                              np.take_along_axis(mask, moves[..., None], axis=-1)[..., 0])


# --- env.return_guard: the learned policy's shield (OURS) ------------------------------------

def _due(cfg, spec, r, c):
    """The battery (units) at which an agent on (r, c) is just due home."""
    return float(return_threshold(spec, cfg)[cell(spec, r, c)])


def test_return_threshold_is_the_trip_home_with_margin_plus_b_low(line_map):
    spec = line_map                                                    # "S....."
    cfg = make_config(drain=(0.9, 1.1), p_dyn_max=0.04, push_drain_factor=1.5)
    margin = (1 + 0.04 * 0.5) * (1 + 2 * 0.04) * 1.25
    threshold = return_threshold(spec, cfg)
    assert threshold[cell(spec, 0, 0)] == cfg.b_low                    # on the station
    assert np.isclose(threshold[cell(spec, 0, 4)], 4 * 1.1 * margin + cfg.b_low)


def test_return_guard_is_off_by_default(middle_station_map):
    spec = middle_station_map                                          # "..S.."
    cfg = deterministic_config(max_agents=1)
    state = place(spec, cfg, [(0, 0)], battery=[1.0])
    assert not cfg.return_guard
    assert (action_mask(spec, state, cfg) == action_mask(spec, state)).all()


def test_return_guard_keeps_only_moves_home_once_due(middle_station_map):
    spec = middle_station_map                                          # "..S.."
    cfg = deterministic_config(max_agents=2, return_guard=True)
    due_left, due_right = _due(cfg, spec, 0, 0), _due(cfg, spec, 0, 4)
    state = place(spec, cfg, [(0, 0), (0, 4)], battery=[due_left, due_right])
    mask = action_mask(spec, state, cfg)[0]
    assert list(mask[0]) == [False, False, False, True, False]         # Right, toward S
    assert list(mask[1]) == [False, False, True, False, False]         # Left, toward S
    state.battery[0] += 0.5                                            # just above: free again
    assert (action_mask(spec, state, cfg) == action_mask(spec, state)).all()


def test_return_guard_sends_a_pushed_arrival_off_the_station_and_back(middle_station_map):
    spec = middle_station_map
    cfg = deterministic_config(max_agents=1, return_guard=True)
    state = place(spec, cfg, [(0, 2)], battery=[cfg.b_low])            # on S, not swapping
    assert list(action_mask(spec, state, cfg)[0, 0]) == [False, False, True, True, False]


def test_a_blocked_due_agent_waits_and_has_right_of_way(line_map):
    spec = line_map                                                    # "S....."
    cfg = deterministic_config(max_agents=3, return_guard=True)
    state = place(spec, cfg, [(0, 2), (0, 1), (0, 5)], battery=[_due(cfg, spec, 0, 2), cfg.b_max, cfg.b_max])
    assert list(action_mask(spec, state)[0, 0]) == [False, False, False, True, True]   # Left held
    mask = action_mask(spec, state, cfg)[0]
    assert list(mask[0]) == [False, False, False, False, True]         # waits
    assert list(mask[1]) == [False, False, True, False, False]         # gives way (onto S)
    assert list(mask[2]) == [False, False, True, False, True]          # not in the way: free


def test_an_agent_in_the_way_with_nowhere_to_go_may_stay(line_map):
    spec = line_map                                                    # "S....."
    cfg = deterministic_config(max_agents=3, return_guard=True)
    state = place(spec, cfg, [(0, 3), (0, 2), (0, 1)], battery=[_due(cfg, spec, 0, 3), cfg.b_max, cfg.b_max])
    mask = action_mask(spec, state, cfg)[0]
    assert list(mask[0]) == ONLY_STAY                                  # waits behind slot 1
    assert list(mask[1]) == ONLY_STAY                                  # in the way, boxed in
    assert list(mask[2]) == [False, False, True, False, True]          # not in the way: free


def test_return_guard_reaches_the_composite_mask_and_the_observation(middle_station_map):
    spec = middle_station_map
    cfg = deterministic_config(max_agents=1, return_guard=True)
    state = place(spec, cfg, [(0, 0)], battery=[_due(cfg, spec, 0, 0)])
    _, move = composite_action_mask(spec, cfg, state, message_phase=False)
    _, vector = actor_observation(spec, cfg, state, phase=1)
    assert list(move[0, 0]) == [False, False, False, True, False]
    assert list(vector[0, 0, 1:6]) == [0, 0, 0, 1, 0]


def test_random_walkers_behind_the_guard_never_run_dry_on_map_a():
    """Agents that move at random among the guarded moves still reach the station in time
    (wind, drain noise and traffic as in the paper), where unguarded ones run dry."""
    spec = load_map("A")
    failures = {}
    for guard in (False, True):
        cfg = make_config("A", max_agents=3, init_battery=(0.15, 0.4), return_guard=guard)
        state = reset_state(spec, cfg, 3, n_envs=8, seed=1)
        rng = np.random.default_rng(1)
        failed = swaps = 0
        for _ in range(1500):
            info = step(spec, cfg, state, random_valid_moves(action_mask(spec, state, cfg), rng))
            failed += int(info.battery_failed.sum())
            swaps += int(info.swap_started.sum())
        failures[guard] = failed
        if guard:
            assert swaps >= 24                                         # everyone swapped at least once
    assert failures[True] == 0 and failures[False] > 0
