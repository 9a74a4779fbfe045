"""Action masks for any SB3 vector env over the PettingZoo env (e.g. stock SuperSuit's), as
sb3-contrib's MaskablePPO asks for them: :class:`VecActionMasks`."""
from __future__ import annotations

import numpy as np
from stable_baselines3.common.vec_env import VecEnvWrapper
from stable_baselines3.common.vec_env.base_vec_env import VecEnvIndices

MASK_KEY = "action_mask_flat"
"""The info key of the PettingZoo env that holds an agent's (n_symbols + 5,) mask."""


class VecActionMasks(VecEnvWrapper):
    """Keeps the masks of the last reset or step from the rows' infos and answers
    ``action_masks()`` and ``env_method("action_masks")`` (what ``get_action_masks`` calls).

    Args:
        venv: an SB3 vector env whose rows are agents of the PettingZoo env (their infos hold
            ``action_mask_flat``), e.g. SuperSuit's ``concat_vec_envs_v1(...,
            base_class="stable_baselines3")``.
    """

    def __init__(self, venv):
        super().__init__(venv)
        self._masks = None                        # (num_envs, sum(nvec)) bool
        self._seed = None

    def _keep(self, infos) -> None:
        self._masks = np.stack([np.asarray(info[MASK_KEY], dtype=bool) for info in infos])

    def seed(self, seed: int | None = None) -> list:
        """Seed the next reset (SuperSuit's SB3 wrapper has no ``seed`` of its own to forward to)."""
        self._seed = seed
        return [seed] * self.num_envs

    def reset(self):
        if self._seed is not None and hasattr(self.venv, "venv"):   # SuperSuit: the gymnasium-level vec env
            obs, infos = self.venv.venv.reset(seed=self._seed)
            self.venv.reset_infos = infos
            self._seed = None
        else:
            obs = self.venv.reset()
        self._keep(self.venv.reset_infos)
        return obs

    def step_wait(self):
        obs, rewards, dones, infos = self.venv.step_wait()
        self._keep(infos)
        return obs, rewards, dones, infos

    def action_masks(self) -> np.ndarray:
        """(num_envs, n_symbols + 5) bool: message mask then move mask of every row."""
        if self._masks is None:
            raise RuntimeError("VecActionMasks: reset the env before asking for masks")
        return self._masks.copy()

    def env_method(self, method_name: str, *method_args, indices: VecEnvIndices = None, **method_kwargs):
        if method_name == "action_masks":
            return [row for row in self.action_masks()[list(self._get_indices(indices))]]
        return self.venv.env_method(method_name, *method_args, indices=indices, **method_kwargs)

    def has_attr(self, attr_name: str) -> bool:
        return attr_name == "action_masks" or self.venv.has_attr(attr_name)
