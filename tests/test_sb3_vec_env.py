"""The parameter-shared SB3 vector env: spaces, flat layout, masks, episode ends, seeding; its
rows are the agent protocol's view of one batched simulator state."""
from __future__ import annotations

import copy

import numpy as np
import pytest
import torch
from sb3_contrib import MaskablePPO
from sb3_contrib.common.maskable.utils import get_action_masks, is_masking_supported
from stable_baselines3.common.vec_env import VecMonitor, VecNormalize

from patrolsb3.core import parse_map, protocol
from patrolsb3.core.maps import STAY
from patrolsb3.core.observe import VECTOR_SIZE
from patrolsb3.env import PatrolParallelEnv
from patrolsb3.sb3 import VARIANTS, make_vec_env
from patrolsb3.sb3.vec_env import PatrolVecEnv

from conftest import NON_SQUARE

torch.set_num_threads(1)

A = 5                  # default max_agents
H, W = 3, 7            # NON_SQUARE map: axis mix-ups show up
OBS_SIZE = 2 * H * W + VECTOR_SIZE + 3 * A
TEAMS = [1, 2, 5]


@pytest.fixture
def spec():
    return parse_map(NON_SQUARE, name="non_square")


def masked_actions(masks, rng):
    """(N, 2) int64 (message, move) drawn uniformly among the legal values of each row."""
    return np.array([[rng.choice(np.flatnonzero(m[:16])), rng.choice(np.flatnonzero(m[16:]))]
                     for m in masks], dtype=np.int64)


def the_state(venv):
    """The batched simulator state of a vec env without per-episode settings (one group)."""
    (group,) = venv.episodes.groups
    return group.state


def test_spaces_and_layout(spec):
    venv = make_vec_env(spec, agents=TEAMS, seed=0)
    assert isinstance(venv, PatrolVecEnv)
    assert venv.num_envs == len(TEAMS) * A
    assert venv.observation_space.shape == (OBS_SIZE,)
    assert venv.observation_space.dtype == np.float32
    assert list(venv.action_space.nvec) == [16, 5]
    assert venv.layout == protocol.ObservationLayout((2, H, W), VECTOR_SIZE, 3 * A, A)
    obs = venv.reset()
    assert obs.shape == (venv.num_envs, OBS_SIZE) and obs.dtype == np.float32
    assert venv.observation_space.contains(obs[0])
    assert venv.action_masks().shape == (venv.num_envs, 21)
    assert venv.running_agents() == TEAMS
    assert venv.deployed_rows().tolist() == [k % A < TEAMS[k // A] for k in range(venv.num_envs)]
    assert the_state(venv).pos.shape == (len(TEAMS), A)     # one batched state for all episodes


@pytest.mark.parametrize("variant,timing,phases", [
    ("rl-msg", "same_step", 2), ("rl-intention", "same_step", 2), ("rl-no-msg", "same_step", 1),
    ("rl-msg", "delayed", 1)])
def test_variants_set_comm_and_phases(spec, variant, timing, phases):
    venv = make_vec_env(spec, agents=[1], variant=variant, message_timing=timing)
    assert venv.episode_config(0).comm == VARIANTS[variant]["comm"]
    assert venv.phases_per_step == phases


@pytest.mark.parametrize("variant", sorted(VARIANTS))
def test_rows_are_the_protocol_view_of_the_batched_state(spec, variant):
    """Every step: rows and masks are protocol.decide of the batched state, rewards those of the
    protocol applied to a copy of it, and the PettingZoo env shows one episode the same way."""
    venv = make_vec_env(spec, agents=TEAMS, seed=11, variant=variant, episode_steps=50)
    obs = venv.reset()
    cfg = venv.episode_config(0)
    pz = PatrolParallelEnv(spec, n_agents=1, config=cfg)
    rng = np.random.default_rng(0)
    for t in range(8):
        state, phase = the_state(venv), venv.episodes.phase
        decision = protocol.decide(spec, cfg, state, phase)
        np.testing.assert_array_equal(obs, decision.flat(venv.layout).reshape(venv.num_envs, -1))
        np.testing.assert_array_equal(venv.action_masks(), decision.masks.reshape(venv.num_envs, -1))
        np.testing.assert_array_equal(np.stack(venv.env_method("action_masks")), venv.action_masks())
        for e in range(len(TEAMS)):              # the PettingZoo env's view of episode e
            pz.core_state = copy.deepcopy(state)
            for field in ("pos", "battery", "status", "swap_left", "p_dyn", "messages", "idle", "visited",
                          "t", "n_agents"):
                setattr(pz.core_state, field, getattr(state, field)[e:e + 1].copy())
            pz._decide(phase)
            pz.agents = list(pz.possible_agents)     # view every slot, padding included
            for s_, name in enumerate(pz.possible_agents):
                o = pz._observations()[name]
                np.testing.assert_array_equal(venv.layout.flatten(o["grid"], o["vector"], o["critic"]),
                                              obs[e * A + s_])
        actions = masked_actions(venv.action_masks(), rng)
        mirror = copy.deepcopy(state)
        info = protocol.apply_actions(spec, cfg, mirror, phase,
                                      protocol.check_actions(cfg, phase, actions.reshape(len(TEAMS), A, 2),
                                                             decision.masks))
        obs, rewards, dones, _ = venv.step(actions)
        expected = np.zeros(venv.num_envs) if info is None else info.reward.reshape(-1)
        np.testing.assert_allclose(rewards, expected, rtol=1e-6)
        np.testing.assert_array_equal(the_state(venv).pos, mirror.pos)
        assert not dones.any()


@pytest.mark.parametrize("variant,timing", [(v, "same_step") for v in sorted(VARIANTS)]
                         + [("rl-msg", "delayed")])
def test_strict_env_accepts_masked_random_actions_and_pads_slots(spec, variant, timing):
    """A few hundred steps of mask-sampled actions never raise; padded slots only (0, Stay), reward 0."""
    venv = make_vec_env(spec, agents=[1, 3, 5], variant=variant, seed=2, episode_steps=30,
                        strict=True, message_timing=timing)
    venv.reset()
    rng = np.random.default_rng(1)
    only_noop = np.zeros(21, dtype=bool)
    only_noop[0] = only_noop[16 + STAY] = True
    padded = np.array([k % A >= team for team in (1, 3, 5) for k in range(A)])  # (N,)
    for _ in range(200):
        masks = venv.action_masks()
        assert (masks[padded] == only_noop).all()
        assert masks[:, :16].any(1).all() and masks[:, 16:].any(1).all()
        _, rewards, _, _ = venv.step(masked_actions(masks, rng))
        assert (rewards[padded] == 0).all()


def test_strict_raises_on_masked_move_and_lenient_stays(spec):
    strict = make_vec_env(spec, agents=[1], variant="rl-no-msg", seed=0)
    lenient = make_vec_env(spec, agents=[1], variant="rl-no-msg", seed=0, strict=False)
    strict.reset()
    lenient.reset()
    move_mask = strict.action_masks()[0, 16:]
    bad = int(np.flatnonzero(~move_mask)[0]) if (~move_mask).any() else None
    actions = np.zeros((A, 2), dtype=np.int64)
    actions[:, 1] = STAY
    if bad is None:  # a start cell with every move legal: a padded slot's move is masked
        actions[1, 1] = 0
    else:
        actions[0, 1] = bad
    with pytest.raises(ValueError):
        strict.step(actions)
    lenient.step(actions)  # masked move acts as Stay


@pytest.mark.parametrize("variant", sorted(VARIANTS))
def test_lenient_env_accepts_any_action(spec, variant):
    """strict=False (algorithms without masks): unmasked random actions never raise."""
    venv = make_vec_env(spec, agents=[1, 5], variant=variant, seed=0, episode_steps=10, strict=False)
    venv.reset()
    rng = np.random.default_rng(0)
    for _ in range(60):
        venv.step(np.stack([rng.integers(0, 16, venv.num_envs), rng.integers(0, 5, venv.num_envs)], 1))


@pytest.mark.parametrize("variant,env_steps", [("rl-msg", 10), ("rl-no-msg", 5)])
def test_horizon_marks_truncation_and_keeps_terminal_observation(spec, variant, env_steps):
    venv = make_vec_env(spec, agents=[2, 1], variant=variant, seed=4, episode_steps=5)
    obs = venv.reset()
    cfg = venv.episode_config(0)
    rng = np.random.default_rng(3)
    returns = np.zeros(venv.num_envs)
    for t in range(env_steps):
        actions = masked_actions(venv.action_masks(), rng)
        mirror, phase = copy.deepcopy(the_state(venv)), venv.episodes.phase
        masks = venv.action_masks().reshape(2, A, -1)
        obs, rewards, dones, infos = venv.step(actions)
        returns += rewards
        if t < env_steps - 1:
            assert not dones.any()
            assert not any("episode" in i or "terminal_observation" in i for i in infos)
    assert dones.all()
    for k, info in enumerate(infos):
        assert info["TimeLimit.truncated"] is True
        assert info["terminal_observation"].shape == (OBS_SIZE,)
        assert info["episode"]["l"] == env_steps
        assert info["episode"]["r"] == pytest.approx(returns[k], rel=1e-5)
        assert info["team_episode"]["sim_steps"] == 5
        assert info["team_episode"]["n_agents"] == (2 if k < A else 1)
    # the terminal observation is the last one of the finished episode; obs is the next one's
    protocol.apply_actions(spec, cfg, mirror, phase,
                           protocol.check_actions(cfg, phase, actions.reshape(2, A, 2), masks))
    last = protocol.decide(spec, cfg, mirror, protocol.next_phase(cfg, phase)).flat(venv.layout)
    np.testing.assert_array_equal(np.stack([i["terminal_observation"] for i in infos]),
                                  last.reshape(venv.num_envs, -1))
    assert not np.array_equal(obs[0], infos[0]["terminal_observation"])
    team = infos[0]["team_episode"]
    assert team["reward"] == pytest.approx(returns[:2].mean(), rel=1e-5)
    assert team["max_idleness"] >= team["mean_idleness"] > 0
    assert venv.action_masks()[0, 16 + STAY]  # masks of the new episode are in place


def test_episode_env_gives_one_parallel_episode_its_own_settings(spec):
    venv = make_vec_env(spec, agents=[2, 2], variant="rl-no-msg", seed=1, episode_steps=6,
                        episode_env={1: {"episode_steps": 3, "init_battery": [0.1, 0.1]}})
    assert venv.episode_config(0).episode_steps == 6 and venv.episode_config(1).episode_steps == 3
    assert len(venv.episodes.groups) == 2        # one simulator call per distinct setting
    venv.reset()
    b_max = venv.episode_config(0).b_max
    batteries = [g.state.battery[0, :2] / b_max for g in venv.episodes.groups]   # (2,) each
    assert (batteries[0] >= 0.9).all() and np.allclose(batteries[1], 0.1)
    rng = np.random.default_rng(0)
    ends = {}
    for t in range(1, 7):
        before = venv.episodes.groups[1].state.copy()
        obs, _, dones, infos = venv.step(masked_actions(venv.action_masks(), rng))
        for e in (0, 1):
            if dones[e * A] and e not in ends:
                ends[e] = (t, infos[e * A]["team_episode"]["sim_steps"])
        if t == 3:   # episode 1 ended alone: restarted in place, its terminal observation kept
            assert not dones[:A].any() and dones[A:].all()
            assert "terminal_observation" in infos[A] and "terminal_observation" not in infos[0]
            assert not np.array_equal(infos[A]["terminal_observation"], obs[A])
            assert venv.episodes.groups[1].state.t[0] == 0 and before.t[0] == 2
            assert np.allclose(venv.episodes.groups[1].state.battery[0, :2] / b_max, 0.1)
    assert ends == {1: (3, 3), 0: (6, 6)}


def test_episode_env_refuses_what_would_change_the_spaces(spec):
    with pytest.raises(ValueError, match="local_idleness would change the spaces"):
        make_vec_env(spec, agents=[1, 1], variant="rl-no-msg", episode_env={1: {"local_idleness": True}})
    with pytest.raises(ValueError, match="max_agents"):
        make_vec_env(spec, agents=[1, 1], variant="rl-no-msg", episode_env={0: {"max_agents": 4}})
    with pytest.raises(ValueError, match="no parallel episode 2"):
        make_vec_env(spec, agents=[1, 1], variant="rl-no-msg", episode_env={2: {"episode_steps": 3}})
    with pytest.raises(TypeError):
        make_vec_env(spec, agents=[1, 1], variant="rl-no-msg", episode_env={0: {"nope": 3}})


def test_termination_is_not_truncation(spec):
    venv = make_vec_env(spec, agents=[1], variant="rl-no-msg", seed=0, faults=((0, 1),))
    venv.reset()
    actions = np.tile([0, STAY], (A, 1))
    _, _, dones, infos = venv.step(actions)
    assert dones.all()
    assert all(info["TimeLimit.truncated"] is False for info in infos)
    assert infos[0]["episode"]["l"] == 1


def test_set_agents_takes_effect_at_next_episode(spec):
    venv = make_vec_env(spec, agents=[1, 1], variant="rl-no-msg", seed=0, episode_steps=3)
    venv.reset()
    venv.set_agents([4, 2])
    assert venv.get_agents() == [4, 2]
    stay = np.tile([0, STAY], (venv.num_envs, 1))
    venv.step(stay)
    assert venv.running_agents() == [1, 1]  # the running episode keeps its team
    assert venv.action_masks()[1, 16:].sum() == 1  # slot 1 still padded
    for _ in range(2):
        _, _, dones, infos = venv.step(stay)
    assert dones.all()
    assert infos[0]["team_episode"]["n_agents"] == 1  # the summary is the finished episode's
    assert venv.running_agents() == [4, 2]
    assert venv.get_attr("n_agents") == [4] * A + [2] * A
    assert venv.deployed_rows().tolist() == [True] * 4 + [False] + [True] * 2 + [False] * 3
    assert (venv.action_masks()[:, 16:].sum(1)[~venv.deployed_rows()] == 1).all()
    for _ in range(3):
        _, _, dones, infos = venv.step(stay)
    assert dones.all()
    assert [i["team_episode"]["n_agents"] for i in infos[::A]] == [4, 2]


def test_set_agents_refuses_bad_teams(spec):
    venv = make_vec_env(spec, agents=[1, 2], seed=0)
    with pytest.raises(ValueError, match="2 team sizes"):
        venv.set_agents([1, 2, 3])
    with pytest.raises(ValueError, match="max_agents"):
        venv.set_agents([1, 6])
    assert venv.get_agents() == [1, 2]


def test_make_vec_env_refuses_bad_input(spec):
    with pytest.raises(ValueError, match="rl-intention"):
        make_vec_env(spec, variant="rl-telepathy")
    with pytest.raises(ValueError, match="max_agents"):
        make_vec_env(spec, agents=[1, 6])
    with pytest.raises(ValueError, match="at least one"):
        make_vec_env(spec, agents=[])
    with pytest.raises(TypeError, match="variant"):
        make_vec_env(spec, comm="none")
    with pytest.raises(TypeError, match="strict"):
        make_vec_env(spec, invalid_action="stay")
    with pytest.raises(TypeError, match="unknown environment parameter"):
        make_vec_env(spec, episode_lenght=5)


def run_fixed(venv, steps, seed):
    """Obs and rewards of ``steps`` mask-sampled steps with actions from ``seed``."""
    rng = np.random.default_rng(seed)
    out = [venv.reset()]
    for _ in range(steps):
        obs, rewards, _, _ = venv.step(masked_actions(venv.action_masks(), rng))
        out += [obs, rewards]
    return out


def test_seeding_reproduces_runs_across_auto_resets(spec):
    kw = dict(agents=[1, 3], episode_steps=4, variant="rl-msg")
    a = run_fixed(make_vec_env(spec, seed=5, **kw), 20, seed=0)  # 20 env steps = 2.5 episodes
    b = run_fixed(make_vec_env(spec, seed=5, **kw), 20, seed=0)
    for x, y in zip(a, b):
        np.testing.assert_array_equal(x, y)
    c = make_vec_env(spec, seed=99, **kw)
    assert c.seed(5) == [5] * (2 * A)
    for x, y in zip(a, run_fixed(c, 20, seed=0)):
        np.testing.assert_array_equal(x, y)
    d = run_fixed(make_vec_env(spec, seed=6, **kw), 20, seed=0)
    assert not np.array_equal(a[0], d[0])


def test_sb3_contrib_mask_helpers_and_wrappers(spec):
    venv = make_vec_env(spec, agents=[1, 2], seed=0)
    venv.reset()
    assert is_masking_supported(venv)
    assert venv.has_attr("action_masks")
    np.testing.assert_array_equal(get_action_masks(venv), venv.action_masks())
    for wrapped in (VecMonitor(venv), VecNormalize(VecMonitor(venv))):
        assert is_masking_supported(wrapped)
        np.testing.assert_array_equal(get_action_masks(wrapped), venv.action_masks())
    assert venv.env_method("action_masks", indices=[3])[0].shape == (21,)
    assert venv.env_is_wrapped(object) == [False] * venv.num_envs


def test_maskable_ppo_learns_without_error(spec):
    venv = make_vec_env(spec, agents=[1, 2], seed=0, episode_steps=8)
    model = MaskablePPO("MlpPolicy", venv, n_steps=16, batch_size=80, n_epochs=1, seed=0,
                        policy_kwargs={"net_arch": [32]})
    model.learn(256)
    assert model.num_timesteps >= 256
    assert len(model.ep_info_buffer) > 0


def test_package_exports_lazily():
    import patrolsb3.sb3 as sb3
    assert sb3.make_vec_env is make_vec_env
    assert sb3.MaskableRecurrentPPO.__name__ == "MaskableRecurrentPPO"
    with pytest.raises(AttributeError, match="no_such_name"):
        sb3.no_such_name
