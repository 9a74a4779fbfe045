"""MaskableRecurrentPPO: stored log-probs are recomputed exactly over padded sequences with the
stored masks, a strict env never gets a masked action, inactive slots have log-prob 0, and
save / load keeps predict() with the recurrent state."""
import numpy as np
import pytest
import torch as th

from patrolsb3.core import parse_map
from patrolsb3.sb3 import make_vec_env
from patrolsb3.sb3.maskable_recurrent_ppo import MaskableRecurrentPPO
from patrolsb3.sb3.policy import PatrolRecurrentPolicy, policy_kwargs_for

th.set_num_threads(1)
NON_SQUARE = "S..#..2\n.#.....\n...#5.."


def tiny_model(agents=(1, 2, 3), episode_steps=6, n_steps=16, batch_size=50, seed=0, **kwargs):
    env = make_vec_env(parse_map(NON_SQUARE, name="ns"), agents=agents, variant="rl-msg", seed=seed,
                       max_agents=3, episode_steps=episode_steps)
    model = MaskableRecurrentPPO(PatrolRecurrentPolicy, env, n_steps=n_steps, batch_size=batch_size, n_epochs=1,
                                 seed=seed, device="cpu", gamma=0.95 ** 0.5,
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
    assert n_checked == model.n_steps * model.n_envs
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
    assert env.get_env(0).cfg.invalid_action == "raise"
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
