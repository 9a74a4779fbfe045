"""patrolsb3.core.observe: actor grid orientation on a non-square map, values, vector, critic."""
import math

import numpy as np
import pytest

from patrolsb3.core.observe import VECTOR_SIZE, actor_observation, critic_state, vector_size

from conftest import deterministic_config, place

SCALE = 18.0   # n_symbols + 2


@pytest.fixture
def observed(non_square_map):
    spec = non_square_map            # "S..#..2" / ".#....." / "...#5.."
    cfg = deterministic_config(max_agents=3)
    state = place(spec, cfg, [(1, 4), (2, 6)], battery=[275.0, 550.0])
    state.messages[0] = [3, 0, 0]
    return spec, cfg, state


def test_channel_zero_orientation_and_values(observed):
    spec, cfg, state = observed
    grid, vector = actor_observation(spec, cfg, state)
    assert grid.shape == (1, 3, 2, 3, 7) and grid.dtype == np.float32
    me, other = grid[0, 0, 0], grid[0, 1, 0]
    assert me[1, 4] == pytest.approx(4 / SCALE)        # own cell, symbol 3: +(1 + 3) / 18
    assert me[2, 6] == pytest.approx(-1 / SCALE)       # the other agent, silent: -(1 + 0) / 18
    assert other[1, 4] == pytest.approx(-4 / SCALE)
    assert other[2, 6] == pytest.approx(1 / SCALE)
    assert me[0, 0] == 1.0 and me[0, 3] == -1.0 and me[2, 3] == -1.0 and me[1, 1] == -1.0
    assert me[0, 1] == 0.0 and me[1, 6] == 0.0
    # nothing else is drawn: exactly two agent cells
    agents = (me != 0) & (me != 1) & (me != -1)
    assert list(zip(*np.nonzero(agents))) == [(1, 4), (2, 6)]
    # the absent slot sees the others but not itself
    absent = grid[0, 2, 0]
    assert absent[1, 4] == pytest.approx(-4 / SCALE) and absent[2, 6] == pytest.approx(-1 / SCALE)


def test_station_value_differs_from_every_agent_value():
    values = [(1 + m) / SCALE for m in range(17)]
    assert max(values) < 1.0 and min(values) > 0.0


def test_agent_on_the_station_is_seen_only_by_itself(observed):
    spec, cfg, state = observed
    state.pos[0, 1] = spec.station
    grid, _ = actor_observation(spec, cfg, state)
    assert grid[0, 0, 0, 0, 0] == 1.0
    assert grid[0, 1, 0, 0, 0] == pytest.approx(1 / SCALE)


def test_channel_one_idleness(observed):
    spec, cfg, state = observed
    v_far = spec.vertex_of_cell[6]                     # (0, 6)
    v_new = spec.vertex_of_cell[2 * 7 + 0]             # (2, 0)
    state.idle[0, v_far] = 200.0
    state.visited[0, v_new] = False
    grid, _ = actor_observation(spec, cfg, state)
    idle = grid[0, 0, 1]
    assert idle[0, 6] == pytest.approx(1 - math.exp(-1), rel=1e-6)
    assert idle[2, 0] == 1.0                           # never visited
    assert idle[0, 0] == 0.0                           # station
    assert idle[0, 3] == -1.0 and idle[1, 1] == -1.0   # obstacles
    assert idle[1, 4] == 0.0
    assert np.array_equal(grid[0, 0, 1], grid[0, 2, 1])  # same for every observer


def test_vector(observed):
    spec, cfg, state = observed
    _, vector = actor_observation(spec, cfg, state, phase=0)
    assert vector.shape == (1, 3, VECTOR_SIZE)
    assert list(vector[0, 0, :8]) == [0.5, 1, 1, 1, 1, 1, 0, 1]     # (1, 4): every move free
    assert list(vector[0, 1, :8]) == [1.0, 1, 0, 1, 0, 1, 0, 1]     # (2, 6): Down, Right leave the grid
    assert list(vector[0, 2, :8]) == [1.0, 0, 0, 0, 0, 1, 0, 0]     # absent: Stay only, inactive
    # home features: (1, 4) is 5 steps from the station, first move Left; (2, 6) is 8 steps,
    # Up and Left tie and the lower action index (Up) wins; H + W = 10
    np.testing.assert_allclose(vector[0, 0, 8:], [0.5, 0.5 - 5 * cfg.drain[1] / 550, 0, 0, 1, 0, 0], rtol=1e-6)
    np.testing.assert_allclose(vector[0, 1, 8:], [0.8, 1.0 - 8 * cfg.drain[1] / 550, 1, 0, 0, 0, 0], rtol=1e-6)
    assert not vector[0, 2, 8:].any()
    _, vector = actor_observation(spec, cfg, state, phase=1)
    assert vector[0, 0, 6] == 1


def test_critic_state_pads_empty_slots_with_the_station(observed):
    spec, cfg, state = observed
    critic = critic_state(spec, cfg, state)
    assert critic.shape == (1, 9) and critic.dtype == np.float32
    assert list(critic[0]) == pytest.approx([0.5, 0.5, 4 / 6, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0])


def test_local_idleness_copies_the_idleness_of_the_cell_each_move_leads_to(non_square_map):
    spec = non_square_map            # "S..#..2" / ".#....." / "...#5.."
    cfg = deterministic_config(max_agents=3, local_idleness=True)
    state = place(spec, cfg, [(1, 4), (2, 6)], battery=[275.0, 550.0])
    state.idle[0, spec.vertex_of_cell[0 * 7 + 4]] = 200.0     # above agent 0
    state.visited[0, spec.vertex_of_cell[2 * 7 + 4]] = False  # below agent 0: never visited
    grid, vector = actor_observation(spec, cfg, state)
    assert vector.shape == (1, 3, vector_size(cfg)) == (1, 3, VECTOR_SIZE + 5)
    np.testing.assert_allclose(vector[0, 0, VECTOR_SIZE:], [1 - math.exp(-1), 1, 0, 0, 0], rtol=1e-6)
    assert list(vector[0, 1, VECTOR_SIZE:]) == [0, -1, 0, -1, 0]    # Down, Right leave the grid
    assert not vector[0, 2, VECTOR_SIZE:].any()                      # absent slot
    # the first VECTOR_SIZE values are those of the paper's layout, unchanged
    _, plain = actor_observation(spec, deterministic_config(max_agents=3), state)
    assert np.array_equal(vector[..., :VECTOR_SIZE], plain)
    # the values are grid channel 1 next to the agent: Up from (1, 4) reads (0, 4)
    assert vector[0, 0, VECTOR_SIZE] == grid[0, 0, 1, 0, 4]


def test_symbol_planes_are_legible(non_square_map):
    """message_encoding='planes': positions at full scale on channel 0, one plane per symbol."""
    spec = non_square_map
    cfg = deterministic_config(max_agents=3, message_encoding="planes")
    state = place(spec, cfg, [(1, 4), (2, 6)], battery=[275.0, 550.0])
    state.messages[0] = [3, 16, 0]
    grid, _ = actor_observation(spec, cfg, state)
    assert grid.shape == (1, 3, 2 + 16, 3, 7)
    me, other, absent = grid[0, 0], grid[0, 1], grid[0, 2]
    assert me[0, 1, 4] == 1.0 and me[0, 2, 6] == -0.5 and me[0, 0, 0] == 0.5 and me[0, 0, 3] == -1.0
    assert other[0, 1, 4] == -0.5 and other[0, 2, 6] == 1.0
    # plane 1 + s holds symbol s: own +1, others -1, nothing else anywhere
    assert me[1 + 3, 1, 4] == 1.0 and me[1 + 16, 2, 6] == -1.0
    assert other[1 + 3, 1, 4] == -1.0 and other[1 + 16, 2, 6] == 1.0
    assert np.count_nonzero(me[2:]) == 2 and np.count_nonzero(other[2:]) == 2
    assert absent[0, 1, 4] == -0.5 and absent[1 + 3, 1, 4] == -1.0 and np.count_nonzero(absent[2:]) == 2
    # idleness is channel 1 in both encodings
    scalar, _ = actor_observation(spec, deterministic_config(max_agents=3), state)
    np.testing.assert_array_equal(grid[:, :, 1], scalar[:, :, 1])
