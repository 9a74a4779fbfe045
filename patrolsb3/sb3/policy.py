"""The paper's actor and critic networks as SB3 policies (docs/model.md, section 7).

Observation rows of :func:`patrolsb3.sb3.make_vec_env` are flat vectors
``[grid (2, H, W) flattened, vector (15), critic (3 * max_agents)]``. Each network is

    Conv(2->4, 3x3) tanh -> Conv(4->8, 3x3) tanh -> flatten (8 x (H-4) x (W-4))
    -> concat vector (actor) or vector + critic state (critic)
    -> Dense 512 -> 341 -> 227 (tanh)                 [:class:`PatrolFeaturesExtractor`]
    -> LSTM (``lstm_hidden_size``, actor; the critic's is optional)
    -> heads: message (16) + move (5) logits as one masked MultiDiscrete distribution, value (1)

Actor and critic never share weights (``share_features_extractor=False``): the actor's
extractor reads only grid + vector, the critic's reads the whole row (centralised critic).
The Dense stack is the projection in front of the LSTM, so the recurrent cell sees 227
features, not the 512 of the convolutions.
"""
from __future__ import annotations

import contextlib
from typing import Any

import numpy as np
import torch as th
from gymnasium import spaces
from sb3_contrib.common.maskable.distributions import make_masked_proba_distribution
from sb3_contrib.common.maskable.policies import MaskableActorCriticPolicy
from sb3_contrib.common.recurrent.policies import RecurrentActorCriticPolicy
from sb3_contrib.common.recurrent.type_aliases import RNNStates
from stable_baselines3.common.policies import BasePolicy
from stable_baselines3.common.torch_layers import BaseFeaturesExtractor
from torch import nn

from .precision import autocast

ROLES = ("actor", "critic")


def conv_padding(grid_shape: tuple[int, int, int], n_convs: int, kernel_size: int) -> tuple[int, int]:
    """Per-axis padding of the convolutions: 0 (the paper's unpadded convs) when the axis is
    long enough, else 'same' padding so that maps thinner than 1 + n_convs * (k - 1) work."""
    shrink = n_convs * (kernel_size - 1)
    return tuple(0 if size > shrink else kernel_size // 2 for size in grid_shape[1:])


class PatrolFeaturesExtractor(BaseFeaturesExtractor):
    """Conv + Dense trunk of one network (actor or critic) over a flat observation row.

    Args:
        observation_space: Box of the flat rows (2*H*W + vector_size + critic_size,).
        grid_shape: (C, H, W) of the grid part.
        vector_size: length of the vector part.
        critic_size: length of the centralised critic part.
        role: "actor" (grid + vector) or "critic" (grid + vector + critic state).
        conv_channels: output channels of the 3x3 tanh convolutions.
        kernel_size: convolution kernel size.
        dense_sizes: sizes of the tanh Dense layers; the last is ``features_dim``.
    """

    def __init__(self, observation_space: spaces.Box, grid_shape, vector_size: int, critic_size: int,
                 role: str = "actor", conv_channels=(4, 8), kernel_size: int = 3,
                 dense_sizes=(512, 341, 227)):
        if role not in ROLES:
            raise ValueError(f"unknown role {role!r}; known: {ROLES}")
        grid_shape = tuple(int(v) for v in grid_shape)
        grid_size = int(np.prod(grid_shape))
        expected = grid_size + vector_size + critic_size
        if observation_space.shape != (expected,):
            raise ValueError(f"observation space {observation_space.shape} does not match the layout "
                             f"grid {grid_shape} + vector {vector_size} + critic {critic_size} = ({expected},)")
        super().__init__(observation_space, features_dim=int(dense_sizes[-1]))
        self.role = role
        self.grid_shape = grid_shape
        self.grid_size = grid_size
        self.input_size = grid_size + vector_size + (critic_size if role == "critic" else 0)
        padding = conv_padding(grid_shape, len(conv_channels), kernel_size)
        layers, channels = [], grid_shape[0]
        for out in conv_channels:
            layers += [nn.Conv2d(channels, out, kernel_size, padding=padding), nn.Tanh()]
            channels = out
        self.conv = nn.Sequential(*layers, nn.Flatten())
        with th.no_grad():
            conv_out = self.conv(th.zeros(1, *grid_shape)).shape[1]   # 8 x 8 x 8 = 512 on 12 x 12
        dense, width = [], conv_out + self.input_size - grid_size
        for size in dense_sizes:
            dense += [nn.Linear(width, int(size)), nn.Tanh()]
            width = int(size)
        self.dense = nn.Sequential(*dense)

    def forward(self, observations: th.Tensor) -> th.Tensor:
        """(B, obs_dim) rows -> (B, features_dim) features."""
        grid = observations[:, :self.grid_size].reshape(-1, *self.grid_shape)   # (B, C, H, W)
        rest = observations[:, self.grid_size:self.input_size]                   # (B, vector [+ critic])
        return self.dense(th.cat([self.conv(grid), rest], dim=1))


def _policy_kwargs(kwargs: dict, grid_shape, vector_size, critic_size, conv_channels, dense_sizes) -> dict:
    """SB3 policy keyword arguments for the paper's networks: tanh, no extra layers after the
    trunks, the actor's and the critic's own :class:`PatrolFeaturesExtractor`."""
    kwargs = dict(kwargs)
    kwargs.setdefault("activation_fn", nn.Tanh)
    kwargs.setdefault("net_arch", dict(pi=[], vf=[]))
    kwargs["share_features_extractor"] = False
    kwargs["features_extractor_class"] = PatrolFeaturesExtractor
    kwargs["features_extractor_kwargs"] = _extractor_kwargs(grid_shape, vector_size, critic_size,
                                                            conv_channels, dense_sizes)
    return kwargs


def _extractor_kwargs(grid_shape, vector_size, critic_size, conv_channels, dense_sizes) -> dict:
    return dict(grid_shape=tuple(grid_shape), vector_size=int(vector_size), critic_size=int(critic_size),
                conv_channels=tuple(conv_channels), dense_sizes=tuple(dense_sizes))


class _RoleExtractorMixin:
    """SB3's ActorCriticPolicy calls ``make_features_extractor`` twice when the extractor is
    not shared: first for the actor, then for the critic. Give each its role.

    Also the training precision (:mod:`patrolsb3.sb3.precision`): ``precision`` ("fp32" or
    "bf16", set by ``train`` for the run; not saved with the policy, so a loaded policy is
    fp32) is what the trunks compute in during the rollout and the update; ``predict`` is
    always fp32.
    """

    precision = "fp32"

    def trunk_context(self):
        """The context the trunks (convolutions, Dense stack, LSTM) run in."""
        return autocast(self.precision, self.device.type)

    def frozen_weights_scope(self):
        """A context for a stretch where the weights do not change (a rollout's collection):
        bf16 copies of the weights are cast once and kept until it ends, instead of once per
        forward pass (autocast's weight cache lives until the outermost autocast context
        exits; this one is disabled, so nothing else in it changes precision)."""
        if self.precision == "fp32":
            return contextlib.nullcontext()
        return th.autocast(device_type=self.device.type, enabled=False)

    @contextlib.contextmanager
    def full_precision(self):
        """Within it, the trunks compute in fp32 whatever the run's precision (prediction)."""
        saved, self.precision = self.precision, "fp32"
        try:
            yield
        finally:
            self.precision = saved

    def make_features_extractor(self) -> BaseFeaturesExtractor:
        role = "critic" if "pi_features_extractor" in self._modules else "actor"
        return self.features_extractor_class(self.observation_space, role=role, **self.features_extractor_kwargs)

    def _get_action_dist_from_latent(self, latent_pi: th.Tensor):
        return self.action_dist.proba_distribution(action_logits=self.action_net(latent_pi))


MASKED_LOGIT = -1e8
"""What sb3-contrib's masked distributions put in place of a masked logit (HUGE_NEG)."""


def masked_sample(logits: th.Tensor, action_masks, nvec, deterministic: bool = False):
    """Sample a masked MultiDiscrete action and its log-probability from flat logits.

    Args:
        logits: (B, sum(nvec)) unnormalised logits of every dimension, side by side.
        action_masks: (B, sum(nvec)) bool or 0/1, legal values.
        nvec: the MultiDiscrete sizes.
        deterministic: the most likely legal value instead of a sample.

    Returns:
        actions (B, len(nvec)) int64 and log-probs (B,), the sum over dimensions.
    """
    legal = th.as_tensor(action_masks, device=logits.device).bool()
    masked = th.where(legal, logits, th.full_like(logits, MASKED_LOGIT))
    actions, log_probs = [], 0.0
    for part in th.split(masked, [int(n) for n in nvec], dim=1):
        log_p = th.log_softmax(part, dim=1)                                          # (B, n)
        choice = th.argmax(part, dim=1) if deterministic else th.multinomial(log_p.exp(), 1).squeeze(1)
        actions.append(choice)
        log_probs = log_probs + log_p.gather(1, choice[:, None]).squeeze(1)
    return th.stack(actions, dim=1), log_probs


def lstm_step(x: th.Tensor, state: tuple[th.Tensor, th.Tensor], lstm: nn.LSTM):
    """One time step of a one-layer ``nn.LSTM`` with its own weights, written out: the same
    formula (gates i, f, g, o), without the fused kernel's fixed cost, which dominates a
    rollout's single step of a few rows.

    Args:
        x: (n, input_size) inputs.
        state: hidden and cell, each (1, n, hidden_size).

    Returns:
        output (n, hidden_size) and the new (hidden, cell), each (1, n, hidden_size).
    """
    h, c = state[0][0], state[1][0]                                                # (n, hidden)
    gates = (nn.functional.linear(x, lstm.weight_ih_l0, lstm.bias_ih_l0)
             + nn.functional.linear(h, lstm.weight_hh_l0, lstm.bias_hh_l0))        # (n, 4 hidden)
    i, f, g, o = gates.chunk(4, dim=1)
    c = th.sigmoid(f) * c + th.sigmoid(i) * th.tanh(g)
    h = th.sigmoid(o) * th.tanh(c)
    return h, (h.unsqueeze(0), c.unsqueeze(0))


class PatrolRecurrentPolicy(_RoleExtractorMixin, RecurrentActorCriticPolicy):
    """Recurrent, masked, parameter-shared actor-critic of the paper.

    Every method of :class:`RecurrentActorCriticPolicy` that produces a distribution takes
    ``action_masks`` ((B, 21) bool or float) and applies them; without masks it samples from
    the unmasked distribution.

    Args:
        observation_space: flat rows (see :class:`PatrolFeaturesExtractor`).
        action_space: MultiDiscrete([n_symbols, 5]).
        lr_schedule: learning-rate schedule.
        grid_shape: (C, H, W) of the grid part of a row.
        vector_size: length of the actor's vector part.
        critic_size: length of the centralised critic part.
        conv_channels: channels of the two 3x3 tanh convolutions.
        dense_sizes: the tanh Dense stack in front of the LSTM.
        lstm_hidden_size: hidden units of the LSTM.
        enable_critic_lstm: give the critic its own LSTM (default False: the critic state is
            near-Markov, and a feed-forward critic halves the recurrent cost; see bench).
        **kwargs: passed to :class:`RecurrentActorCriticPolicy`.
    """

    def __init__(self, observation_space, action_space, lr_schedule, grid_shape, vector_size: int = 15,
                 critic_size: int = 15, conv_channels=(4, 8), dense_sizes=(512, 341, 227),
                 lstm_hidden_size: int = 128, enable_critic_lstm: bool = False, **kwargs: Any):
        kwargs = _policy_kwargs(kwargs, grid_shape, vector_size, critic_size, conv_channels, dense_sizes)
        super().__init__(observation_space, action_space, lr_schedule, lstm_hidden_size=lstm_hidden_size,
                         enable_critic_lstm=enable_critic_lstm, **kwargs)

    def _build(self, lr_schedule) -> None:
        # SB3 builds the logits layer of its MultiCategorical (Linear(latent, sum(nvec))); the
        # masked distribution reads the same logits.
        super()._build(lr_schedule)
        self.action_dist = make_masked_proba_distribution(self.action_space)

    def _get_constructor_parameters(self) -> dict[str, Any]:
        data = super()._get_constructor_parameters()
        kw = self.features_extractor_kwargs
        data.update(grid_shape=kw["grid_shape"], vector_size=kw["vector_size"], critic_size=kw["critic_size"],
                    conv_channels=kw["conv_channels"], dense_sizes=kw["dense_sizes"],
                    lstm_hidden_size=self.lstm_actor.hidden_size, enable_critic_lstm=self.enable_critic_lstm)
        for key in ("features_extractor_class", "features_extractor_kwargs", "share_features_extractor"):
            data.pop(key, None)
        return data

    @staticmethod
    def _process_sequence(features: th.Tensor, lstm_states: tuple[th.Tensor, th.Tensor],
                          episode_starts: th.Tensor, lstm: nn.LSTM,
                          by_hand: bool = False) -> tuple[th.Tensor, tuple[th.Tensor, th.Tensor]]:
        """LSTM over padded sequences in one call when episodes only start at a sequence's
        first step (always true for RecurrentRolloutBuffer's sequences and for collection);
        otherwise sb3-contrib's step-by-step loop. Same result, far fewer kernel launches.
        ``by_hand``: a single step is computed by :func:`lstm_step` (the rollout's forward;
        ``predict`` keeps the fused kernel, so evaluations reproduce bit for bit)."""
        n_seq = lstm_states[0].shape[1]
        starts = episode_starts.reshape((n_seq, -1))                                   # (n_seq, T)
        if starts.shape[1] > 1 and bool(th.any(starts[:, 1:] != 0)):
            return RecurrentActorCriticPolicy._process_sequence(features, lstm_states, episode_starts, lstm)
        keep = (1.0 - starts[:, 0]).view(1, n_seq, 1)                                  # (1, n_seq, 1)
        if by_hand and starts.shape[1] == 1 and lstm.num_layers == 1:    # one step: the cell by hand
            return lstm_step(features, (keep * lstm_states[0], keep * lstm_states[1]), lstm)
        sequence = features.reshape((n_seq, -1, lstm.input_size)).swapaxes(0, 1)       # (T, n_seq, F)
        output, states = lstm(sequence, (keep * lstm_states[0], keep * lstm_states[1]))
        return th.flatten(output.transpose(0, 1), start_dim=0, end_dim=1), states      # (n_seq*T, hidden)

    def _latents(self, obs: th.Tensor, lstm_states: RNNStates, episode_starts: th.Tensor, by_hand: bool = False):
        """Actor and critic latents (B, hidden) fp32 and the new states (the recurrent half of
        forward); the trunks run in the policy's precision, the latents and states come out fp32."""
        with self.trunk_context():
            pi_features, vf_features = self.extract_features(obs)
            latent_pi, states_pi = self._process_sequence(pi_features, lstm_states.pi, episode_starts,
                                                          self.lstm_actor, by_hand)
            if self.lstm_critic is not None:
                latent_vf, states_vf = self._process_sequence(vf_features, lstm_states.vf, episode_starts,
                                                              self.lstm_critic, by_hand)
            else:
                latent_vf, states_vf = self.critic(vf_features), states_pi
            latent_pi = self.mlp_extractor.forward_actor(latent_pi)
            latent_vf = self.mlp_extractor.forward_critic(latent_vf)
        if self.precision == "fp32":
            return latent_pi, latent_vf, RNNStates(states_pi, states_vf)
        states_pi, states_vf = (tuple(t.float() for t in states_pi), tuple(t.float() for t in states_vf))
        return latent_pi.float(), latent_vf.float(), RNNStates(states_pi, states_vf)

    def _masked_distribution(self, latent_pi: th.Tensor, action_masks):
        distribution = self._get_action_dist_from_latent(latent_pi)
        if action_masks is not None:
            distribution.apply_masking(action_masks)
        return distribution

    def forward(self, obs: th.Tensor, lstm_states: RNNStates, episode_starts: th.Tensor,
                deterministic: bool = False, action_masks=None):
        """Actions (B, 2), values (B, 1), log-probs (B,) and the new LSTM states.

        With masks, the masked MultiCategorical of sb3-contrib is sampled directly from its
        logits (masked logits set to its -1e8, a log-softmax per action dimension): the same
        distribution without building one ``Categorical`` object per dimension per step.
        """
        latent_pi, latent_vf, states = self._latents(obs, lstm_states, episode_starts, by_hand=True)
        if action_masks is None:
            distribution = self._masked_distribution(latent_pi, None)
            actions = distribution.get_actions(deterministic=deterministic)
            log_prob = distribution.log_prob(actions)
        else:
            actions, log_prob = masked_sample(self.action_net(latent_pi), action_masks,
                                              self.action_space.nvec, deterministic)
        return actions.reshape((-1, *self.action_space.shape)), self.value_net(latent_vf), log_prob, states

    def evaluate_actions(self, obs: th.Tensor, actions: th.Tensor, lstm_states: RNNStates,
                         episode_starts: th.Tensor, action_masks=None, per_head: bool = False,
                         with_distribution: bool = False):
        """Values (B, 1), log-probs (B,) and entropies (B,) of the given actions; with
        ``per_head`` the entropies are (B, 2): message head, move head; with
        ``with_distribution`` the masked distribution comes fourth (its ``distributions`` are
        the message and move heads)."""
        latent_pi, latent_vf, _ = self._latents(obs, lstm_states, episode_starts)
        distribution = self._masked_distribution(latent_pi, action_masks)
        entropy = (th.stack([d.entropy() for d in distribution.distributions], dim=1) if per_head
                   else distribution.entropy())
        out = self.value_net(latent_vf), distribution.log_prob(actions), entropy
        return (*out, distribution) if with_distribution else out

    def get_distribution(self, obs: th.Tensor, lstm_states, episode_starts: th.Tensor, action_masks=None):
        """The (masked) action distribution and the actor's new LSTM states."""
        features = BasePolicy.extract_features(self, obs, self.pi_features_extractor)  # actor part only
        latent_pi, lstm_states = self._process_sequence(features, lstm_states, episode_starts, self.lstm_actor)
        latent_pi = self.mlp_extractor.forward_actor(latent_pi)
        return self._masked_distribution(latent_pi, action_masks), lstm_states

    def _predict(self, observation, lstm_states, episode_starts, deterministic: bool = False, action_masks=None):
        distribution, lstm_states = self.get_distribution(observation, lstm_states, episode_starts, action_masks)
        return distribution.get_actions(deterministic=deterministic), lstm_states

    def predict(self, observation: np.ndarray, state=None, episode_start=None, deterministic: bool = False,
                action_masks=None):
        """Actions (n, 2) and the actor's LSTM state ((layers, n, hidden) x 2) for n rows.

        Args:
            observation: (n, obs_dim) rows (or one row).
            state: LSTM (hidden, cell) from the previous call, None at the start.
            episode_start: (n,) bool, True where a new episode starts (state reset).
            deterministic: take the most likely legal action.
            action_masks: (n, 21) legal actions; None samples without masks.
        """
        self.set_training_mode(False)
        with self.full_precision():
            return self._predict_rows(observation, state, episode_start, deterministic, action_masks)

    def _predict_rows(self, observation, state, episode_start, deterministic, action_masks):
        obs_tensor, vectorized = self.obs_to_tensor(observation)
        n_envs = obs_tensor.shape[0]
        if state is None:
            zeros = np.zeros((self.lstm_hidden_state_shape[0], n_envs, self.lstm_hidden_state_shape[2]), np.float32)
            state = (zeros, zeros)
        if episode_start is None:
            episode_start = np.zeros(n_envs, dtype=bool)
        with th.no_grad():
            states = (th.as_tensor(np.asarray(state[0]), dtype=th.float32, device=self.device),
                      th.as_tensor(np.asarray(state[1]), dtype=th.float32, device=self.device))
            starts = th.as_tensor(np.asarray(episode_start), dtype=th.float32, device=self.device)
            masks = None if action_masks is None else th.as_tensor(np.asarray(action_masks), device=self.device)
            actions, states = self._predict(obs_tensor, states, starts, deterministic, masks)
        actions = actions.cpu().numpy().reshape((-1, *self.action_space.shape))
        if not vectorized:
            actions = actions.squeeze(axis=0)
        return actions, (states[0].cpu().numpy(), states[1].cpu().numpy())


class PatrolMaskablePolicy(_RoleExtractorMixin, MaskableActorCriticPolicy):
    """The same Conv + Dense actor and centralised critic without recurrence, for
    sb3-contrib's MaskablePPO.

    Args:
        observation_space: flat rows (see :class:`PatrolFeaturesExtractor`).
        action_space: MultiDiscrete([n_symbols, 5]).
        lr_schedule: learning-rate schedule.
        grid_shape, vector_size, critic_size, conv_channels, dense_sizes: as in
            :class:`PatrolRecurrentPolicy`.
        **kwargs: passed to :class:`MaskableActorCriticPolicy`.
    """

    def __init__(self, observation_space, action_space, lr_schedule, grid_shape, vector_size: int = 15,
                 critic_size: int = 15, conv_channels=(4, 8), dense_sizes=(512, 341, 227), **kwargs: Any):
        kwargs = _policy_kwargs(kwargs, grid_shape, vector_size, critic_size, conv_channels, dense_sizes)
        super().__init__(observation_space, action_space, lr_schedule, **kwargs)

    def extract_features(self, obs, features_extractor=None):
        """SB3's, with the trunks in the policy's precision; the features come out fp32."""
        with self.trunk_context():
            features = super().extract_features(obs, features_extractor)
        if self.precision == "fp32":
            return features
        return tuple(f.float() for f in features) if isinstance(features, tuple) else features.float()

    def predict(self, *args, **kwargs):
        """SB3's ``predict``, always in fp32."""
        with self.full_precision():
            return super().predict(*args, **kwargs)

    def _get_constructor_parameters(self) -> dict[str, Any]:
        data = super()._get_constructor_parameters()
        kw = self.features_extractor_kwargs
        data.update(grid_shape=kw["grid_shape"], vector_size=kw["vector_size"], critic_size=kw["critic_size"],
                    conv_channels=kw["conv_channels"], dense_sizes=kw["dense_sizes"])
        for key in ("features_extractor_class", "features_extractor_kwargs", "share_features_extractor"):
            data.pop(key, None)
        return data


def policy_kwargs_for(layout, **overrides) -> dict:
    """``policy_kwargs`` of our policies from a vec env's
    :class:`~patrolsb3.core.protocol.ObservationLayout` plus overrides."""
    kwargs = dict(grid_shape=tuple(layout.grid_shape), vector_size=int(layout.vector_size),
                  critic_size=int(layout.critic_size))
    kwargs.update(overrides)
    return kwargs
