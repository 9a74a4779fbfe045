"""The parameter-shared SB3 vector env: spaces, flat layout, masks, episode ends, seeding."""
from __future__ import annotations

import numpy as np
import pytest
import torch
from sb3_contrib import MaskablePPO
from sb3_contrib.common.maskable.utils import get_action_masks, is_masking_supported
from stable_baselines3.common.vec_env import VecMonitor, VecNormalize

from patrolsb3.core import parse_map
from patrolsb3.core.maps import STAY
from patrolsb3.core.observe import VECTOR_SIZE
from patrolsb3.env import PatrolParallelEnv
from patrolsb3.sb3 import VARIANTS, make_vec_env
from patrolsb3.sb3.vec_env import PatrolVecEnv, flatten_observation

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


def unflatten(row, layout):
    """Split one flat observation back into the env's Dict layout."""
    g = int(np.prod(layout["grid_shape"]))
    v = layout["vector_size"]
    return {"grid": row[:g].reshape(layout["grid_shape"]), "vector": row[g:g + v],
            "critic": row[g + v:]}


def test_spaces_and_layout(spec):
    venv = make_vec_env(spec, agents=TEAMS, seed=0)
    assert isinstance(venv, PatrolVecEnv)
    assert venv.num_envs == len(TEAMS) * A
    assert venv.observation_space.shape == (OBS_SIZE,)
    assert venv.observation_space.dtype == np.float32
    assert list(venv.action_space.nvec) == [16, 5]
    assert venv.layout == {"grid_shape": (2, H, W), "vector_size": VECTOR_SIZE, "critic_size": 3 * A}
    obs = venv.reset()
    assert obs.shape == (venv.num_envs, OBS_SIZE) and obs.dtype == np.float32
    assert venv.observation_space.contains(obs[0])
    assert venv.action_masks().shape == (venv.num_envs, 21)
    assert isinstance(venv.get_env(2), PatrolParallelEnv)
    assert venv.get_env(2).n_agents == 5


@pytest.mark.parametrize("variant,timing,phases", [
    ("rl-msg", "same_step", 2), ("rl-intention", "same_step", 2), ("rl-no-msg", "same_step", 1),
    ("rl-msg", "delayed", 1)])
def test_variants_set_comm_and_phases(spec, variant, timing, phases):
    venv = make_vec_env(spec, agents=[1], variant=variant, message_timing=timing)
    assert venv.get_env(0).cfg.comm == VARIANTS[variant]["comm"]
    assert venv.phases_per_step == phases


def test_rows_mirror_independent_envs(spec):
    """Row e*A + s is slot s of an env reset with seed + e: obs layout, masks and rewards."""
    seed = 11
    venv = make_vec_env(spec, agents=TEAMS, seed=seed, episode_steps=50)
    obs = venv.reset()
    envs = [PatrolParallelEnv(spec, n_agents=k, episode_steps=50) for k in TEAMS]
    resets = [env.reset(seed=seed + e) for e, env in enumerate(envs)]
    masks = venv.env_method("action_masks")
    assert len(masks) == venv.num_envs
    rng = np.random.default_rng(0)
    for t in range(6):
        for e, env in enumerate(envs):
            ref_obs, ref_infos = resets[e][0], resets[e][1]
            for s, name in enumerate(env.possible_agents):
                k = e * A + s
                parts = unflatten(obs[k], venv.layout)
                for key in ("grid", "vector", "critic"):
                    np.testing.assert_array_equal(parts[key], ref_obs[name][key])
                np.testing.assert_array_equal(flatten_observation(ref_obs[name]), obs[k])
                message, move = ref_infos[name]["action_mask"]
                np.testing.assert_array_equal(masks[k], np.concatenate([message, move]).astype(bool))
        actions = masked_actions(venv.action_masks(), rng)
        obs, rewards, dones, _ = venv.step(actions)
        masks = venv.env_method("action_masks")
        for e, env in enumerate(envs):
            act = {name: actions[e * A + s] for s, name in enumerate(env.possible_agents)}
            o, r, *_, i = env.step(act)
            resets[e] = (o, i)
            np.testing.assert_allclose(rewards[e * A:(e + 1) * A],
                                       [r[name] for name in env.possible_agents], rtol=1e-6)
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
    mirror = PatrolParallelEnv(spec, n_agents=2, episode_steps=5, comm=VARIANTS[variant]["comm"])
    mirror.reset(seed=4)
    rng = np.random.default_rng(3)
    returns = np.zeros(venv.num_envs)
    for t in range(env_steps):
        actions = masked_actions(venv.action_masks(), rng)
        obs, rewards, dones, infos = venv.step(actions)
        m_obs, *_ = mirror.step({name: actions[s] for s, name in enumerate(mirror.possible_agents)})
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
    for s, name in enumerate(mirror.possible_agents):
        np.testing.assert_array_equal(infos[s]["terminal_observation"], flatten_observation(m_obs[name]))
    assert not np.array_equal(obs[0], infos[0]["terminal_observation"])
    team = infos[0]["team_episode"]
    assert team["reward"] == pytest.approx(returns[:2].mean(), rel=1e-5)
    assert team["max_idleness"] >= team["mean_idleness"] > 0
    assert venv.action_masks()[0, 16 + STAY]  # masks of the new episode are in place


def test_episode_env_gives_one_parallel_episode_its_own_settings(spec):
    venv = make_vec_env(spec, agents=[2, 2], variant="rl-no-msg", seed=1, episode_steps=6,
                        episode_env={1: {"episode_steps": 3, "init_battery": [0.1, 0.1]}})
    assert venv.get_env(0).cfg.episode_steps == 6 and venv.get_env(1).cfg.episode_steps == 3
    venv.reset()
    b_max = venv.get_env(0).cfg.b_max
    batteries = [venv.get_env(e).core_state.battery[0, :2] / b_max for e in (0, 1)]   # (2,) each
    assert (batteries[0] >= 0.9).all() and np.allclose(batteries[1], 0.1)
    rng = np.random.default_rng(0)
    ends = {}
    for t in range(1, 7):
        _, _, dones, infos = venv.step(masked_actions(venv.action_masks(), rng))
        for e in (0, 1):
            if dones[e * A] and e not in ends:
                ends[e] = (t, infos[e * A]["team_episode"]["sim_steps"])
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
    assert venv.get_env(0).n_agents == 1  # the running episode keeps its team
    assert venv.action_masks()[1, 16:].sum() == 1  # slot 1 still padded
    for _ in range(2):
        _, _, dones, infos = venv.step(stay)
    assert dones.all()
    assert infos[0]["team_episode"]["n_agents"] == 1  # the summary is the finished episode's
    assert [venv.get_env(i).n_agents for i in range(2)] == [4, 2]
    assert venv.get_attr("n_agents") == [4] * A + [2] * A
    status = [i["status"] for i in infos]  # reset infos of the new episodes
    assert status == ["active"] * 4 + ["absent"] + ["active"] * 2 + ["absent"] * 3
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
    assert c.seed(5) == [5] * A + [6] * A
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
