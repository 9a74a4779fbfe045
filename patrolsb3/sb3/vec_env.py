"""Parameter sharing for SB3: every agent slot of every parallel episode is one row of an SB3
``VecEnv``, built with SuperSuit over one batched simulator and completed where SuperSuit 3.11
falls short of SB3.

Stack (outside in)::

    PatrolVecEnv                      this module: masks, seeding, team sizes, truncation flags
      SB3VecEnvWrapper                supersuit concat_vec_envs_v1(base_class="stable_baselines3")
        ConcatVecEnv                  one sub-env
          MarkovVectorEnv             supersuit pettingzoo_env_to_vec_env_v1: one row per agent
            BatchedPatrolEnv          patrolsb3.sb3.batched_env: the slots of all parallel
                                      episodes as the agents of one PettingZoo ParallelEnv,
                                      one batched simulator call per step

Why this shape: SuperSuit stays the flattening layer (a PettingZoo env in, a shared-policy
vector env out), but the simulator underneath steps every parallel episode in one call: 8
one-episode envs cost 8 calls and 8 sets of observations per step, one batched env costs
about one. The agent protocol (phases, masks, flat layout) is :mod:`patrolsb3.core.protocol`,
the same as in the PettingZoo env and the zoo policy.

Gaps of SuperSuit closed here:

* ``env_method`` / ``has_attr`` / ``get_attr`` / ``seed`` are not forwarded by SuperSuit's SB3
  wrapper; :class:`PatrolVecEnv` implements them (``env_method("action_masks")`` gives the
  masks sb3-contrib's ``get_action_masks`` needs).
* SuperSuit's SB3 wrapper joins termination and truncation into ``dones``; we read both from
  the gymnasium-level ``ConcatVecEnv`` and set ``TimeLimit.truncated`` so SB3 bootstraps the
  value at the horizon.
* ``black_death_v3`` is not used: slots never leave the env (inactive and padded slots have
  the single legal action (0, Stay) and reward 0).

Padded slots (a team smaller than ``max_agents``) keep their rows, since SB3 fixes
``num_envs``; :meth:`PatrolVecEnv.deployed_rows` says which rows act, so that
:class:`~patrolsb3.sb3.maskable_recurrent_ppo.MaskableRecurrentPPO` neither runs the policy
on the others nor trains on them.

Discount with two phases: with same-step messages (comm 'learned' or 'intention') one
simulator step is two env steps (message phase, then move phase), and the message phase's
reward is 0. ``PatrolVecEnv.phases_per_step`` says how many; a trainer should use
``gamma ** (1 / phases_per_step)`` per env step so that the discount per simulator step stays
the paper's 0.95.
"""
from __future__ import annotations

from typing import Any, Sequence

import numpy as np
import supersuit as ss
from stable_baselines3.common.vec_env import VecEnvWrapper
from stable_baselines3.common.vec_env.base_vec_env import VecEnvIndices

from ..core import protocol
from ..core.config import EnvConfig, make_config
from ..core.maps import load_map
from .batched_env import BatchedPatrolEnv
from .variants import variant_overrides

DEFAULT_AGENTS = (1, 1, 1, 1, 2, 3, 4, 5)
"""Team size of each parallel episode: the last stage of the paper's curriculum."""

MASK_METHOD = "action_masks"
"""Name sb3-contrib's ``get_action_masks`` / ``is_masking_supported`` look for."""


class PatrolVecEnv(VecEnvWrapper):
    """SB3 ``VecEnv`` with one row per agent slot of every parallel episode.

    Row ``k`` is slot ``k % max_agents`` of episode ``k // max_agents``; one shared policy
    acts for all rows (parameter sharing).

    Observation: Box(-1, 1, (layout.size,), float32) in the flat layout of
    :class:`patrolsb3.core.protocol.ObservationLayout` ([grid (2, H, W) in C order, vector,
    critic (3 * max_agents)]); the critic part is the centralised state; actors must not read it.

    Action: MultiDiscrete([n_symbols, 5]) = (message, move). :meth:`action_masks` gives
    (num_envs, n_symbols + 5) bool, message mask then move mask.

    Infos at an episode's last step (every row of it): ``terminal_observation`` (flat),
    ``TimeLimit.truncated`` (cut by the horizon, not terminated), ``episode`` ({"r": the
    slot's return, "l": env steps}) and ``team_episode`` (the team's summary: reward,
    n_agents, mean_idleness, max_idleness, collisions, battery_failures, sim_steps).

    Attributes:
        layout: the :class:`~patrolsb3.core.protocol.ObservationLayout` of the rows.
        phases_per_step: env steps per simulator step (2 with same-step messages, else 1);
            discount per env step = gamma ** (1 / phases_per_step), gamma per simulator step.
        max_agents: slots per parallel episode.
        n_episodes: parallel episodes (``num_envs // max_agents``).
        episodes: the :class:`~patrolsb3.sb3.batched_env.BatchedPatrolEnv` underneath.
    """

    def __init__(self, venv):
        """Wrap SuperSuit's SB3 vector env (from ``concat_vec_envs_v1``).

        Args:
            venv: ``SB3VecEnvWrapper`` over a ``ConcatVecEnv`` of one ``MarkovVectorEnv`` over
                a :class:`~patrolsb3.sb3.batched_env.BatchedPatrolEnv`.
        """
        self._concat = venv.venv                                     # ConcatVecEnv
        self.episodes = self._concat.vec_envs[0].par_env             # BatchedPatrolEnv
        self.layout = self.episodes.layout
        self.max_agents = self.episodes.max_agents
        self.n_episodes = self.episodes.n_episodes
        super().__init__(venv, observation_space=venv.observation_space, action_space=venv.action_space)
        self.phases_per_step = protocol.phases_per_step(self.episodes.cfg)
        self._pending_seed = None

    # ------------------------------------------------------------------ episodes of the rows
    def episode_config(self, i: int) -> EnvConfig:
        """The settings of parallel episode ``i`` (rows i*max_agents .. +max_agents-1)."""
        return self.episodes.configs[i]

    def set_agents(self, agents: Sequence[int]) -> None:
        """Team size of each parallel episode, effective from its next reset.

        Args:
            agents: one team size per parallel episode (length ``n_episodes``).

        Raises:
            ValueError: wrong length, or a team size the env refuses (below 1, above
                max_agents or above the map's vertex count).
        """
        self.episodes.set_teams(agents)

    def get_agents(self) -> list[int]:
        """Team sizes scheduled for the parallel episodes (used from their next reset)."""
        return [int(k) for k in self.episodes.teams]

    def running_agents(self) -> list[int]:
        """Team sizes of the running episodes."""
        return [int(k) for k in self.episodes.running]

    def deployed_rows(self) -> np.ndarray:
        """(num_envs,) bool: rows of deployed slots (the others are padding and never act)."""
        return self.episodes.deployed_rows()

    def episode_of_rows(self) -> np.ndarray:
        """(num_envs,) int64: the parallel episode (team) of each row."""
        return np.arange(self.num_envs, dtype=np.int64) // self.max_agents

    def action_masks(self) -> np.ndarray:
        """(num_envs, n_symbols + 5) bool: message mask then move mask of every row, for the
        current phase."""
        return self.episodes.masks.copy()

    # ------------------------------------------------------------------ VecEnv API
    def seed(self, seed: int | None = None) -> list[int | None]:
        """Seed the next reset (the generator every parallel episode draws from)."""
        self._pending_seed = None if seed is None else int(seed)
        return [self._pending_seed] * self.num_envs

    def reset(self) -> np.ndarray:
        """Reset every parallel episode; (num_envs, obs_size) float32."""
        obs, infos = self._concat.reset(seed=self._pending_seed)
        self._pending_seed = None
        self.reset_infos = infos
        return obs

    def step_wait(self):
        """Step every row; SB3's (obs, rewards, dones, infos)."""
        obs, rewards, terminations, truncations, infos = self._concat.step_wait()
        terminations = np.asarray(terminations, dtype=bool)   # (N,)
        truncations = np.asarray(truncations, dtype=bool)     # (N,)
        dones = terminations | truncations                    # (N,)
        for k in np.flatnonzero(dones):
            infos[k]["TimeLimit.truncated"] = bool(truncations[k] and not terminations[k])
        return obs, np.asarray(rewards, dtype=np.float32), dones, infos

    def set_options(self, options=None) -> None:
        """Reset options are not forwarded by SuperSuit; team sizes go through set_agents.

        Raises:
            NotImplementedError: any options given.
        """
        if options:
            raise NotImplementedError(f"PatrolVecEnv takes no reset options ({options!r}); change "
                                      f"team sizes with set_agents([...]) and seeds with seed(s)")

    def has_attr(self, attr_name: str) -> bool:
        """True for ``action_masks`` and for attributes of the batched env."""
        return attr_name == MASK_METHOD or hasattr(self.episodes, attr_name)

    def get_attr(self, attr_name: str, indices: VecEnvIndices = None) -> list[Any]:
        """Per row: ``n_agents`` (its episode's running team), ``cfg`` (its episode's settings),
        else the batched env's attribute."""
        rows = list(self._get_indices(indices))
        if attr_name == "n_agents":
            return [int(self.episodes.running[k // self.max_agents]) for k in rows]
        if attr_name == "cfg":
            return [self.episode_config(k // self.max_agents) for k in rows]
        return [getattr(self.episodes, attr_name) for _ in rows]

    def set_attr(self, attr_name: str, value: Any, indices: VecEnvIndices = None) -> None:
        """Set an attribute of the batched env (shared by every row)."""
        setattr(self.episodes, attr_name, value)

    def env_method(self, method_name: str, *method_args, indices: VecEnvIndices = None,
                   **method_kwargs) -> list[Any]:
        """``action_masks``: each row's (n_symbols + 5,) bool mask; any other name is called on
        the batched env, once per row asked."""
        rows = list(self._get_indices(indices))
        if method_name == MASK_METHOD:
            masks = self.episodes.masks
            return [masks[k].copy() for k in rows]
        return [getattr(self.episodes, method_name)(*method_args, **method_kwargs) for _ in rows]

    def env_is_wrapped(self, wrapper_class, indices: VecEnvIndices = None) -> list[bool]:
        """No row is wrapped by a gymnasium wrapper (a PettingZoo env underneath)."""
        return [False for _ in self._get_indices(indices)]


def training_config(map, variant: str, strict: bool = True, **env_kwargs):
    """The EnvConfig a training vec env runs (:func:`make_vec_env` builds its episodes from it,
    ``train`` records it in config.yml): the map's paper values, the variant's messages, the
    given settings, and ``invalid_action`` "raise" (``strict``, masked algorithms) or "stay".

    Raises:
        TypeError, ValueError: as :func:`make_vec_env`.
    """
    spec = load_map(map)
    config = {**variant_overrides(variant), **env_kwargs, "invalid_action": "raise" if strict else "stay"}
    return make_config(spec.name, **config)


def make_vec_env(map="A", agents: Sequence[int] = DEFAULT_AGENTS, variant: str = "rl-msg",
                 seed: int | None = 0, strict: bool = True, episode_env: dict | None = None,
                 **env_kwargs) -> PatrolVecEnv:
    """Build the parameter-shared SB3 vector env of a training run.

    Args:
        map: shipped map name ("A" .. "D"), a map file path or a MapSpec.
        agents: team size of each parallel episode; ``num_envs = len(agents) * max_agents``.
        variant: a key of :data:`patrolsb3.sb3.VARIANTS` (sets the env's ``comm``).
        seed: seed of the first reset; None for fresh entropy.
        strict: True: a masked action raises in the env; False: masked moves act as Stay
            (``invalid_action="stay"``), for algorithms without masks.
        episode_env: {parallel episode index: EnvConfig overrides} for episodes that run with
            other settings than ``env_kwargs`` (only settings that keep the spaces and phases,
            see :func:`patrolsb3.core.protocol.protocol_signature`), e.g. short low-battery
            episodes beside long ones.
        **env_kwargs: other EnvConfig fields (``episode_steps``, ``message_timing``, ...).

    Returns:
        A :class:`PatrolVecEnv`, seeded but not yet reset.

    Raises:
        ValueError: unknown variant, empty ``agents``, a team size the env refuses, or an
            ``episode_env`` entry for an episode the run does not have or that changes the spaces.
        TypeError: ``comm`` / ``invalid_action`` given directly (use ``variant`` / ``strict``),
            or an unknown EnvConfig field.
    """
    for key, instead in (("comm", "variant"), ("invalid_action", "strict")):
        if key in env_kwargs:
            raise TypeError(f"make_vec_env sets {key!r} from {instead!r}; do not pass it directly")
    agents = [int(k) for k in agents]
    if not agents:
        raise ValueError("agents must list at least one team size (one per parallel episode)")
    spec = load_map(map)
    base = training_config(spec, variant, strict, **env_kwargs)
    configs = [base] * len(agents)
    for i, overrides in (episode_env or {}).items():
        if not 0 <= int(i) < len(agents):
            raise ValueError(f"episode_env: no parallel episode {i} (there are {len(agents)})")
        cfg = make_config(None, **{**base.to_dict(), **overrides})
        if protocol.protocol_signature(cfg) != protocol.protocol_signature(base):
            changed = [k for k in overrides if getattr(cfg, k) != getattr(base, k)]
            raise ValueError(f"episode_env: {', '.join(changed)} would change the spaces or phases "
                             f"of the env; only settings that keep them can differ per episode")
        configs[int(i)] = cfg
    batched = BatchedPatrolEnv(spec, configs, agents)
    markov = ss.pettingzoo_env_to_vec_env_v1(batched)
    venv = ss.concat_vec_envs_v1(markov, 1, num_cpus=0, base_class="stable_baselines3")
    vec_env = PatrolVecEnv(venv)
    vec_env.seed(seed)
    return vec_env
