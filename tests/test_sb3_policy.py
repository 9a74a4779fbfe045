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


def test_masked_sample_is_sb3_contribs_masked_distribution():
    from gymnasium import spaces
    from sb3_contrib.common.maskable.distributions import make_masked_proba_distribution

    from patrolsb3.sb3.policy import masked_sample
    space = spaces.MultiDiscrete([16, 5])
    gen = th.Generator().manual_seed(0)
    logits = th.randn(64, 21, generator=gen)
    masks = th.rand(64, 21, generator=gen) > 0.5
    masks[:, 0] = masks[:, 16 + 4] = True                   # one legal value per dimension at least
    dist = make_masked_proba_distribution(space).proba_distribution(action_logits=logits)
    dist.apply_masking(masks)
    actions, log_prob = masked_sample(logits, masks, space.nvec, deterministic=True)
    th.testing.assert_close(actions, dist.get_actions(deterministic=True).reshape(-1, 2))
    th.testing.assert_close(log_prob, dist.log_prob(actions), rtol=1e-5, atol=1e-5)
    th.manual_seed(1)
    sampled, log_prob = masked_sample(logits, masks, space.nvec)
    assert masks[th.arange(64), sampled[:, 0]].all() and masks[th.arange(64), 16 + sampled[:, 1]].all()
    th.testing.assert_close(log_prob, dist.log_prob(sampled), rtol=1e-5, atol=1e-5)


def test_lstm_step_is_one_step_of_the_lstm():
    from torch import nn

    from patrolsb3.sb3.policy import lstm_step
    lstm = nn.LSTM(7, 5)
    gen = th.Generator().manual_seed(0)
    x, h, c = th.randn(3, 7, generator=gen), th.randn(1, 3, 5, generator=gen), th.randn(1, 3, 5, generator=gen)
    out, (h1, c1) = lstm_step(x, (h, c), lstm)
    ref, (h2, c2) = lstm(x[None], (h, c))
    th.testing.assert_close(out, ref[0])
    th.testing.assert_close(h1, h2)
    th.testing.assert_close(c1, c2)
