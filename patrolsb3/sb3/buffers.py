"""sb3-contrib's RecurrentRolloutBuffer that also stores the action masks of every step
(what MaskableRolloutBuffer adds to RolloutBuffer), padded into the same sequences, and
trains on deployed rows only.

Rows of slots that their episode does not deploy (a team smaller than ``max_agents``) stay in
the buffer, since SB3 fixes ``n_envs``, but never reach a minibatch: when the buffer is
prepared, every field is cut down to the deployed steps (in env-major order, as
sb3-contrib flattens them), and a sequence boundary is put wherever that cut joins two
stretches that were not consecutive. Sequences are then built and padded exactly as
sb3-contrib does; the advantage normalisation of each minibatch therefore sees deployed rows
only.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np
import torch as th
from gymnasium import spaces
from sb3_contrib.common.recurrent.buffers import RecurrentRolloutBuffer
from sb3_contrib.common.recurrent.type_aliases import RNNStates


class MaskableRecurrentRolloutBufferSamples(NamedTuple):
    """A padded minibatch: RecurrentRolloutBufferSamples plus ``action_masks``."""

    observations: th.Tensor    # (n_seq * max_len, obs_dim)
    actions: th.Tensor         # (n_seq * max_len, 2)
    old_values: th.Tensor      # (n_seq * max_len,)
    old_log_prob: th.Tensor    # (n_seq * max_len,)
    advantages: th.Tensor      # (n_seq * max_len,)
    returns: th.Tensor         # (n_seq * max_len,)
    lstm_states: RNNStates     # pi and vf: (hidden, cell) each (layers, n_seq, hidden)
    episode_starts: th.Tensor  # (n_seq * max_len,)
    mask: th.Tensor            # (n_seq * max_len,) 1 on real steps, 0 on sequence padding
    action_masks: th.Tensor    # (n_seq * max_len, sum(nvec)) 1 = legal; padding is all-legal


def mask_dims(action_space: spaces.Space) -> int:
    """Length of a flat action mask for a Discrete or MultiDiscrete space."""
    if isinstance(action_space, spaces.Discrete):
        return int(action_space.n)
    if isinstance(action_space, spaces.MultiDiscrete):
        return int(np.sum(action_space.nvec))
    raise ValueError(f"action masks need a Discrete or MultiDiscrete action space, got {action_space}")


_FLAT_FIELDS = ("observations", "actions", "values", "log_probs", "advantages", "returns",
                "hidden_states_pi", "cell_states_pi", "hidden_states_vf", "cell_states_vf",
                "episode_starts", "action_masks", "deployed")
_LSTM_FIELDS = ("hidden_states_pi", "cell_states_pi", "hidden_states_vf", "cell_states_vf")


def sequence_breaks(kept: np.ndarray, n_steps: int) -> np.ndarray:
    """Where a new sequence must start among kept env-major rows.

    Args:
        kept: (K,) increasing indices into the env-major flattening (env * n_steps + step).
        n_steps: steps per env in the buffer.

    Returns:
        (K,) float32, 1 where row j starts another env's data or follows a gap, else 0.
    """
    breaks = np.ones(len(kept), dtype=np.float32)
    if len(kept) > 1:
        breaks[1:] = (kept[1:] != kept[:-1] + 1) | (kept[1:] % n_steps == 0)
    return breaks


def team_gap(rewards: np.ndarray, deployed: np.ndarray, episode_of_rows: np.ndarray) -> np.ndarray:
    """(n_envs,) each deployed row's team mean reward minus its own, for one env step.

    Args:
        rewards: (n_envs,) this step's rewards.
        deployed: (n_envs,) bool rows that act (padded slots: gap 0, not in any mean).
        episode_of_rows: (n_envs,) int the parallel episode of each row (its team).
    """
    n = int(episode_of_rows.max()) + 1
    weight = deployed.astype(np.float64)                                        # (n_envs,)
    total = np.bincount(episode_of_rows, weights=rewards * weight, minlength=n)  # (n,)
    count = np.bincount(episode_of_rows, weights=weight, minlength=n)            # (n,)
    mean = total / np.maximum(count, 1.0)
    return np.where(deployed, mean[episode_of_rows] - rewards, 0.0)


def discounted_gaps(gaps: np.ndarray, episode_starts: np.ndarray, last_dones: np.ndarray,
                    discount: float) -> np.ndarray:
    """(n_steps, n_envs) G_t = gap_t + discount * G_{t+1} within each episode, 0 past the
    rollout: what the team's reward adds to a row's GAE advantage (discount = gamma * lambda)
    when its own reward is replaced by the team mean.

    Args:
        gaps: (n_steps, n_envs) team mean minus own reward of every step.
        episode_starts: (n_steps, n_envs) 1 where a row's episode starts at that step.
        last_dones: (n_envs,) episodes that ended at the rollout's last step.
        discount: gamma * gae_lambda.
    """
    out = np.zeros_like(gaps, dtype=np.float64)
    following = np.zeros(gaps.shape[1])
    for t in reversed(range(len(gaps))):
        cut = last_dones if t == len(gaps) - 1 else episode_starts[t + 1]
        following = gaps[t] + discount * (1.0 - cut) * following
        out[t] = following
    return out


class MaskableRecurrentRolloutBuffer(RecurrentRolloutBuffer):
    """Recurrent rollout buffer with action masks and deployed-row flags (module docstring).

    While filling: ``action_masks`` (n_steps, n_envs, mask_dims) float32 and ``deployed``
    (n_steps, n_envs) bool. Once prepared by :meth:`get`: every field flattened env-major and
    cut to the deployed rows, ``n_rows`` of them, with ``env_change`` (n_rows, 1) the sequence
    breaks.
    """

    def reset(self) -> None:
        self.mask_dims = mask_dims(self.action_space)
        self.action_masks = np.ones((self.buffer_size, self.n_envs, self.mask_dims), dtype=np.float32)
        self.deployed = np.ones((self.buffer_size, self.n_envs), dtype=bool)
        self.team_gaps = np.zeros((self.buffer_size, self.n_envs), dtype=np.float32)   # team mean - own reward
        self.n_rows = self.buffer_size * self.n_envs
        self.env_change = None
        super().reset()

    def add(self, *args, action_masks: np.ndarray | None = None, deployed: np.ndarray | None = None,
            team_gaps: np.ndarray | None = None, **kwargs) -> None:
        """RecurrentRolloutBuffer.add plus the (n_envs, mask_dims) masks of this step, the
        (n_envs,) flags of the rows that are deployed (None: all) and, for a team share of the
        reward, the (n_envs,) team-mean-minus-own rewards of this step (:func:`team_gap`)."""
        if team_gaps is not None:
            self.team_gaps[self.pos] = team_gaps
        if action_masks is not None:
            self.action_masks[self.pos] = np.asarray(action_masks).reshape((self.n_envs, self.mask_dims))
        self.deployed[self.pos] = True if deployed is None else np.asarray(deployed, dtype=bool)
        super().add(*args, **kwargs)

    def share_team_reward(self, share: float, n_symbols: int, last_dones: np.ndarray) -> None:
        """Give message rows a ``share`` of the team's reward: once the GAE advantages are
        computed, add ``share * G`` (:func:`discounted_gaps` of the stored team gaps) to the
        advantage of every deployed row whose message head has a choice. Their returns (the
        critic's targets) and every other row stay as they were; the critic is the agent's own."""
        speaking = self.deployed & (self.action_masks[..., :n_symbols].sum(axis=-1) > 1)   # (n_steps, n_envs)
        gaps = discounted_gaps(self.team_gaps, self.episode_starts, np.asarray(last_dones, dtype=np.float64),
                               self.gamma * self.gae_lambda)
        self.advantages = np.where(speaking, self.advantages + share * gaps, self.advantages).astype(np.float32)

    def prepare(self) -> None:
        """Flatten every field env-major and keep the deployed rows only (once per rollout)."""
        if self.generator_ready:
            return
        for name in _LSTM_FIELDS:   # (n_steps, layers, n_envs, hidden) -> (n_steps, n_envs, layers, hidden)
            self.__dict__[name] = self.__dict__[name].swapaxes(1, 2)
        for name in _FLAT_FIELDS:
            self.__dict__[name] = self.swap_and_flatten(self.__dict__[name])
        kept = np.flatnonzero(self.deployed.reshape(-1))                    # (n_rows,)
        if len(kept) < len(self.deployed):
            for name in _FLAT_FIELDS:
                self.__dict__[name] = self.__dict__[name][kept]
        self.n_rows = len(kept)
        self.env_change = sequence_breaks(kept, self.buffer_size)[:, None]   # (n_rows, 1) like the fields
        self.generator_ready = True

    def get(self, batch_size: int | None = None):
        """Minibatches of about ``batch_size`` deployed rows (all of them when None), in
        sb3-contrib's order: the rows from a random split point on, then the rest."""
        assert self.full, "Rollout buffer must be full before sampling from it"
        self.prepare()
        n = self.n_rows
        batch_size = n if batch_size is None else int(batch_size)
        split_index = np.random.randint(n)
        indices = np.concatenate((np.arange(split_index, n), np.arange(split_index)))
        for start in range(0, n, batch_size):
            yield self._get_samples(indices[start:start + batch_size], self.env_change)

    def _get_samples(self, batch_inds: np.ndarray, env_change: np.ndarray, env=None) -> MaskableRecurrentRolloutBufferSamples:
        samples = super()._get_samples(batch_inds, env_change, env)
        masks = self.pad(self.action_masks[batch_inds], padding_value=1.0)       # (n_seq, max_len, mask_dims)
        return MaskableRecurrentRolloutBufferSamples(*samples, action_masks=masks.reshape(-1, self.mask_dims))
