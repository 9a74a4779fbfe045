"""MaskableRecurrentPPO: stored log-probs are recomputed exactly over padded sequences with the
stored masks, a strict env never gets a masked action, inactive slots have log-prob 0, padded
slots take no work (and the losses are the old way's restricted to deployed rows), and save /
load keeps predict() with the recurrent state."""
import copy

import numpy as np
import pytest
import torch as th

from sb3_contrib.common.recurrent.buffers import RecurrentRolloutBuffer

from patrolsb3.core import parse_map
from patrolsb3.sb3 import make_vec_env
from patrolsb3.sb3.maskable_recurrent_ppo import MaskableRecurrentPPO
from patrolsb3.sb3.policy import PatrolRecurrentPolicy, policy_kwargs_for

th.set_num_threads(1)
NON_SQUARE = "S..#..2\n.#.....\n...#5.."


def tiny_model(agents=(1, 2, 3), episode_steps=6, n_steps=16, batch_size=50, seed=0, n_minibatches=None, **kwargs):
    env = make_vec_env(parse_map(NON_SQUARE, name="ns"), agents=agents, variant="rl-msg", seed=seed,
                       max_agents=3, episode_steps=episode_steps)
    model = MaskableRecurrentPPO(PatrolRecurrentPolicy, env, n_steps=n_steps, batch_size=batch_size, n_epochs=1,
                                 seed=seed, device="cpu", gamma=0.95 ** 0.5, n_minibatches=n_minibatches,
                                 policy_kwargs=policy_kwargs_for(env.layout, dense_sizes=(32, 32),
                                                                 lstm_hidden_size=16, **kwargs))
    return model, env


def collect(model):
    _, callback = model._setup_learn(model.n_steps * model.n_envs, None)
    assert model.collect_rollouts(model.env, callback, model.rollout_buffer, model.n_steps)
    return model.rollout_buffer


@pytest.mark.parametrize("critic_lstm", [False, True])
def test_recomputed_log_probs_equal_stored(critic_lstm):
    # 6-step episodes (12 env steps) end inside the 16-step rollout, and batch_size 50 cuts
    # sequences mid-episode: padding and episode starts inside the minibatches.
    model, _ = tiny_model(enable_critic_lstm=critic_lstm)
    buffer = collect(model)
    model.policy.set_training_mode(False)
    n_checked = 0
    with th.no_grad():
        for data in buffer.get(model.batch_size):
            real = data.mask > 0.5
            values, log_prob, _ = model.policy.evaluate_actions(
                data.observations, data.actions, data.lstm_states, data.episode_starts,
                action_masks=data.action_masks)
            assert th.allclose(log_prob[real], data.old_log_prob[real], atol=1e-5)
            assert th.allclose(values.flatten()[real], data.old_values[real], atol=1e-5)
            n_checked += int(real.sum())
    assert n_checked == model.n_steps * sum((1, 2, 3))   # deployed rows only
    assert bool((buffer.episode_starts[1:] == 1).any())   # episodes really restarted inside


def test_masks_are_stored_and_needed():
    model, _ = tiny_model()
    buffer = collect(model)
    with th.no_grad():
        data = next(buffer.get(None))
        _, unmasked, _ = model.policy.evaluate_actions(data.observations, data.actions, data.lstm_states,
                                                       data.episode_starts)
    assert not th.allclose(unmasked, data.old_log_prob, atol=1e-3)   # the check above can fail


def test_inactive_slots_have_log_prob_zero():
    model, env = tiny_model(agents=(1, 1, 2))           # 3 slots per episode: 5 of 9 rows inactive
    buffer = collect(model)
    single = buffer.action_masks.sum(axis=-1) == 2       # (n_steps, rows): one message, one move
    assert single.any()
    assert np.all(buffer.log_probs[single] == 0.0)
    assert np.all(buffer.log_probs[~single] < 0.0)


def test_strict_env_learns_without_masked_actions():
    # strict env (invalid_action='raise'): any masked action would raise InvalidActionError / ValueError
    model, env = tiny_model(agents=(3, 3), n_steps=24)
    assert env.episode_config(0).invalid_action == "raise"
    model.learn(2 * model.n_steps * model.n_envs)
    assert model.num_timesteps == 2 * model.n_steps * model.n_envs


def test_save_load_predict_with_recurrent_state(tmp_path):
    model, env = tiny_model()
    obs = env.reset()
    starts = np.ones(env.num_envs, dtype=bool)
    state = None
    for _ in range(3):
        actions, state = model.predict(obs, state, starts, deterministic=True, action_masks=env.action_masks())
        obs, _, starts, _ = env.step(actions)
    masks = env.action_masks()
    before, state_before = model.predict(obs, state, starts, deterministic=True, action_masks=masks)
    model.save(tmp_path / "m.zip")
    loaded = MaskableRecurrentPPO.load(tmp_path / "m.zip", device="cpu")
    after, state_after = loaded.predict(obs, state, starts, deterministic=True, action_masks=masks)
    assert np.array_equal(before, after)
    np.testing.assert_allclose(state_before[0], state_after[0], atol=1e-6)
    fresh, _ = loaded.predict(obs, None, starts, deterministic=True, action_masks=masks)
    assert masks[np.arange(len(after)), after[:, 0]].all() and masks[np.arange(len(after)), 16 + after[:, 1]].all()
    assert fresh.shape == after.shape


def test_padded_slots_are_not_run_through_the_rollout_forward():
    model, env = tiny_model(agents=(1, 1, 2))           # 3 slots per episode: 4 of 9 rows deployed
    rows_seen = []
    forward = model.policy.forward
    model.policy.forward = lambda obs, *a, **k: (rows_seen.append(obs.shape[0]), forward(obs, *a, **k))[1]
    buffer = collect(model)
    assert rows_seen == [4] * model.n_steps
    assert buffer.deployed.sum(axis=1).tolist() == [4] * model.n_steps


def _loss_and_grads(model, data, row_mask=None):
    model.policy.optimizer.zero_grad()
    loss, terms = model.minibatch_loss(data, clip_range=0.15, clip_range_vf=None, row_mask=row_mask)
    loss.backward()
    return loss.item(), terms, [p.grad.detach().clone() for p in model.policy.parameters()]


def test_losses_and_gradients_equal_the_old_way_on_deployed_rows(monkeypatch):
    """One rollout with padded slots: the skip's loss and gradients equal those of sb3-contrib's
    whole-buffer minibatch (padded rows included) with the loss restricted to deployed rows;
    the advantage normalisation of the skip sees deployed rows only."""
    model, env = tiny_model(agents=(1, 1, 2))
    buffer = collect(model)
    old = copy.deepcopy(buffer)
    with th.no_grad():                                   # ratios != 1: the policy loss has weight
        for p in model.policy.parameters():
            p.add_(0.01 * th.randn_like(p))
    monkeypatch.setattr(np.random, "randint", lambda n: 0)
    new_data = next(buffer.get(None))
    assert int((new_data.mask > 0.5).sum()) == int(old.deployed.sum())
    # the old way: every row in the minibatch, the loss masked to deployed rows
    old.action_masks = old.swap_and_flatten(old.action_masks)
    old.deployed = old.swap_and_flatten(old.deployed.astype(np.float32))
    old_data = next(RecurrentRolloutBuffer.get(old, None))
    deployed = old.pad_and_flatten(old.deployed[np.arange(old.n_envs * old.buffer_size)]) > 0.5
    assert int(deployed.sum()) < int((old_data.mask > 0.5).sum())   # padded rows were there
    new_loss, new_terms, new_grads = _loss_and_grads(model, new_data)
    old_loss, old_terms, old_grads = _loss_and_grads(model, old_data, row_mask=deployed)
    assert abs(new_terms["policy_loss"]) > 1e-6
    assert new_loss == pytest.approx(old_loss, rel=1e-5, abs=1e-7)
    for key in new_terms:
        assert new_terms[key] == pytest.approx(old_terms[key], rel=1e-4, abs=1e-7), key
    for new, old_grad in zip(new_grads, old_grads):
        th.testing.assert_close(new, old_grad, rtol=1e-4, atol=1e-6)
    # and the loss over every row (padded ones in the normalisation and the means) differs
    every_loss, _, _ = _loss_and_grads(model, old_data)
    assert every_loss != pytest.approx(new_loss, rel=1e-3)


def test_n_minibatches_splits_the_deployed_rows():
    model, env = tiny_model(agents=(1, 1, 2), n_minibatches=3)
    collect(model)
    assert model.update_batch_size() == -(-model.n_steps * 4 // 3)
    sizes = [int((d.mask > 0.5).sum()) for d in model.rollout_buffer.get(model.update_batch_size())]
    assert sum(sizes) == model.n_steps * 4 and len(sizes) == 3


def test_a_zoo_model_zip_loads_as_an_sb3_model_and_acts_on_the_training_env(tiny_zoo):
    """SB3 users' way: MaskableRecurrentPPO.load(zoo model.zip) (a policy only), predict with
    action_masks on the training vec env's rows; with env= it trains on."""
    from patrolsb3 import zoo
    entry = zoo.entry_dir("A", "rl-msg", zoo_dir=tiny_zoo) / "model.zip"   # <zoo>/A/rl-msg/seed<k>/
    model = MaskableRecurrentPPO.load(entry, device="cpu")
    policy = zoo.load("A", "rl-msg", zoo_dir=tiny_zoo)
    settings = {k: v for k, v in policy.env_settings().items() if k != "comm"}
    venv = make_vec_env("A", agents=[3, 2], variant="rl-msg", seed=0, **settings)
    obs, masks = venv.reset(), venv.action_masks()
    starts = np.ones(venv.num_envs, dtype=bool)
    actions, state = model.predict(obs, state=None, episode_start=starts, deterministic=True, action_masks=masks)
    reference, _ = policy.policy.predict(obs, state=None, episode_start=starts, deterministic=True,
                                         action_masks=masks)
    np.testing.assert_array_equal(actions, reference)
    assert masks[np.arange(len(actions)), actions[:, 0]].all()
    venv.step(actions)                                       # a strict env accepts them
    trainable = MaskableRecurrentPPO.load(entry, env=venv, device="cpu", n_steps=8, batch_size=32)
    trainable.learn(8 * venv.num_envs)
    assert trainable.num_timesteps == 8 * venv.num_envs


def test_the_message_head_can_have_an_entropy_coefficient_of_its_own():
    """With ent_coef_message, the move head's entropy is averaged over every real row (weighted by
    ent_coef) and the message head's over the rows where it has a choice (weighted by
    ent_coef_message); with both at 0 the loss is the plain PPO loss without entropy."""
    model, _ = tiny_model(agents=(2, 3, 3))
    buffer = collect(model)
    data = next(buffer.get(None))
    mask = data.mask > 1e-8
    with th.no_grad():
        _, _, per_head = model.policy.evaluate_actions(data.observations, data.actions, data.lstm_states,
                                                       data.episode_starts, action_masks=data.action_masks,
                                                       per_head=True)
    n_messages = int(model.action_space.nvec[0])
    speaking = mask & (data.action_masks[:, :n_messages].sum(dim=1) > 1)
    assert 0 < int(speaking.sum()) < int(mask.sum())           # message phases only: some rows, not all
    model.ent_coef, model.ent_coef_message = 0.0, 0.3
    loss, terms = model.minibatch_loss(data, clip_range=0.15)
    assert terms["message_entropy_loss"] == pytest.approx(-per_head[:, 0][speaking].mean().item(), rel=1e-5)
    assert terms["entropy_loss"] == pytest.approx(-per_head[:, 1][mask].mean().item(), rel=1e-5)
    assert terms["message_entropy_loss"] < 0                   # a real bonus: the head has a choice
    plain = loss.item() - 0.3 * terms["message_entropy_loss"]
    model.ent_coef_message = None                              # the default: one coefficient, 0 here
    default_loss, _ = model.minibatch_loss(data, clip_range=0.15)
    assert plain == pytest.approx(default_loss.item(), rel=1e-5)


def test_ent_coef_message_is_refused_where_it_means_nothing():
    with pytest.raises(ValueError, match="ent_coef_message must be a number"):
        MaskableRecurrentPPO(PatrolRecurrentPolicy, tiny_model()[1], ent_coef_message="high")
    from patrolsb3.sb3.train import check_run_settings, resolve_hyperparams
    hp = resolve_hyperparams("A", overrides={"algo": "MaskablePPO", "ent_coef_message": 0.01})
    with pytest.raises(ValueError, match="ent_coef_message is a setting of MaskableRecurrentPPO"):
        check_run_settings(hp, 1000)


def planes_model(variant="rl-msg", **algo_kwargs):
    env = make_vec_env(parse_map(NON_SQUARE, name="ns"), agents=(2, 3, 3), variant=variant, seed=0,
                       max_agents=3, episode_steps=6, message_encoding="planes")
    model = MaskableRecurrentPPO(PatrolRecurrentPolicy, env, n_steps=16, batch_size=50, n_epochs=1, seed=0,
                                 device="cpu", policy_kwargs=policy_kwargs_for(env.layout, dense_sizes=(32, 32),
                                                                                lstm_hidden_size=16),
                                 **algo_kwargs)
    return model, env


def test_the_signalling_term_is_the_entropy_of_the_mean_symbol_minus_the_mean_entropy():
    model, _ = planes_model(signal_coef=0.5)
    data = next(collect(model).get(None))
    mask = data.mask > 1e-8
    loss, terms = model.minibatch_loss(data, clip_range=0.15)
    with th.no_grad():
        _, _, _, dist = model.policy.evaluate_actions(data.observations, data.actions, data.lstm_states,
                                                      data.episode_starts, action_masks=data.action_masks,
                                                      with_distribution=True)
    probs = dist.distributions[0].probs.numpy()                               # (n, 16)
    speaking = (mask & (data.action_masks[:, :16].sum(dim=1) > 1)).numpy()
    p = probs[speaking]
    mean = p.mean(axis=0)
    expected = -(mean * np.log(mean)).sum() - (-(p * np.log(np.where(p > 0, p, 1))).sum(axis=1)).mean()
    assert terms["signalling"] == pytest.approx(expected, rel=1e-4, abs=1e-6)
    model.signal_coef = None                                                  # the default: no term
    plain, plain_terms = model.minibatch_loss(data, clip_range=0.15)
    assert "signalling" not in plain_terms
    assert loss.item() == pytest.approx(plain.item() - 0.5 * terms["signalling"], rel=1e-5, abs=1e-6)


def test_the_listening_term_compares_the_moves_with_and_without_the_received_symbols():
    model, _ = planes_model(listen_coef=2.0)
    data = next(collect(model).get(None))
    mask = data.mask > 1e-8
    loss, terms = model.minibatch_loss(data, clip_range=0.15)
    C, H, W = model.policy.features_extractor_kwargs["grid_shape"]
    obs = data.observations
    planes = obs[:, 2 * H * W:C * H * W]
    rows = (mask & (planes < 0).any(dim=1) & (data.action_masks[:, 16:].sum(dim=1) > 1)
            & (obs[:, C * H * W + 6] > 0.5))
    assert 0 < int(rows.sum()) < int(mask.sum())          # move rows that heard something, not all
    silent = obs.clone()
    silent[:, 2 * H * W:C * H * W] = th.where(planes < 0, th.zeros_like(planes), planes)
    with th.no_grad():   # (SB3's policy refills one distribution object: copy the probs out)
        heard, _ = model.policy.get_distribution(obs, data.lstm_states.pi, data.episode_starts, data.action_masks)
        heard = heard.distributions[1].probs.clone()
        unheard, _ = model.policy.get_distribution(silent, data.lstm_states.pi, data.episode_starts,
                                                   data.action_masks)
        unheard = unheard.distributions[1].probs.clone()
    expected = (heard[rows] - unheard[rows]).abs().sum(1).mean()
    assert terms["listening"] == pytest.approx(expected.item(), rel=1e-4)
    assert terms["listening"] > 0                         # an untrained policy already hears a little
    model.listen_coef = None
    plain, _ = model.minibatch_loss(data, clip_range=0.15)
    assert loss.item() == pytest.approx(plain.item() - 2.0 * terms["listening"], rel=1e-5, abs=1e-6)
    # the bonus has a gradient (through the heard branch only) that reaches the actor's convolutions
    model.policy.optimizer.zero_grad()
    model.listening(model.policy.evaluate_actions(data.observations, data.actions, data.lstm_states,
                                                  data.episode_starts, action_masks=data.action_masks,
                                                  with_distribution=True)[3], data, mask).backward()
    conv = model.policy.pi_features_extractor.conv[0].weight.grad
    assert conv is not None and float(conv.abs().sum()) > 0
    # without messages nothing is received: the term is 0 and takes no work
    quiet, _ = planes_model(variant="rl-no-msg", listen_coef=2.0)
    _, quiet_terms = quiet.minibatch_loss(next(collect(quiet).get(None)), clip_range=0.15)
    assert quiet_terms["listening"] == 0.0


def test_listening_and_signalling_settings_are_refused_where_they_mean_nothing():
    with pytest.raises(ValueError, match="listen_coef needs legible messages"):
        MaskableRecurrentPPO(PatrolRecurrentPolicy, tiny_model()[1], listen_coef=1.0,
                             policy_kwargs=policy_kwargs_for(tiny_model()[1].layout))
    with pytest.raises(ValueError, match="signal_coef must be a number"):
        MaskableRecurrentPPO(PatrolRecurrentPolicy, tiny_model()[1], signal_coef="yes")
    from patrolsb3.sb3.train import check_run_settings, resolve_hyperparams
    hp = resolve_hyperparams("A", overrides={"listen_coef": 0.1})
    with pytest.raises(ValueError, match="listen_coef needs legible messages: set env.message_encoding=planes"):
        check_run_settings(hp, 1000)
    hp = resolve_hyperparams("A", overrides={"listen_coef": 0.1, "env": {"message_encoding": "planes"}})
    check_run_settings(hp, 1000)
    hp = resolve_hyperparams("A", overrides={"algo": "MaskablePPO", "signal_coef": 0.1})
    with pytest.raises(ValueError, match="signal_coef is a setting of MaskableRecurrentPPO"):
        check_run_settings(hp, 1000)
    hp = resolve_hyperparams("A", overrides={"message_team_share": 2})
    with pytest.raises(ValueError, match="message_team_share must be between 0 and 1"):
        check_run_settings(hp, 1000)


def test_team_gap_is_the_team_mean_minus_the_own_reward_of_deployed_rows():
    from patrolsb3.sb3.buffers import team_gap
    rewards = np.array([1.0, 3.0, 9.0, 4.0, 0.0, 7.0])            # two episodes of 3 slots
    deployed = np.array([True, True, False, True, True, True])     # episode 0 deploys 2 slots
    gaps = team_gap(rewards, deployed, np.array([0, 0, 0, 1, 1, 1]))
    np.testing.assert_allclose(gaps, [1.0, -1.0, 0.0, 11 / 3 - 4, 11 / 3, 11 / 3 - 7])   # means 2 and 11/3


def test_message_team_share_moves_only_the_message_rows_advantages_by_the_discounted_team_gap():
    """Two identical runs, one with message_team_share=1: same rollout, same returns (the
    critic's targets), same advantages on move rows; on rows with a message choice the
    advantage grows by the GAE (values 0) of the team-mean-minus-own rewards, computed here
    with the textbook recursion."""
    def model(share):
        env = make_vec_env(parse_map(NON_SQUARE, name="ns"), agents=(2, 3, 3), variant="rl-msg", seed=0,
                           max_agents=3, episode_steps=6)
        return MaskableRecurrentPPO(PatrolRecurrentPolicy, env, n_steps=16, batch_size=50, n_epochs=1, seed=0,
                                    device="cpu", gamma=0.95, gae_lambda=0.9, message_team_share=share,
                                    policy_kwargs=policy_kwargs_for(env.layout, dense_sizes=(32, 32),
                                                                    lstm_hidden_size=16))
    plain = collect(model(None))          # each model seeds torch when built: build, then collect
    with_share = model(1.0)
    shared = collect(with_share)
    last_dones = np.asarray(with_share._last_episode_starts, dtype=np.float64)     # (9,) ended at the last step
    np.testing.assert_array_equal(plain.actions, shared.actions)
    np.testing.assert_allclose(plain.returns, shared.returns)
    gaps = shared.team_gaps.astype(np.float64)                                  # (16, 9)
    assert np.allclose(gaps.reshape(16, 3, 3).sum(axis=-1)[:, 0] + gaps[:, 2], 0.0, atol=1e-5)   # 2 deployed
    assert (gaps[:, 2] == 0).all() and np.abs(gaps).max() > 0                   # padded slot: 0
    expected = np.zeros_like(gaps)
    following = np.zeros(9)
    for t in reversed(range(16)):
        non_terminal = 1.0 - (shared.episode_starts[t + 1] if t < 15 else last_dones)
        following = gaps[t] + 0.95 * 0.9 * non_terminal * following
        expected[t] = following
    speaking = shared.action_masks[..., :16].sum(axis=-1) > 1
    assert speaking.any() and (~speaking).any()
    np.testing.assert_allclose(shared.advantages[~speaking], plain.advantages[~speaking], atol=1e-6)
    np.testing.assert_allclose(shared.advantages[speaking] - plain.advantages[speaking], expected[speaking],
                               atol=1e-4)
    with pytest.raises(ValueError, match="message_team_share must be between 0 and 1"):
        model(1.5)
