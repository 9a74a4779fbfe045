"""patrolsb3.env: PettingZoo API conformance, phases, masks in info, and clear errors."""
import warnings

import numpy as np
import pytest
from pettingzoo.test import api_test, parallel_api_test, parallel_seed_test

import patrolsb3
from patrolsb3.core import parse_map
from patrolsb3.core.maps import STAY
from patrolsb3.core.protocol import MESSAGE_PHASE, MOVE_PHASE
from patrolsb3.core.state import ACTIVE
from patrolsb3.core.step import InvalidActionError
from patrolsb3.env import INFO_KEYS

MODES = [("learned", "same_step"), ("learned", "delayed"), ("none", "same_step"),
         ("intention", "same_step"), ("intention", "delayed")]


# PettingZoo's tests sample unmasked random actions, hence invalid_action="stay".
@pytest.mark.parametrize("comm, timing", MODES)
def test_parallel_api(comm, timing):
    env = patrolsb3.parallel_env("A", n_agents=3, seed=0, comm=comm, message_timing=timing,
                                 invalid_action="stay", episode_steps=60)
    parallel_api_test(env, num_cycles=200)


@pytest.mark.parametrize("comm", ["learned", "none"])
def test_parallel_api_with_symbol_planes(comm):
    env = patrolsb3.parallel_env("A", n_agents=3, seed=0, comm=comm, invalid_action="stay", episode_steps=60,
                                 message_encoding="planes")
    assert env.observation_space("drone_0")["grid"].shape == (18, 12, 12)
    parallel_api_test(env, num_cycles=100)


@pytest.mark.parametrize("comm, timing", MODES)
def test_parallel_seed(comm, timing):
    parallel_seed_test(lambda: patrolsb3.parallel_env("C", n_agents=4, comm=comm,
                                                      message_timing=timing,
                                                      invalid_action="stay"), num_cycles=100)


@pytest.mark.parametrize("comm, timing", MODES)
def test_aec_api(comm, timing):
    env = patrolsb3.env("B", n_agents=2, seed=1, comm=comm, message_timing=timing,
                        invalid_action="stay", episode_steps=40)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)   # Dict observations: PettingZoo only warns
        api_test(env, num_cycles=100)


def masked_move(infos):
    """An agent whose mask forbids a move, and that move (every map start has one such agent
    but a start in open ground has none: the first agent that has one is taken)."""
    for agent, info in infos.items():
        forbidden = np.flatnonzero(info["action_mask"][1] == 0)
        if len(forbidden):
            return agent, int(forbidden[0])
    raise AssertionError("no agent has a masked move at this start; take another seed")


def test_masked_move_raises_by_default():
    env = patrolsb3.parallel_env("A", n_agents=3, seed=0, comm="none")
    obs, infos = env.reset()
    agent, bad = masked_move(infos)
    with pytest.raises(InvalidActionError, match=f"agent {agent[-1]} .* which its action mask forbids"):
        env.step({a: (0, bad if a == agent else STAY) for a in env.agents})


def test_masked_move_is_stay_when_configured():
    env = patrolsb3.parallel_env("A", n_agents=3, seed=0, comm="none", invalid_action="stay",
                                 p_dyn_max=0.0)
    obs, infos = env.reset()
    before = env.core_state.pos.copy()
    agent, bad = masked_move(infos)
    env.step({a: (0, bad if a == agent else STAY) for a in env.agents})
    assert np.array_equal(env.core_state.pos, before)
    assert env.core_state.t[0] == 1


def test_message_phase_refuses_a_move_and_a_move_phase_refuses_a_message():
    env = patrolsb3.parallel_env("A", n_agents=2, seed=0, comm="learned")
    obs, infos = env.reset()
    assert infos["drone_0"]["phase"] == MESSAGE_PHASE
    with pytest.raises(ValueError, match="drone_0: action \\(3, 0\\) is not legal in the message phase"):
        env.step({"drone_0": (3, 0), "drone_1": (0, STAY)})
    env.step({"drone_0": (5, STAY), "drone_1": (5, STAY)})
    with pytest.raises(ValueError, match="drone_0 sent message index 5 where only 0 is legal"):
        env.step({"drone_0": (5, STAY), "drone_1": (0, STAY)})


def test_team_too_large_is_refused():
    with pytest.raises(ValueError, match="n_agents=6 must be between 1 and max_agents=5"):
        patrolsb3.parallel_env("A", n_agents=6)
    with pytest.raises(ValueError, match="n_agents=3 is larger than the 2 vertices of map tiny"):
        patrolsb3.parallel_env(parse_map("S..", name="tiny"), n_agents=3)
    env = patrolsb3.parallel_env("A", n_agents=2)
    with pytest.raises(ValueError, match="n_agents=9 must be between 1 and max_agents=5"):
        env.reset(options={"n_agents": 9})


def test_unknown_parameter_and_map_are_refused():
    with pytest.raises(TypeError, match=r"unknown environment parameter\(s\) \['speed'\]"):
        patrolsb3.parallel_env("A", speed=3)
    with pytest.raises(patrolsb3.MapError, match="known maps: A, B, C, D"):
        patrolsb3.parallel_env("Q")


def test_same_step_messages_take_two_env_steps_and_are_seen_before_moving():
    env = patrolsb3.parallel_env("A", n_agents=2, seed=0, comm="learned", p_dyn_max=0.0)
    obs, infos = env.reset()
    obs, rewards, terms, truncs, infos = env.step({"drone_0": (4, STAY), "drone_1": (9, STAY)})
    assert rewards == {a: 0.0 for a in env.agents} and env.agents == ["drone_0", "drone_1"]
    assert env.core_state.t[0] == 0 and infos["drone_0"]["phase"] == MOVE_PHASE
    r, c = divmod(int(env.core_state.pos[0, 1]), 12)
    assert obs["drone_0"]["grid"][0, r, c] == pytest.approx(-(1 + 10) / 18)   # drone_1's symbol 10
    assert obs["drone_0"]["vector"][6] == 1.0
    obs, rewards, terms, truncs, infos = env.step({a: (0, STAY) for a in env.agents})
    assert env.core_state.t[0] == 1 and infos["drone_0"]["phase"] == MESSAGE_PHASE
    assert rewards["drone_0"] > 0 and "drone_2" not in rewards
    assert obs["drone_0"]["grid"][0, r, c] == pytest.approx(-1 / 18)        # symbols cleared


def test_delayed_messages_are_seen_at_the_next_step():
    env = patrolsb3.parallel_env("A", n_agents=2, seed=0, comm="learned", message_timing="delayed",
                                 p_dyn_max=0.0)
    obs, infos = env.reset()
    obs, *_ = env.step({"drone_0": (6, STAY), "drone_1": (0, STAY)})
    assert env.core_state.t[0] == 1
    r, c = divmod(int(env.core_state.pos[0, 0]), 12)
    assert obs["drone_0"]["grid"][0, r, c] == pytest.approx((1 + 7) / 18)


def test_info_carries_what_evaluation_needs():
    env = patrolsb3.parallel_env("A", n_agents=3, seed=0, comm="none")
    obs, infos = env.reset()
    msg_mask, move_mask = infos["drone_0"]["action_mask"]
    assert msg_mask.dtype == np.int8 and msg_mask.shape == (16,)
    assert move_mask.dtype == np.int8 and move_mask.shape == (5,)
    assert env.agents == ["drone_0", "drone_1", "drone_2"] and "drone_4" not in infos   # the team only
    assert infos["drone_0"]["status"] == ACTIVE
    np.testing.assert_array_equal(infos["drone_0"]["action_mask_flat"], np.concatenate([msg_mask, move_mask]))
    first = infos
    obs, rewards, terms, truncs, infos = env.step({a: (0, STAY) for a in env.agents})
    for key in INFO_KEYS:
        assert key in infos["drone_0"]
    assert set(first["drone_0"]) == set(infos["drone_0"]) == set(INFO_KEYS)   # one schema at every step
    assert all(isinstance(v, (int, float, bool, tuple, np.ndarray)) for v in infos["drone_0"].values())
    assert infos["drone_0"]["mean_idleness"] == pytest.approx(env.core_state.idle.mean())
    assert obs["drone_0"]["grid"].shape == (2, 12, 12)
    assert env.observation_space("drone_0").contains(obs["drone_0"])


def test_episode_ends_with_truncation():
    env = patrolsb3.parallel_env("A", n_agents=1, seed=0, comm="none", episode_steps=5)
    env.reset()
    for t in range(5):
        obs, rewards, terms, truncs, infos = env.step({a: (0, STAY) for a in env.agents})
    assert all(truncs.values()) and not any(terms.values())
    assert env.agents == []


def random_masked_actions(infos, agents, rng):
    """One random legal (message, move) per agent from its info mask."""
    actions = {}
    for a in agents:
        msg_mask, move_mask = infos[a]["action_mask"]
        actions[a] = (int(rng.choice(np.flatnonzero(msg_mask))), int(rng.choice(np.flatnonzero(move_mask))))
    return actions


def trajectory(seed, comm, timing, n_env_steps=300):
    env = patrolsb3.parallel_env("D", n_agents=4, comm=comm, message_timing=timing)
    obs, infos = env.reset(seed=seed)
    rng = np.random.default_rng(99)
    out = []
    for _ in range(n_env_steps):
        obs, rewards, terms, truncs, infos = env.step(random_masked_actions(infos, env.agents, rng))
        out.append((np.stack([obs[a]["grid"] for a in env.agents]),
                    [rewards[a] for a in env.agents],
                    [infos[a]["collided"] for a in env.agents],
                    env.core_state.battery.copy()))
    return out


@pytest.mark.parametrize("comm, timing", [("learned", "same_step"), ("none", "same_step"),
                                          ("intention", "delayed")])
def test_same_seed_same_episode_for_many_steps(comm, timing):
    # PettingZoo's parallel_seed_test stops after its first step (its loop breaks on
    # `any(terminations)` of a non-empty dict), so the whole trajectory is compared here.
    one, two = trajectory(5, comm, timing), trajectory(5, comm, timing)
    for (g1, r1, c1, b1), (g2, r2, c2, b2) in zip(one, two):
        assert np.array_equal(g1, g2) and r1 == r2 and c1 == c2 and np.array_equal(b1, b2)
    other = trajectory(6, comm, timing)
    assert not all(np.array_equal(a[0], b[0]) for a, b in zip(one, other))


def test_delayed_messages_out_of_range_are_refused_or_repaired_and_obs_stay_in_the_box():
    strict = patrolsb3.parallel_env("A", n_agents=2, seed=0, comm="learned", message_timing="delayed")
    obs, infos = strict.reset(seed=0)
    with pytest.raises(InvalidActionError, match="sent message index 40"):
        strict.step({"drone_0": (40, STAY), "drone_1": (0, STAY)})
    lenient = patrolsb3.parallel_env("A", n_agents=2, seed=0, comm="learned", message_timing="delayed",
                                     invalid_action="stay")
    lenient.reset(seed=0)
    obs, *_ = lenient.step({"drone_0": (40, STAY), "drone_1": (-3, STAY)})
    obs, *_ = lenient.step({"drone_0": (0, STAY), "drone_1": (0, STAY)})
    assert all(lenient.observation_space(a).contains(o) for a, o in obs.items())


def test_misuse_of_the_env_is_refused_by_name():
    env = patrolsb3.parallel_env(map="A", n_agents=2, render_mode="rgb_array")
    with pytest.raises(RuntimeError, match=r"step\(\) before reset\(\)"):
        env.step({"drone_0": (0, STAY)})
    with pytest.raises(RuntimeError, match=r"render\(\) before reset\(\)"):
        env.render()
    env.reset(seed=0)
    with pytest.raises(TypeError, match=r"takes a dict \{agent: \(message, move\)\}, got list"):
        env.step([(0, 0), (0, 0)])
    with pytest.raises(ValueError, match=r"unknown agent\(s\) \['drone_4'\]"):
        env.step({"drone_0": (0, STAY), "drone_4": (0, STAY)})
    for bad in ((0.5, 0), (float("nan"), 0), (0, 0, 0), "up", (None, 1)):
        with pytest.raises(ValueError, match="the action of drone_1 must be"):
            env.step({"drone_0": (0, STAY), "drone_1": bad})
    assert env.render().ndim == 3
    obs, *_ = env.step({"drone_0": np.array([0.0, float(STAY)]), "drone_1": np.array([0, STAY])})   # whole floats are fine
    assert set(obs) == {"drone_0", "drone_1"}
    env.agents = []                                            # as after the last step of an episode
    with pytest.raises(RuntimeError, match="the episode has ended"):
        env.step({"drone_0": (0, STAY)})
