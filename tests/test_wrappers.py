"""Other clients without an adapter of their own: flat observations for stock SuperSuit, the
mask wrapper for sb3-contrib's MaskablePPO, and PettingZoo's render and performance tests in
their documented setting (unmasked random actions: invalid_action='stay'; headless human mode:
MPLBACKEND=Agg)."""
import functools

import matplotlib
import numpy as np
import supersuit as ss
import torch
from pettingzoo.test import parallel_api_test, performance_benchmark, render_test
from sb3_contrib import MaskablePPO
from sb3_contrib.common.maskable.utils import get_action_masks

import patrolsb3
from patrolsb3.core import protocol
from patrolsb3.sb3.masks import VecActionMasks
from patrolsb3.wrappers import FlatObservations

torch.set_num_threads(1)
matplotlib.use("Agg")


def test_flat_observations_are_the_training_layout():
    base = patrolsb3.parallel_env("B", n_agents=3, seed=1, episode_steps=30, invalid_action="stay")
    env = FlatObservations(base)
    obs, infos = env.reset(seed=1)
    layout = protocol.ObservationLayout.of(base.spec_map, base.cfg)
    decision = protocol.decide(base.spec_map, base.cfg, base.core_state, base.phase)
    for i, agent in enumerate(env.agents):
        np.testing.assert_array_equal(obs[agent], decision.flat(layout)[0, i])
        assert env.observation_space(agent).contains(obs[agent])
    parallel_api_test(FlatObservations(patrolsb3.parallel_env("B", n_agents=3, seed=1, episode_steps=30,
                                                              invalid_action="stay")), num_cycles=60)


def test_stock_supersuit_and_maskable_ppo_with_the_mask_wrapper():
    """A strict env (a masked action raises): MaskablePPO samples legal actions only."""
    env = FlatObservations(patrolsb3.parallel_env("A", n_agents=3, max_agents=3, comm="learned", episode_steps=40))
    venv = VecActionMasks(ss.concat_vec_envs_v1(ss.pettingzoo_env_to_vec_env_v1(env), 2,
                                                base_class="stable_baselines3"))
    venv.reset()
    masks = get_action_masks(venv)
    assert masks.shape == (6, 21) and masks[:, 0].all() and masks[:, 16 + 4].all()
    model = MaskablePPO("MlpPolicy", venv, n_steps=32, batch_size=96, n_epochs=1, seed=0,
                        policy_kwargs={"net_arch": [32]})
    model.learn(600)
    assert model.num_timesteps >= 600


def test_pettingzoo_render_and_performance_tests():
    render_test(functools.partial(patrolsb3.env, "A", n_agents=2, invalid_action="stay", episode_steps=15))
    performance_benchmark(patrolsb3.env("A", n_agents=2, invalid_action="stay", episode_steps=50))


def test_torchrl_pettingzoo_wrapper_checks_specs_and_rolls_out_masked():
    """TorchRL builds on the env (flat masks in the info): its spec check passes and a random
    rollout under the masks runs on a strict env (a masked action would raise)."""
    import pytest
    torchrl = pytest.importorskip("torchrl", reason="torchrl is not installed (pip install -e '.[test]')")
    from torchrl.envs import PettingZooWrapper
    from torchrl.envs.utils import check_env_specs

    from patrolsb3.wrappers import FlatMasks
    base = FlatMasks(patrolsb3.parallel_env("A", n_agents=3, max_agents=3, seed=0, episode_steps=30))
    env = PettingZooWrapper(env=base, use_mask=True, categorical_actions=True)
    check_env_specs(env)
    rollout = env.rollout(40)
    assert rollout.batch_size[0] == 40 and torchrl.__version__
