"""The paper's network as an SB3 policy: actor blind to the critic slice, any grid size,
single-legal-action slots with log-prob 0."""
import numpy as np
import pytest
import torch as th
from gymnasium import spaces

from patrolsb3.sb3.policy import PatrolFeaturesExtractor, PatrolRecurrentPolicy, conv_padding
from sb3_contrib.common.recurrent.type_aliases import RNNStates

th.set_num_threads(1)


def make_policy(H=12, W=12, max_agents=5, **kwargs):
    size = 2 * H * W + 8 + 3 * max_agents
    obs_space = spaces.Box(-1, 1, (size,), np.float32)
    policy = PatrolRecurrentPolicy(obs_space, spaces.MultiDiscrete([16, 5]), lambda _: 1e-4, grid_shape=(2, H, W),
                                   vector_size=8, critic_size=3 * max_agents, **kwargs)
    return policy, size


def zero_states(policy, n):
    h = th.zeros(1, n, policy.lstm_actor.hidden_size)
    return RNNStates((h, h), (h, h))


def test_paper_sizes_on_12x12():
    policy, _ = make_policy()
    dense = [m for m in policy.pi_features_extractor.dense if isinstance(m, th.nn.Linear)]
    assert [(d.in_features, d.out_features) for d in dense] == [(512 + 8, 512), (512, 341), (341, 227)]
    critic_dense = [m for m in policy.vf_features_extractor.dense if isinstance(m, th.nn.Linear)]
    assert critic_dense[0].in_features == 512 + 8 + 15
    assert policy.action_net.out_features == 21


def test_actor_never_reads_the_critic_slice():
    policy, size = make_policy()
    obs = th.rand(6, size) * 2 - 1
    other = obs.clone()
    other[:, -15:] = th.rand(6, 15)                      # change only the centralised critic state
    starts = th.zeros(6)
    with th.no_grad():
        d1, _ = policy.get_distribution(obs, zero_states(policy, 6).pi, starts)
        d2, _ = policy.get_distribution(other, zero_states(policy, 6).pi, starts)
        v1 = policy.predict_values(obs, zero_states(policy, 6).vf, starts)
        v2 = policy.predict_values(other, zero_states(policy, 6).vf, starts)
    for a, b in zip(d1.distributions, d2.distributions):   # message and move logits
        assert th.equal(a.logits, b.logits)
    assert not th.allclose(v1, v2)


@pytest.mark.parametrize("H,W", [(1, 8), (4, 6), (7, 13)])
def test_any_grid_size(H, W):
    policy, size = make_policy(H, W, max_agents=2)
    with th.no_grad():
        actions, values, log_prob, _ = policy(th.zeros(3, size), zero_states(policy, 3), th.ones(3))
    assert actions.shape == (3, 2) and values.shape == (3, 1) and log_prob.shape == (3,)
    assert conv_padding((2, 12, 12), 2, 3) == (0, 0) and conv_padding((2, 1, 8), 2, 3) == (1, 0)


def test_wrong_layout_is_refused():
    with pytest.raises(ValueError, match="does not match the layout"):
        PatrolFeaturesExtractor(spaces.Box(-1, 1, (10,), np.float32), (2, 12, 12), 8, 15)


def test_single_legal_action_has_log_prob_zero_and_no_entropy():
    policy, size = make_policy()
    masks = th.zeros(4, 21, dtype=th.bool)
    masks[:, 0] = True                                    # message 0 only
    masks[:, 16 + 4] = True                               # Stay only
    with th.no_grad():
        actions, _, log_prob, _ = policy(th.rand(4, size), zero_states(policy, 4), th.ones(4), action_masks=masks)
        _, lp, entropy = policy.evaluate_actions(th.rand(4, size), actions, zero_states(policy, 4), th.ones(4),
                                                 action_masks=masks)
    assert actions.tolist() == [[0, 4]] * 4
    assert th.all(log_prob == 0) and th.all(lp == 0) and th.all(entropy.abs() < 1e-6)
