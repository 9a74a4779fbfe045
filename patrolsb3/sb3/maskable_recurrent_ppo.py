"""MaskableRecurrentPPO: sb3-contrib's RecurrentPPO with MaskablePPO's action masks.

sb3-contrib has recurrent PPO and maskable PPO but not both at once. This class keeps
RecurrentPPO's recurrence (padded sequences, LSTM states, episode starts) and adds what
MaskablePPO does: masks are read from the env before every step of a rollout, stored in the
buffer (:class:`MaskableRecurrentRolloutBuffer`), and applied when actions are sampled, when
the log-probs are recomputed in ``train`` and in ``predict``. With masks, an action a
strict env would refuse is never sampled, and a slot with a single legal action has
log-prob exactly 0 (no gradient through the policy loss).

Padded slots (rows of an env's ``deployed_rows()`` that are False: slots a smaller team does
not deploy) take no work: the rollout runs the policy on deployed rows only (a padded row
takes its single legal action, value and log-prob 0), and the buffer keeps them out of every
minibatch (:class:`MaskableRecurrentRolloutBuffer`). An env without ``deployed_rows`` has every
row deployed.

Minibatches: ``batch_size`` rows (deployed ones), or, with ``n_minibatches`` given, the
deployed rows of each rollout split into that many minibatches.
"""
from __future__ import annotations

from copy import deepcopy
from typing import ClassVar, Protocol, runtime_checkable

import numpy as np
import torch as th
from sb3_contrib import RecurrentPPO
from sb3_contrib.common.maskable.utils import get_action_masks, is_masking_supported
from sb3_contrib.common.recurrent.type_aliases import RNNStates
from stable_baselines3.common.utils import explained_variance, obs_as_tensor
from stable_baselines3.common.vec_env import VecEnv

from ..core.protocol import ObservationLayout
from .buffers import MaskableRecurrentRolloutBuffer, team_gap
from .policy import PatrolRecurrentPolicy


@runtime_checkable
class PatrolRows(Protocol):
    """What MaskableRecurrentPPO asks of its vec env beyond SB3's ``VecEnv`` (our
    :func:`patrolsb3.sb3.make_vec_env` has all three). ``action_masks`` is required (or
    sb3-contrib's ``env_method("action_masks")``); without ``deployed_rows`` every row is
    deployed; ``episode_of_rows`` is needed only with ``message_team_share``."""

    def action_masks(self) -> np.ndarray:
        """(num_envs, sum(nvec)) bool legal actions of every row."""

    def deployed_rows(self) -> np.ndarray:
        """(num_envs,) bool rows of deployed agents (a smaller team's padded slots are False)."""

    def episode_of_rows(self) -> np.ndarray:
        """(num_envs,) int the parallel episode of every row."""


def env_deployed_rows(env: VecEnv) -> np.ndarray:
    """(num_envs,) bool rows the policy acts for: the vec env's ``deployed_rows()``
    (:class:`PatrolRows`), else all."""
    method = getattr(env, "deployed_rows", None)           # every rollout step: no Protocol isinstance
    if callable(method):
        return np.asarray(method(), dtype=bool)
    return np.ones(env.num_envs, dtype=bool)


def first_legal_actions(masks: np.ndarray, nvec: np.ndarray) -> np.ndarray:
    """(n, len(nvec)) the first legal value of each action dimension of (n, sum(nvec)) masks."""
    bounds = np.concatenate([[0], np.cumsum(nvec)])
    return np.stack([np.argmax(masks[:, a:b], axis=1) for a, b in zip(bounds[:-1], bounds[1:])], axis=1)


def env_action_masks(env: VecEnv) -> np.ndarray:
    """(num_envs, sum(nvec)) bool masks: the vec env's own ``action_masks()`` when it has
    one (one call), else sb3-contrib's ``env_method("action_masks")`` per env."""
    method = getattr(env, "action_masks", None)
    if callable(method):
        return np.asarray(method(), dtype=bool)
    return np.asarray(get_action_masks(env), dtype=bool)


class MaskableRecurrentPPO(RecurrentPPO):
    """Recurrent PPO (LSTM) with invalid-action masking.

    Same arguments as :class:`sb3_contrib.RecurrentPPO`; the policy must accept
    ``action_masks`` in ``forward``, ``evaluate_actions`` and ``predict`` (the default is
    :class:`~patrolsb3.sb3.policy.PatrolRecurrentPolicy`). The env must expose
    ``action_masks()`` (our vec env does) or answer ``env_method("action_masks")``.
    """

    policy_aliases: ClassVar[dict] = {"PatrolRecurrentPolicy": PatrolRecurrentPolicy}

    def __init__(self, *args, n_minibatches: int | None = None, ent_coef_message: float | None = None,
                 signal_coef: float | None = None, listen_coef: float | None = None,
                 message_team_share: float | None = None, **kwargs):
        """Args as :class:`sb3_contrib.RecurrentPPO`, plus

        Args:
            n_minibatches: when given, each update splits the rollout's deployed rows into that
                many minibatches (``batch_size`` is then ignored).
            ent_coef_message: an entropy coefficient of the message head of its own (OURS, for
                learned messages): its entropy bonus is averaged over the rows whose message
                head has a choice (the message phases of rl-msg), not diluted over every row,
                and ``ent_coef`` then weighs the move head's entropy alone. None (default): one
                ``ent_coef`` on the summed entropy of both heads over every row, as SB3.
            signal_coef: weight of a positive-signalling bonus (OURS, after Eccles et al. 2019):
                over a minibatch's rows where the message head has a choice, the entropy of the
                mean symbol distribution minus the mean entropy of each row's, an estimate of
                the mutual information between what a speaker sees and the symbol it sends.
                None or 0: none.
            listen_coef: weight of a positive-listening bonus (OURS, after Eccles et al. 2019):
                over move rows that received symbols and have a choice of move, the L1 distance
                between the move distribution and the same policy's move distribution with the
                received symbols removed (the others' symbol planes cleared; that branch is
                computed without gradient). Needs legible messages (``message_encoding``
                'planes'). None or 0: none.
            message_team_share: a team share of the reward on message rows (OURS), 0..1: the
                advantage of a row whose message head has a choice is computed as if the
                row's own reward were ``(1 - share) * own + share * team mean`` (the mean over
                its episode's deployed slots), so a speaker is paid for what its symbol does
                for the others; move rows and the critic's targets keep the own reward (the
                baseline stays the agent's own value, an approximation). Needs a vec env with
                ``episode_of_rows()`` (ours). None or 0: none.
        """
        if n_minibatches is not None and int(n_minibatches) < 1:
            raise ValueError(f"n_minibatches must be >= 1, got {n_minibatches}")
        for name, value in (("ent_coef_message", ent_coef_message), ("signal_coef", signal_coef),
                            ("listen_coef", listen_coef), ("message_team_share", message_team_share)):
            if value is not None and (isinstance(value, bool) or not isinstance(value, (int, float))):
                raise ValueError(f"{name} must be a number or None, got {value!r}")
        if message_team_share is not None and not 0.0 <= float(message_team_share) <= 1.0:
            raise ValueError(f"message_team_share must be between 0 and 1, got {message_team_share}")
        self.message_team_share = None if message_team_share is None else float(message_team_share)
        self.n_minibatches = None if n_minibatches is None else int(n_minibatches)
        self.ent_coef_message = None if ent_coef_message is None else float(ent_coef_message)
        self.signal_coef = None if signal_coef is None else float(signal_coef)
        self.listen_coef = None if listen_coef is None else float(listen_coef)
        super().__init__(*args, **kwargs)
        if self.listen_coef and self.observation_layout().grid_shape[0] <= 2:
            raise ValueError("listen_coef needs legible messages (env.message_encoding=planes): with "
                             "'scalar' messages the received symbols have no channel of their own")

    def update_batch_size(self) -> int:
        """Rows per minibatch of the coming update (``n_minibatches`` splits the rollout)."""
        n_minibatches = getattr(self, "n_minibatches", None)    # absent in older checkpoints
        if n_minibatches is None:
            return int(self.batch_size)
        self.rollout_buffer.prepare()
        return max(2, -(-self.rollout_buffer.n_rows // n_minibatches))

    def _setup_model(self) -> None:
        super()._setup_model()
        lstm = self.policy.lstm_actor
        self.rollout_buffer = MaskableRecurrentRolloutBuffer(
            self.n_steps, self.observation_space, self.action_space,
            (self.n_steps, lstm.num_layers, self.n_envs, lstm.hidden_size), self.device,
            gamma=self.gamma, gae_lambda=self.gae_lambda, n_envs=self.n_envs)

    def collect_rollouts(self, env: VecEnv, callback, rollout_buffer, n_rollout_steps: int) -> bool:
        """RecurrentPPO.collect_rollouts with masks read before each step and stored; the
        horizon bootstrap of all truncated rows is one batched critic call. In bf16 the
        weights are cast once for the whole collection (they do not change during it)."""
        with self.policy.frozen_weights_scope():
            return self._collect_rollouts(env, callback, rollout_buffer, n_rollout_steps)

    def _collect_rollouts(self, env: VecEnv, callback, rollout_buffer, n_rollout_steps: int) -> bool:
        assert self._last_obs is not None, "No previous observation was provided"
        if not is_masking_supported(env) and not callable(getattr(env, "action_masks", None)):
            raise ValueError("MaskableRecurrentPPO needs an env with action_masks() (patrolsb3.sb3.make_vec_env "
                             "provides it); use RecurrentPPO for an env without masks")
        self.policy.set_training_mode(False)
        n_steps = 0
        rollout_buffer.reset()
        callback.on_rollout_start()
        lstm_states = deepcopy(self._last_lstm_states)
        dones = self._last_episode_starts
        new_obs = self._last_obs
        nvec = self.action_space.nvec
        share = getattr(self, "message_team_share", None)         # absent in older checkpoints
        episode_of_rows = None
        if share:
            method = getattr(env, "episode_of_rows", None)
            if not callable(method):
                raise ValueError("message_team_share needs a vec env with episode_of_rows() (patrolsb3.sb3."
                                 "make_vec_env provides it)")
            episode_of_rows = np.asarray(method(), dtype=np.int64)                 # (n_envs,)
        while n_steps < n_rollout_steps:
            action_masks = env_action_masks(env)                                   # (n_envs, 21)
            deployed = env_deployed_rows(env)                                      # (n_envs,)
            actions, values, log_probs, lstm_states = self._act_deployed(
                self._last_obs, lstm_states, self._last_episode_starts, action_masks, deployed, nvec)
            new_obs, rewards, dones, infos = env.step(actions)
            self.num_timesteps += env.num_envs
            callback.update_locals(locals())
            if not callback.on_step():
                return False
            self._update_info_buffer(infos, dones)
            n_steps += 1
            gaps = None if episode_of_rows is None else team_gap(rewards, deployed, episode_of_rows)
            self._bootstrap_truncated(rewards, dones, infos, lstm_states, deployed)   # after the gaps: raw rewards there
            rollout_buffer.add(self._last_obs, actions, rewards, self._last_episode_starts, values, log_probs,
                               lstm_states=self._last_lstm_states, action_masks=action_masks, deployed=deployed,
                               team_gaps=gaps)
            self._last_obs = new_obs
            self._last_episode_starts = dones
            self._last_lstm_states = lstm_states
        with th.no_grad():
            episode_starts = th.tensor(dones, dtype=th.float32, device=self.device)
            values = self.policy.predict_values(obs_as_tensor(new_obs, self.device), lstm_states.vf, episode_starts)
        rollout_buffer.compute_returns_and_advantage(last_values=values, dones=dones)
        if share:
            rollout_buffer.share_team_reward(share, int(nvec[0]), dones)
        callback.on_rollout_end()
        return True

    def _act_deployed(self, obs: np.ndarray, lstm_states, episode_starts: np.ndarray, action_masks: np.ndarray,
                      deployed: np.ndarray, nvec: np.ndarray):
        """The policy's forward pass on the deployed rows only.

        Returns:
            actions (n_envs, len(nvec)) numpy, values (n_envs, 1), log-probs (n_envs,) and the
            new LSTM states; padded rows get their first legal action, value 0, log-prob 0 and
            keep their LSTM state.
        """
        rows = np.flatnonzero(deployed)
        every = len(rows) == len(deployed)
        index = slice(None) if every else th.as_tensor(rows, device=self.device)
        with th.no_grad():
            obs_tensor = obs_as_tensor(obs[rows] if not every else obs, self.device)
            starts = th.tensor(episode_starts[rows] if not every else episode_starts, dtype=th.float32,
                               device=self.device)
            masks = th.as_tensor(action_masks[rows] if not every else action_masks, device=self.device)
            sub_states = RNNStates((lstm_states.pi[0][:, index], lstm_states.pi[1][:, index]),
                                   (lstm_states.vf[0][:, index], lstm_states.vf[1][:, index]))
            actions, values, log_probs, states = self.policy(obs_tensor, sub_states, starts, action_masks=masks)
        if every:
            return actions.cpu().numpy(), values, log_probs, states
        all_actions = first_legal_actions(action_masks, nvec)                    # (n_envs, len(nvec))
        all_actions[rows] = actions.cpu().numpy()
        all_values = th.zeros((len(deployed), 1), device=self.device)
        all_values[index] = values
        all_log_probs = th.zeros(len(deployed), device=self.device)
        all_log_probs[index] = log_probs
        merged = []
        for old, new in ((lstm_states.pi, states.pi), (lstm_states.vf, states.vf)):
            pair = []
            for old_t, new_t in zip(old, new):
                t = old_t.clone()
                t[:, index] = new_t
                pair.append(t)
            merged.append(tuple(pair))
        return all_actions, all_values, all_log_probs, RNNStates(*merged)

    def _bootstrap_truncated(self, rewards: np.ndarray, dones: np.ndarray, infos: list, lstm_states,
                             deployed: np.ndarray) -> None:
        """Add gamma * V(terminal observation) to the rewards (n_envs,) of deployed rows cut by
        the time limit (SB3 issue #633), in one batched critic call."""
        rows = [i for i in np.flatnonzero(dones & deployed) if infos[i].get("terminal_observation") is not None
                and infos[i].get("TimeLimit.truncated", False)]
        if not rows:
            return
        terminal_obs = np.stack([infos[i]["terminal_observation"] for i in rows])     # (k, obs_dim)
        with th.no_grad():
            state = (lstm_states.vf[0][:, rows, :].contiguous(), lstm_states.vf[1][:, rows, :].contiguous())
            starts = th.zeros(len(rows), dtype=th.float32, device=self.device)
            values = self.policy.predict_values(obs_as_tensor(terminal_obs, self.device), state, starts)
        rewards[rows] += self.gamma * values.flatten().cpu().numpy()

    def train(self) -> None:
        """RecurrentPPO.train with the stored masks applied when log-probs are recomputed."""
        self.policy.set_training_mode(True)
        self._update_learning_rate(self.policy.optimizer)
        clip_range = self.clip_range(self._current_progress_remaining)
        clip_range_vf = self.clip_range_vf(self._current_progress_remaining) if self.clip_range_vf is not None else None
        entropy_losses, pg_losses, value_losses, clip_fractions, approx_kl_divs = [], [], [], [], []
        extra_terms = {}                          # optional terms: message entropy, signalling, listening
        continue_training = True
        for epoch in range(self.n_epochs):
            approx_kl_divs = []
            for data in self.rollout_buffer.get(self.update_batch_size()):
                loss, terms = self.minibatch_loss(data, clip_range, clip_range_vf)
                pg_losses.append(terms["policy_loss"])
                clip_fractions.append(terms["clip_fraction"])
                value_losses.append(terms["value_loss"])
                entropy_losses.append(terms["entropy_loss"])
                for key in ("message_entropy_loss", "signalling", "listening"):
                    if key in terms:
                        extra_terms.setdefault(key, []).append(terms[key])
                approx_kl_div = terms["approx_kl"]
                approx_kl_divs.append(approx_kl_div)
                if self.target_kl is not None and approx_kl_div > 1.5 * self.target_kl:
                    continue_training = False
                    if self.verbose >= 1:
                        print(f"Early stopping at step {epoch} due to reaching max kl: {approx_kl_div:.2f}")
                    break
                self.policy.optimizer.zero_grad()
                loss.backward()
                th.nn.utils.clip_grad_norm_(self.policy.parameters(), self.max_grad_norm)
                self.policy.optimizer.step()
            self._n_updates += 1
            if not continue_training:
                break
        explained_var = explained_variance(self.rollout_buffer.values.flatten(), self.rollout_buffer.returns.flatten())
        self.logger.record("train/entropy_loss", np.mean(entropy_losses))
        for key, values in extra_terms.items():
            self.logger.record(f"train/{key}", np.mean(values))
        self.logger.record("train/policy_gradient_loss", np.mean(pg_losses))
        self.logger.record("train/value_loss", np.mean(value_losses))
        self.logger.record("train/approx_kl", np.mean(approx_kl_divs))
        self.logger.record("train/clip_fraction", np.mean(clip_fractions))
        self.logger.record("train/loss", loss.item())
        self.logger.record("train/explained_variance", explained_var)
        self.logger.record("train/n_updates", self._n_updates, exclude="tensorboard")
        self.logger.record("train/clip_range", clip_range)
        if clip_range_vf is not None:
            self.logger.record("train/clip_range_vf", clip_range_vf)

    def minibatch_loss(self, data, clip_range: float, clip_range_vf: float | None = None,
                       row_mask: th.Tensor | None = None):
        """PPO's loss on one padded minibatch, over its real steps (and ``row_mask``, if given).

        Args:
            data: a :class:`~patrolsb3.sb3.buffers.MaskableRecurrentRolloutBufferSamples`.
            clip_range: the policy ratio clip.
            clip_range_vf: the value clip (None: no clip).
            row_mask: (n,) bool, further rows to leave out (tests compare the padded-slot skip
                with the old way restricted to deployed rows).

        Returns:
            The loss tensor, and its terms as floats: policy_loss, value_loss, entropy_loss,
            clip_fraction, approx_kl.
        """
        mask = data.mask > 1e-8                                                    # real (not padded) steps
        if row_mask is not None:
            mask = mask & row_mask
        message_coef = getattr(self, "ent_coef_message", None)      # absent in older checkpoints
        signal_coef = getattr(self, "signal_coef", None) or 0.0
        listen_coef = getattr(self, "listen_coef", None) or 0.0
        values, log_prob, entropy, distribution = self.policy.evaluate_actions(
            data.observations, data.actions, data.lstm_states, data.episode_starts,
            action_masks=data.action_masks, per_head=message_coef is not None, with_distribution=True)
        values = values.flatten()
        advantages = data.advantages
        if self.normalize_advantage and int(mask.sum()) > 1:   # as SB3's PPO: not over a single row
            advantages = (advantages - advantages[mask].mean()) / (advantages[mask].std() + 1e-8)
        ratio = th.exp(log_prob - data.old_log_prob)
        policy_loss_1 = advantages * ratio
        policy_loss_2 = advantages * th.clamp(ratio, 1 - clip_range, 1 + clip_range)
        policy_loss = -th.mean(th.min(policy_loss_1, policy_loss_2)[mask])
        if clip_range_vf is None:
            values_pred = values
        else:
            values_pred = data.old_values + th.clamp(values - data.old_values, -clip_range_vf, clip_range_vf)
        value_loss = th.mean(((data.returns - values_pred) ** 2)[mask])
        terms = {}
        if message_coef is None:
            entropy_loss = -th.mean(entropy[mask])
            loss = policy_loss + self.ent_coef * entropy_loss + self.vf_coef * value_loss
        else:                   # each head its own coefficient; the message head over its choices only
            n_messages = int(self.action_space.nvec[0])
            speaking = mask & (data.action_masks[:, :n_messages].sum(dim=1) > 1)   # (n,) message choices
            entropy_loss = -th.mean(entropy[:, 1][mask])
            message_entropy_loss = (-th.mean(entropy[:, 0][speaking]) if bool(speaking.any())
                                    else entropy.new_zeros(()))
            loss = (policy_loss + self.ent_coef * entropy_loss + message_coef * message_entropy_loss
                    + self.vf_coef * value_loss)
            terms["message_entropy_loss"] = message_entropy_loss.item()
        if signal_coef:
            signalling = self.signalling(distribution, data.action_masks, mask)
            loss = loss - signal_coef * signalling
            terms["signalling"] = signalling.item()
        if listen_coef:
            listening = self.listening(distribution, data, mask)
            loss = loss - listen_coef * listening
            terms["listening"] = listening.item()
        with th.no_grad():
            log_ratio = log_prob - data.old_log_prob
            approx_kl = th.mean(((th.exp(log_ratio) - 1) - log_ratio)[mask]).item()
            clip_fraction = th.mean((th.abs(ratio - 1) > clip_range).float()[mask]).item()
        return loss, {"policy_loss": policy_loss.item(), "value_loss": value_loss.item(),
                      "entropy_loss": entropy_loss.item(), "clip_fraction": clip_fraction,
                      "approx_kl": approx_kl, **terms}

    def observation_layout(self) -> ObservationLayout:
        """Where each part of an observation row sits (the policy's grid, vector and critic
        sizes): the algorithm reads rows through it, not by hand."""
        kw = self.policy.features_extractor_kwargs
        return ObservationLayout(tuple(kw["grid_shape"]), int(kw["vector_size"]), int(kw["critic_size"]),
                                 int(kw["critic_size"]) // 3)

    def signalling(self, distribution, action_masks: th.Tensor, mask: th.Tensor) -> th.Tensor:
        """The positive-signalling term of a minibatch: H(mean symbol distribution) - mean H(symbol
        distribution of a row), over the real rows whose message head has a choice (0 if none).

        Args:
            distribution: the masked distribution of the minibatch (message head first).
            action_masks: (n, n_symbols + 5) the rows' masks.
            mask: (n,) bool real rows.
        """
        n_messages = int(self.action_space.nvec[0])
        speaking = mask & (action_masks[:, :n_messages].sum(dim=1) > 1)            # (n,)
        if not bool(speaking.any()):
            return action_masks.new_zeros((), dtype=th.float32)
        head = distribution.distributions[0]
        probs = head.probs[speaking]                                               # (k, n_symbols)
        mean = probs.mean(dim=0)                                                   # (n_symbols,)
        mean_entropy = -(mean * th.log(mean.clamp_min(1e-12))).sum()
        return mean_entropy - head.entropy()[speaking].mean()

    def listening(self, distribution, data, mask: th.Tensor) -> th.Tensor:
        """The positive-listening term of a minibatch: mean L1 distance between each listening
        row's move distribution and the one the policy gives with the received symbols removed
        (computed without gradient, from the same LSTM states), 0 if no row listens.

        A row listens when it is real, in a move phase, has received a symbol (a -1 on one of
        the others' symbol planes) and has more than one legal move.
        """
        layout = self.observation_layout()
        symbols = layout.symbol_columns()
        obs = data.observations
        planes = obs[:, symbols]                                                   # (n, n_symbols*H*W)
        n_messages = int(self.action_space.nvec[0])
        received = (planes < 0).any(dim=1)
        choice = data.action_masks[:, n_messages:].sum(dim=1) > 1
        move_phase = obs[:, layout.phase_column()] > 0.5
        rows = mask & received & choice & move_phase                               # (n,)
        if not bool(rows.any()):
            return obs.new_zeros(())
        # read before the second pass: SB3's policy keeps one distribution object and refills it
        heard = distribution.distributions[1].probs[rows]                          # (k, 5)
        silent = obs.clone()
        silent[:, symbols] = planes.clamp_min(0.0)                                 # own symbol kept
        with th.no_grad():
            unheard, _ = self.policy.get_distribution(silent, data.lstm_states.pi, data.episode_starts,
                                                      data.action_masks)
            unheard_probs = unheard.distributions[1].probs[rows]                   # (k, 5)
        return (heard - unheard_probs).abs().sum(dim=1).mean()

    def predict(self, observation, state=None, episode_start=None, deterministic: bool = False, action_masks=None):
        """Actions and the next LSTM state; ``action_masks`` (n, 21) restricts the choice.

        Args:
            observation: (n, obs_dim) rows.
            state: LSTM state returned by the previous call (None at the start).
            episode_start: (n,) bool, True where an episode starts.
            deterministic: most likely legal action instead of a sample.
            action_masks: (n, sum(nvec)) legal actions, or None (unmasked).
        """
        return self.policy.predict(observation, state, episode_start, deterministic, action_masks=action_masks)

    @classmethod
    def load(cls, path, env=None, device="auto", custom_objects=None, print_system_info: bool = False,
             force_reset: bool = True, **kwargs):
        """SB3's ``load`` of a saved algorithm, and also of a zoo ``model.zip`` (a policy only, no
        optimizer): then the algorithm is built around the policy (on ``env`` if given, else on
        a stand-in env of the policy's spaces), so that ``predict(obs, state, episode_start,
        action_masks=...)`` works as for any SB3 model; to train further, pass ``env``.

        Args:
            path: an algorithm zip (``model.save``) or a policy zip (``policy.save``, the zoo's).
            env: the vec env to attach (e.g. ``patrolsb3.sb3.make_vec_env``), or None.
            device, custom_objects, print_system_info, force_reset, **kwargs: as SB3's ``load``.
        """
        import zipfile
        with zipfile.ZipFile(path) as archive:
            policy_only = "data" not in archive.namelist()
        if not policy_only:
            return super().load(path, env=env, device=device, custom_objects=custom_objects,
                                print_system_info=print_system_info, force_reset=force_reset, **kwargs)
        import gymnasium as gym
        from stable_baselines3.common.vec_env import DummyVecEnv
        policy = PatrolRecurrentPolicy.load(str(path), device=device)
        params = policy._get_constructor_parameters()
        spaces = {"observation_space": params.pop("observation_space"), "action_space": params.pop("action_space")}
        for key in ("lr_schedule", "use_sde", "squash_output", "full_std", "use_expln"):   # the algorithm's
            params.pop(key, None)
        if env is None:
            stand_in = type("PolicySpaces", (gym.Env,), {**spaces, "reset": None, "step": None})
            env = DummyVecEnv([stand_in])
        model = cls(PatrolRecurrentPolicy, env, policy_kwargs=params, device=device, **kwargs)
        model.policy.load_state_dict(policy.state_dict())
        return model

    def learn(self, total_timesteps: int, callback=None, log_interval: int = 1,
              tb_log_name: str = "MaskableRecurrentPPO", reset_num_timesteps: bool = True, progress_bar: bool = False):
        return super().learn(total_timesteps=total_timesteps, callback=callback, log_interval=log_interval,
                             tb_log_name=tb_log_name, reset_num_timesteps=reset_num_timesteps,
                             progress_bar=progress_bar)
