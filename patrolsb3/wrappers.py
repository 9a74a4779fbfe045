"""PettingZoo wrappers for clients that want flat arrays (stock SuperSuit, SB3, TorchRL).

:class:`FlatObservations` turns each agent's Dict observation into the flat row of
:class:`patrolsb3.core.protocol.ObservationLayout` (the training layout: grid, vector, critic):
a ``Box(-1, 1, (layout.size,), float32)``. With stock SuperSuit and sb3-contrib's MaskablePPO::

    import supersuit as ss
    from sb3_contrib import MaskablePPO
    import patrolsb3
    from patrolsb3.wrappers import FlatObservations
    from patrolsb3.sb3.masks import VecActionMasks

    env = FlatObservations(patrolsb3.parallel_env("A", n_agents=3, max_agents=3, comm="none"))
    venv = ss.concat_vec_envs_v1(ss.pettingzoo_env_to_vec_env_v1(env), 2, base_class="stable_baselines3")
    model = MaskablePPO("MlpPolicy", VecActionMasks(venv)).learn(4096)

SuperSuit's vector env wants every possible agent in every step, so give the env
``max_agents = n_agents`` (the package's own training env pads teams itself:
:mod:`patrolsb3.sb3.batched_env`).
"""
from __future__ import annotations

import functools

import numpy as np
from gymnasium import spaces
from pettingzoo.utils.wrappers import BaseParallelWrapper

from .core.protocol import ObservationLayout


class FlatObservations(BaseParallelWrapper):
    """Each agent's observation as one flat float32 row (module docstring)."""

    def __init__(self, env):
        super().__init__(env)
        base = env.unwrapped
        self.layout = ObservationLayout.of(base.spec_map, base.cfg)
        self._space = spaces.Box(-1.0, 1.0, (self.layout.size,), np.float32)

    @functools.lru_cache(maxsize=None)
    def observation_space(self, agent):
        return self._space

    def _flat(self, observations: dict) -> dict:
        return {a: self.layout.flatten(o["grid"], o["vector"], o["critic"]) for a, o in observations.items()}

    def reset(self, seed=None, options=None):
        observations, infos = self.env.reset(seed=seed, options=options)
        return self._flat(observations), infos

    def step(self, actions):
        observations, rewards, terminations, truncations, infos = self.env.step(actions)
        return self._flat(observations), rewards, terminations, truncations, infos


class FlatMasks(BaseParallelWrapper):
    """Each agent's ``info["action_mask"]`` as one flat (n_symbols + 5,) bool array (message
    mask, then move mask) instead of PettingZoo's tuple for ``MultiDiscrete``: what TorchRL's
    ``PettingZooWrapper(env, use_mask=True)`` reads. ::

        from torchrl.envs import PettingZooWrapper
        env = PettingZooWrapper(env=FlatMasks(patrolsb3.parallel_env("A", n_agents=3, max_agents=3)),
                                use_mask=True, categorical_actions=True)
    """

    @staticmethod
    def _flat(infos: dict) -> dict:
        return {a: {**{k: v for k, v in info.items() if k != "action_mask_flat"},
                    "action_mask": np.asarray(info["action_mask_flat"], dtype=bool)} for a, info in infos.items()}

    def reset(self, seed=None, options=None):
        observations, infos = self.env.reset(seed=seed, options=options)
        return observations, self._flat(infos)

    def step(self, actions):
        observations, rewards, terminations, truncations, infos = self.env.step(actions)
        return observations, rewards, terminations, truncations, self._flat(infos)
