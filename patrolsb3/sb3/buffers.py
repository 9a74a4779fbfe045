"""sb3-contrib's RecurrentRolloutBuffer that also stores the action masks of every step
(what MaskableRolloutBuffer adds to RolloutBuffer), padded into the same sequences."""
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


class MaskableRecurrentRolloutBuffer(RecurrentRolloutBuffer):
    """Recurrent rollout buffer with action masks (see module docstring).

    ``action_masks``: (n_steps, n_envs, mask_dims) float32 while filling, then flattened
    env-major to (n_envs * n_steps, mask_dims) like every other field.
    """

    def reset(self) -> None:
        self.mask_dims = mask_dims(self.action_space)
        self.action_masks = np.ones((self.buffer_size, self.n_envs, self.mask_dims), dtype=np.float32)
        super().reset()

    def add(self, *args, action_masks: np.ndarray | None = None, **kwargs) -> None:
        """RecurrentRolloutBuffer.add plus the (n_envs, mask_dims) masks of this step."""
        if action_masks is not None:
            self.action_masks[self.pos] = np.asarray(action_masks).reshape((self.n_envs, self.mask_dims))
        super().add(*args, **kwargs)

    def get(self, batch_size: int | None = None):
        if not self.generator_ready:
            self.action_masks = self.swap_and_flatten(self.action_masks)
        yield from super().get(batch_size)

    def _get_samples(self, batch_inds: np.ndarray, env_change: np.ndarray, env=None) -> MaskableRecurrentRolloutBufferSamples:
        samples = super()._get_samples(batch_inds, env_change, env)
        masks = self.pad(self.action_masks[batch_inds], padding_value=1.0)       # (n_seq, max_len, mask_dims)
        return MaskableRecurrentRolloutBufferSamples(*samples, action_masks=masks.reshape(-1, self.mask_dims))
