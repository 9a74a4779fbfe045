"""The agent protocol (core/protocol.py): phases, symbols, layout, masks, checks, application."""
import copy

import numpy as np
import pytest

from patrolsb3.core import InvalidActionError, make_config, parse_map, protocol, reset_state
from patrolsb3.core.maps import STAY
from patrolsb3.core.masks import action_mask, composite_action_mask
from patrolsb3.core.observe import actor_observation, critic_state

from conftest import NON_SQUARE

H, W = 3, 7


@pytest.fixture
def spec():
    return parse_map(NON_SQUARE, name="non_square")


def test_phases_of_each_mode():
    learned, none = make_config(comm="learned"), make_config(comm="none")
    delayed = make_config(comm="learned", message_timing="delayed")
    assert protocol.first_phase(learned) == protocol.MESSAGE_PHASE
    assert protocol.next_phase(learned, protocol.MESSAGE_PHASE) == protocol.MOVE_PHASE
    assert protocol.next_phase(learned, protocol.MOVE_PHASE) == protocol.MESSAGE_PHASE
    for cfg in (none, delayed):
        assert protocol.first_phase(cfg) == protocol.MOVE_PHASE
        assert protocol.next_phase(cfg, protocol.MOVE_PHASE) == protocol.MOVE_PHASE
    assert [protocol.phases_per_step(c) for c in (learned, none, delayed)] == [2, 1, 1]


def test_symbols_are_index_plus_one_and_silence_for_inactive():
    active = np.array([[True, False, True]])
    np.testing.assert_array_equal(protocol.symbols_of(np.array([[0, 5, 15]]), active), [[1, 0, 16]])


def test_layout_flatten_and_split_are_inverse(spec):
    cfg = make_config(max_agents=4, local_idleness=True)
    layout = protocol.ObservationLayout.of(spec, cfg)
    assert layout == protocol.ObservationLayout((2, H, W), 20, 12, 4)
    assert layout.size == 2 * H * W + 20 + 12
    rng = np.random.default_rng(0)
    grid, vector, critic = rng.random((6, 2, H, W)), rng.random((6, 20)), rng.random((6, 12))
    flat = layout.flatten(grid, vector, critic)
    assert flat.shape == (6, layout.size) and flat.dtype == np.float32
    parts = layout.split(flat)
    np.testing.assert_allclose(parts["grid"], grid, rtol=1e-6)      # C order: axis mix-ups fail
    np.testing.assert_allclose(parts["vector"], vector, rtol=1e-6)
    np.testing.assert_allclose(parts["critic"], critic, rtol=1e-6)
    assert layout.flatten(grid[0], vector[0], critic[0]).shape == (layout.size,)


@pytest.mark.parametrize("comm,timing", [("learned", "same_step"), ("intention", "same_step"),
                                         ("none", "same_step"), ("learned", "delayed")])
def test_decide_is_the_core_view_with_masks_built_once(spec, comm, timing):
    cfg = make_config(comm=comm, message_timing=timing)
    state = reset_state(spec, cfg, [1, 3, 5], n_envs=3, seed=2)
    for phase in (protocol.MESSAGE_PHASE, protocol.MOVE_PHASE):
        d = protocol.decide(spec, cfg, state, phase)
        grid, vector = actor_observation(spec, cfg, state, phase=phase)
        np.testing.assert_array_equal(d.grid, grid)
        np.testing.assert_array_equal(d.vector, vector)
        np.testing.assert_array_equal(d.critic, critic_state(spec, cfg, state))
        message, move = composite_action_mask(spec, cfg, state, message_phase=phase == protocol.MESSAGE_PHASE)
        np.testing.assert_array_equal(d.masks, np.concatenate([message, move], -1))
        flat = d.flat(protocol.ObservationLayout.of(spec, cfg))                # (E, A, size)
        assert flat.shape == (3, cfg.max_agents, 2 * H * W + 15 + 15)
        np.testing.assert_array_equal(flat[2, 1, -15:], d.critic[2])          # every slot: its episode's


def test_check_actions_raises_or_repairs(spec):
    strict = make_config(comm="learned")
    lenient = make_config(comm="learned", invalid_action="stay")
    state = reset_state(spec, strict, [2], n_envs=1, seed=0)
    masks = protocol.decide(spec, strict, state, protocol.MESSAGE_PHASE).masks    # (1, 5, 21)
    legal = np.tile([3, STAY], (1, 5, 1))
    legal[0, 2:, 0] = 0                                                       # absent slots: silent
    np.testing.assert_array_equal(protocol.check_actions(strict, protocol.MESSAGE_PHASE, legal, masks), legal)
    moving = legal.copy()
    moving[0, 0, 1] = 0
    with pytest.raises(InvalidActionError, match=r"drone_0: action \(3, 0\) is not legal in the message phase"):
        protocol.check_actions(strict, protocol.MESSAGE_PHASE, moving, masks)
    speaking_absent = legal.copy()
    speaking_absent[0, 3, 0] = 7
    with pytest.raises(InvalidActionError, match="drone_3"):
        protocol.check_actions(strict, protocol.MESSAGE_PHASE, speaking_absent, masks)
    repaired = protocol.check_actions(lenient, protocol.MESSAGE_PHASE, moving, masks)
    assert tuple(repaired[0, 0]) == (3, STAY)
    repaired = protocol.check_actions(lenient, protocol.MESSAGE_PHASE, speaking_absent, masks)
    assert tuple(repaired[0, 3]) == (0, STAY)
    # move phase: only message index 0; several episodes are named by episode
    state2 = reset_state(spec, strict, [2, 2], n_envs=2, seed=0)
    move_masks = protocol.decide(spec, strict, state2, protocol.MOVE_PHASE).masks
    talk = np.tile([0, STAY], (2, 5, 1))
    talk[1, 1, 0] = 5
    with pytest.raises(InvalidActionError, match="episode 1, drone_1 sent message index 5 where only 0 is legal"):
        protocol.check_actions(strict, protocol.MOVE_PHASE, talk, move_masks)


def test_apply_actions_message_then_move(spec):
    cfg = make_config(comm="learned", episode_steps=10)
    state = reset_state(spec, cfg, [2], n_envs=1, seed=1)
    actions = np.tile([0, STAY], (1, 5, 1))
    actions[0, :2, 0] = [4, 9]
    assert protocol.apply_actions(spec, cfg, state, protocol.MESSAGE_PHASE, actions) is None
    np.testing.assert_array_equal(state.messages[0], [5, 10, 0, 0, 0])
    assert state.t[0] == 0                                                   # no simulator step
    mask = action_mask(spec, state, cfg)
    move = np.tile([0, STAY], (1, 5, 1))
    move[0, 0, 1] = int(np.argmax(mask[0, 0]))
    info = protocol.apply_actions(spec, cfg, state, protocol.MOVE_PHASE, move)
    assert info is not None and state.t[0] == 1
    assert (state.messages == 0).all()                                       # cleared after the move


def test_delayed_symbols_show_at_the_next_step(spec):
    cfg = make_config(comm="learned", message_timing="delayed")
    state = reset_state(spec, cfg, [2], n_envs=1, seed=1)
    actions = np.tile([0, STAY], (1, 5, 1))
    actions[0, :2, 0] = [1, 2]
    before = copy.deepcopy(state)
    info = protocol.apply_actions(spec, cfg, state, protocol.MOVE_PHASE, actions)
    assert info is not None
    np.testing.assert_array_equal(state.messages[0, :2], np.where(state.active[0, :2], [2, 3], 0))
    assert (before.messages == 0).all()


def test_check_team(spec):
    cfg = make_config()
    assert protocol.check_team(spec, cfg, 3) == 3
    with pytest.raises(ValueError, match="n_agents=6 must be between 1 and max_agents=5"):
        protocol.check_team(spec, cfg, 6)


def test_protocol_signature_separates_what_changes_the_spaces():
    base = make_config()
    assert protocol.protocol_signature(base) == protocol.protocol_signature(make_config(episode_steps=7))
    for change in ({"local_idleness": True}, {"comm": "none"}, {"max_agents": 4},
                   {"message_timing": "delayed"}, {"message_encoding": "planes"}):
        assert protocol.protocol_signature(base) != protocol.protocol_signature(make_config(**change))


@pytest.mark.parametrize("bad", [2.5, "3", True])
def test_check_team_refuses_what_is_not_a_whole_number(spec, bad):
    with pytest.raises(ValueError, match="n_agents must be a whole number"):
        protocol.check_team(spec, make_config(), bad)


@pytest.mark.parametrize("settings", [{"comm": "learned"}, {"comm": "learned", "message_encoding": "planes"},
                                      {"comm": "intention", "local_idleness": True},
                                      {"comm": "learned", "return_guard": True, "init_battery": (0.05, 0.2)},
                                      {"comm": "none"}, {"comm": "learned", "message_timing": "delayed"}])
def test_next_decision_equals_deciding_anew(spec, settings):
    """After a message phase only the symbols are redrawn; the result must be what decide()
    computes from scratch, for every mode, over random legal play (symbols included)."""
    cfg = make_config(**settings)
    state = reset_state(spec, cfg, [1, 3, 5], n_envs=3, seed=4)
    rng = np.random.default_rng(0)
    phase = protocol.first_phase(cfg)
    decision = protocol.decide(spec, cfg, state, phase)
    reused = 0
    for _ in range(60):
        masks = decision.masks                                                # (E, A, n_symbols + 5)
        n = cfg.n_symbols
        actions = np.stack([np.argmax(rng.random(masks[..., :n].shape) * masks[..., :n], -1),
                            np.argmax(rng.random(masks[..., n:].shape) * masks[..., n:], -1)], -1)
        protocol.apply_actions(spec, cfg, state, phase, actions, decision)
        new = protocol.next_decision(spec, cfg, state, phase, decision)
        fresh = protocol.decide(spec, cfg, state, protocol.next_phase(cfg, phase))
        for field in ("phase", "grid", "vector", "critic", "masks", "move_mask"):
            np.testing.assert_array_equal(getattr(new, field), getattr(fresh, field), err_msg=field)
        reused += phase == protocol.MESSAGE_PHASE and (state.messages > 0).any()
        phase, decision = new.phase, new
    assert (reused > 0) == cfg.two_phase               # the reuse path ran, with symbols shown


def test_the_simulator_checks_moves_against_the_decision_mask_as_against_the_rule(spec):
    """Moves checked against a decision's move mask: the same verdicts as the rule itself (the
    same repaired moves, the same refusal), and not the return guard's narrower mask."""
    from patrolsb3.core.step import check_moves
    for settings in ({}, {"return_guard": True, "init_battery": (0.02, 0.1)}):
        cfg = make_config(comm="none", invalid_action="stay", **settings)
        state = reset_state(spec, cfg, [2, 4, 5], n_envs=3, seed=5)
        decision = protocol.decide(spec, cfg, state, protocol.MOVE_PHASE)
        plain = action_mask(spec, state)                                      # (E, A, 5) no guard
        for move in range(5):
            moves = np.full(state.pos.shape, move)
            expected = check_moves(spec, cfg, state, moves)
            np.testing.assert_array_equal(check_moves(spec, cfg, state, moves, plain), expected)
            with_decision = copy.deepcopy(state)
            act = np.stack([np.zeros_like(moves), moves], -1)
            info = protocol.apply_actions(spec, cfg, with_decision, protocol.MOVE_PHASE, act, decision)
            without = copy.deepcopy(state)
            info_rule = protocol.apply_actions(spec, cfg, without, protocol.MOVE_PHASE, act)
            np.testing.assert_array_equal(with_decision.pos, without.pos)
            np.testing.assert_array_equal(info.reward, info_rule.reward)
    strict = make_config(comm="none")
    state = reset_state(spec, strict, [3], n_envs=1, seed=5)
    plain = action_mask(spec, state)
    bad = np.argwhere(~plain[0, :3])
    if len(bad):
        slot, move = bad[0]
        moves = np.full((1, strict.max_agents), STAY)
        moves[0, slot] = move
        with pytest.raises(InvalidActionError, match="its action mask forbids") as with_mask:
            check_moves(spec, strict, state, moves, plain)
        with pytest.raises(InvalidActionError) as with_rule:
            check_moves(spec, strict, state, moves)
        assert str(with_mask.value) == str(with_rule.value)


def test_the_layout_names_the_symbol_planes_and_the_phase_column():
    from patrolsb3.core import load_map, make_config
    from patrolsb3.core.observe import PHASE_INDEX
    from patrolsb3.core.protocol import ObservationLayout
    spec = load_map("A")
    planes = ObservationLayout.of(spec, make_config("A", message_encoding="planes"))
    H, W = spec.shape
    assert planes.symbol_columns() == slice(2 * H * W, (2 + 16) * H * W)
    assert planes.phase_column() == planes.grid_size + PHASE_INDEX
    scalar = ObservationLayout.of(spec, make_config("A"))
    cols = scalar.symbol_columns()
    assert cols.stop - cols.start == 0                              # no planes with scalar messages
