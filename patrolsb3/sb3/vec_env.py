"""Parameter sharing for SB3: every agent slot of every parallel episode is one row of an SB3
``VecEnv``, built with SuperSuit and completed where SuperSuit 3.11 falls short of SB3.

Stack (outside in)::

    PatrolVecEnv                      this module: flat Box obs, masks, seeding, episode ends
      SB3VecEnvWrapper                supersuit concat_vec_envs_v1(base_class="stable_baselines3")
        ConcatVecEnv                  one MarkovVectorEnv per parallel episode
          MarkovVectorEnv             supersuit pettingzoo_env_to_vec_env_v1: one row per slot
            EpisodeResets             this module: team size and seed of every (auto-)reset
              PatrolParallelEnv       the PettingZoo env

Gaps of SuperSuit closed here:

* ``env_method`` / ``has_attr`` / ``get_attr`` / ``seed`` are not forwarded by SuperSuit's SB3
  wrapper; :class:`PatrolVecEnv` implements them (``env_method("action_masks")`` gives the
  masks sb3-contrib's ``get_action_masks`` needs).
* SuperSuit's SB3 wrapper joins termination and truncation into ``dones``; we read both from
  the gymnasium-level ``ConcatVecEnv`` and set ``TimeLimit.truncated`` so SB3 bootstraps the
  value at the horizon. ``terminal_observation`` is flattened like the observations.
* ``black_death_v3`` is not used: slots never leave the env (inactive slots have the single
  legal action (0, Stay) and reward 0), and it rejects Dict observations.
* Unseeded auto-resets would draw fresh entropy; :class:`EpisodeResets` draws each episode's
  seed from a generator seeded at the seeded reset, so a seeded run is reproducible.

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
from gymnasium import spaces
from pettingzoo.utils.wrappers import BaseParallelWrapper
from stable_baselines3.common.vec_env import VecEnvWrapper
from stable_baselines3.common.vec_env.base_vec_env import VecEnvIndices

from ..env import PatrolParallelEnv
from .variants import variant_overrides

DEFAULT_AGENTS = (1, 1, 1, 1, 2, 3, 4, 5)
"""Team size of each parallel episode: the last stage of the paper's curriculum."""

MASK_METHOD = "action_masks"
"""Name sb3-contrib's ``get_action_masks`` / ``is_masking_supported`` look for."""


class EpisodeResets(BaseParallelWrapper):
    """Gives every reset of the wrapped env a team size and, once seeded, a seed.

    SuperSuit's vector envs auto-reset without seed or options; this wrapper supplies both:
    ``n_agents`` (changed by :meth:`PatrolVecEnv.set_agents`, effective at the next reset) and a
    seed drawn from a generator seeded by the last seeded reset.
    """

    def __init__(self, env: PatrolParallelEnv, n_agents: int):
        super().__init__(env)
        self.n_agents = int(n_agents)
        self._seed_rng = None  # np.random.Generator, set by a seeded reset

    def reset(self, seed=None, options=None):
        """Reset with ``options["n_agents"]`` defaulting to ``self.n_agents``."""
        if seed is not None:
            self._seed_rng = np.random.default_rng(seed)
        elif self._seed_rng is not None:
            seed = int(self._seed_rng.integers(2 ** 31 - 1))
        options = dict(options or {})
        options.setdefault("n_agents", self.n_agents)
        return self.env.reset(seed=seed, options=options)


def flatten_observation(obs: dict) -> np.ndarray:
    """Flatten Dict observations to the vector layout [grid, vector, critic].

    Args:
        obs: {"grid": (..., 2, H, W), "vector": (..., 15), "critic": (..., 3 * max_agents)},
            with any number of leading batch axes (none for one agent's observation).

    Returns:
        (..., 2*H*W + 15 + 3*max_agents) float32.
    """
    batch = obs["vector"].shape[:-1]
    return np.concatenate([obs["grid"].reshape(*batch, -1), obs["vector"], obs["critic"]],
                          axis=-1).astype(np.float32)


def mask_row(action_mask: tuple) -> np.ndarray:
    """One slot's (message (n_symbols,), move (5,)) int8 masks as a (n_symbols + 5,) bool row."""
    return np.concatenate(action_mask).astype(bool)


class PatrolVecEnv(VecEnvWrapper):
    """SB3 ``VecEnv`` with one row per agent slot of every parallel episode.

    Row ``k`` is slot ``k % max_agents`` of episode ``k // max_agents``; one shared policy
    acts for all rows (parameter sharing).

    Observation: Box(-1, 1, (2*H*W + 15 + 3*max_agents,), float32), the env's Dict observation
    flattened as [grid (2, H, W) in C order, vector (15), critic (3*max_agents)]; see
    :attr:`layout`. The critic part is the centralised state; actors must not read it.

    Action: MultiDiscrete([n_symbols, 5]) = (message, move). :meth:`action_masks` gives
    (num_envs, n_symbols + 5) bool, message mask then move mask, from the env's infos.

    Infos at an episode's last step (every row of it): ``terminal_observation`` (flat),
    ``TimeLimit.truncated`` (cut by the horizon, not terminated), ``episode`` ({"r": the
    slot's return, "l": env steps}) and ``team_episode`` (see :meth:`_team_summary`).

    Attributes:
        layout: {"grid_shape": (2, H, W), "vector_size": 15, "critic_size": 3 * max_agents}.
        phases_per_step: env steps per simulator step (2 with same-step messages, else 1);
            discount per env step = gamma ** (1 / phases_per_step), gamma per simulator step.
        max_agents: slots per parallel episode.
        n_episodes: parallel episodes (``num_envs // max_agents``).
    """

    def __init__(self, venv):
        """Wrap SuperSuit's SB3 vector env (from ``concat_vec_envs_v1``).

        Args:
            venv: ``SB3VecEnvWrapper`` over a ``ConcatVecEnv`` of ``MarkovVectorEnv`` over
                :class:`EpisodeResets`.
        """
        self._concat = venv.venv                                     # ConcatVecEnv
        self._resets = [v.par_env for v in self._concat.vec_envs]    # EpisodeResets per episode
        env = self._resets[0].unwrapped
        self.max_agents = env.cfg.max_agents
        self.n_episodes = len(self._resets)
        H, W = env.spec_map.shape
        self.layout = {"grid_shape": (2, H, W), "vector_size": venv.observation_space["vector"].shape[0],
                       "critic_size": venv.observation_space["critic"].shape[0]}
        size = 2 * H * W + self.layout["vector_size"] + self.layout["critic_size"]
        observation_space = spaces.Box(-1.0, 1.0, (size,), np.float32)
        super().__init__(venv, observation_space=observation_space, action_space=venv.action_space)
        # discount: same-step messages make two env steps per simulator step (module docstring)
        self.phases_per_step = 2 if env._two_phase else 1
        n_mask = int(np.sum(self.action_space.nvec))
        N, E = self.num_envs, self.n_episodes
        self._masks = np.zeros((N, n_mask), dtype=bool)   # (N, n_symbols + 5) from the last infos
        self._pending_seed = None
        self._returns = np.zeros(N, dtype=np.float64)     # (N,) return of each row's episode so far
        self._lengths = np.zeros(N, dtype=np.int64)       # (N,) env steps of each row's episode
        self._team = np.array([r.n_agents for r in self._resets], dtype=np.int64)  # (E,) deployed
        self._sim_steps = np.zeros(E, dtype=np.int64)     # (E,) simulator steps so far
        self._idle_sum = np.zeros(E, dtype=np.float64)    # (E,) sum over sim steps of mean idleness
        self._idle_max = np.zeros(E, dtype=np.float64)    # (E,) worst instantaneous max idleness
        self._collisions = np.zeros(E, dtype=np.int64)    # (E,) collision events
        self._failures = np.zeros(E, dtype=np.int64)      # (E,) battery failures

    # ------------------------------------------------------------------ episodes of the rows
    def get_env(self, i: int) -> PatrolParallelEnv:
        """The PettingZoo env of parallel episode ``i`` (rows i*max_agents .. +max_agents-1)."""
        return self._resets[i].unwrapped

    def set_agents(self, agents: Sequence[int]) -> None:
        """Team size of each parallel episode, effective from its next reset.

        Args:
            agents: one team size per parallel episode (length ``n_episodes``).

        Raises:
            ValueError: wrong length, or a team size the env refuses (below 1, above
                max_agents or above the map's vertex count).
        """
        agents = [int(k) for k in agents]
        if len(agents) != self.n_episodes:
            raise ValueError(f"set_agents needs {self.n_episodes} team sizes (one per parallel "
                             f"episode), got {len(agents)}: {agents}")
        for i, k in enumerate(agents):
            self.get_env(i)._check_team(k)  # the env's own rule for a valid team
        for resets, k in zip(self._resets, agents):
            resets.n_agents = k

    def get_agents(self) -> list[int]:
        """Team sizes scheduled for the parallel episodes (used from their next reset)."""
        return [r.n_agents for r in self._resets]

    def action_masks(self) -> np.ndarray:
        """(num_envs, n_symbols + 5) bool: message mask then move mask of every row, from the
        infos of the last reset or step."""
        return self._masks.copy()

    # ------------------------------------------------------------------ VecEnv API
    def seed(self, seed: int | None = None) -> list[int | None]:
        """Seed the next reset: episode ``i`` gets ``seed + i``, its later episodes seeds drawn
        from a generator seeded with it. Returns the seed of each row."""
        self._pending_seed = None if seed is None else int(seed)
        if seed is None:
            return [None] * self.num_envs
        return [int(seed) + k // self.max_agents for k in range(self.num_envs)]

    def reset(self) -> np.ndarray:
        """Reset every parallel episode; (num_envs, obs_size) float32."""
        obs, infos = self._concat.reset(seed=self._pending_seed)
        self._pending_seed = None
        self._returns[:] = 0.0
        self._lengths[:] = 0
        for e in range(self.n_episodes):
            self._start_episode(e)
        self.reset_infos = infos
        self._update_masks(infos)
        return flatten_observation(obs)

    def step_wait(self):
        """Step every row; SB3's (obs, rewards, dones, infos) with episode-end infos added."""
        obs, rewards, terminations, truncations, infos = self._concat.step_wait()
        terminations = np.asarray(terminations, dtype=bool)   # (N,)
        truncations = np.asarray(truncations, dtype=bool)     # (N,)
        dones = terminations | truncations                    # (N,)
        self._returns += rewards
        self._lengths += 1
        A = self.max_agents
        for e in range(self.n_episodes):
            rows = range(e * A, (e + 1) * A)
            self._accumulate(e, [infos[k] for k in rows])
            if not dones[e * A]:
                continue
            summary = self._team_summary(e)
            for k in rows:
                info = infos[k]
                info["terminal_observation"] = flatten_observation(info["terminal_observation"])
                info["TimeLimit.truncated"] = bool(truncations[k] and not terminations[k])
                info["episode"] = {"r": float(self._returns[k]), "l": int(self._lengths[k])}
                info["team_episode"] = dict(summary)
                self._returns[k] = 0.0
                self._lengths[k] = 0
            self._start_episode(e)
        self._update_masks(infos)
        return flatten_observation(obs), np.asarray(rewards, dtype=np.float32), dones, infos

    def set_options(self, options=None) -> None:
        """Reset options are not forwarded by SuperSuit; team sizes go through set_agents.

        Raises:
            NotImplementedError: any options given.
        """
        if options:
            raise NotImplementedError(f"PatrolVecEnv takes no reset options ({options!r}); change "
                                      f"team sizes with set_agents([...]) and seeds with seed(s)")

    def has_attr(self, attr_name: str) -> bool:
        """True for ``action_masks`` and for attributes of the PettingZoo env."""
        return attr_name == MASK_METHOD or hasattr(self.get_env(0), attr_name)

    def get_attr(self, attr_name: str, indices: VecEnvIndices = None) -> list[Any]:
        """Attribute of the PettingZoo env of each row's episode."""
        return [getattr(self.get_env(k // self.max_agents), attr_name)
                for k in self._get_indices(indices)]

    def set_attr(self, attr_name: str, value: Any, indices: VecEnvIndices = None) -> None:
        """Set an attribute on the PettingZoo env of each given row's episode."""
        for e in sorted({k // self.max_agents for k in self._get_indices(indices)}):
            setattr(self.get_env(e), attr_name, value)

    def env_method(self, method_name: str, *method_args, indices: VecEnvIndices = None,
                   **method_kwargs) -> list[Any]:
        """``action_masks``: each row's (n_symbols + 5,) bool mask; any other name is called on
        the PettingZoo env of each row's episode."""
        rows = list(self._get_indices(indices))
        if method_name == MASK_METHOD:
            return [self._masks[k].copy() for k in rows]
        return [getattr(self.get_env(k // self.max_agents), method_name)(*method_args, **method_kwargs)
                for k in rows]

    def env_is_wrapped(self, wrapper_class, indices: VecEnvIndices = None) -> list[bool]:
        """No row is wrapped by a gymnasium wrapper (PettingZoo envs underneath)."""
        return [False for _ in self._get_indices(indices)]

    # ------------------------------------------------------------------ bookkeeping
    def _update_masks(self, infos: list[dict]) -> None:
        for k, info in enumerate(infos):
            self._masks[k] = mask_row(info["action_mask"])

    def _start_episode(self, e: int) -> None:
        """Zero episode ``e``'s accumulators and record its team (the one it was reset with)."""
        self._team[e] = self.get_env(e).n_agents
        self._sim_steps[e] = 0
        self._idle_sum[e] = 0.0
        self._idle_max[e] = 0.0
        self._collisions[e] = 0
        self._failures[e] = 0

    def _accumulate(self, e: int, infos: list[dict]) -> None:
        """Add one env step of episode ``e`` (its max_agents row infos) to the accumulators."""
        if "mean_idleness" not in infos[0]:  # a message phase: the simulator did not step
            return
        self._sim_steps[e] += 1
        self._idle_sum[e] += infos[0]["mean_idleness"]
        self._idle_max[e] = max(self._idle_max[e], infos[0]["max_idleness"])
        self._collisions[e] += infos[0]["collisions"]
        self._failures[e] += sum(int(i["battery_failed"]) for i in infos)

    def _team_summary(self, e: int) -> dict:
        """Episode ``e``'s summary for the learning curve.

        Returns:
            reward: mean over deployed slots of their return; n_agents: team size;
            mean_idleness: time average of the mean vertex idleness (AVG^h); max_idleness:
            worst instantaneous vertex idleness; collisions: events; battery_failures: slots
            whose battery ran out; sim_steps: simulator steps.
        """
        A, n = self.max_agents, int(self._team[e])
        steps = int(self._sim_steps[e])
        return {
            "reward": float(self._returns[e * A:e * A + n].mean()),
            "n_agents": n,
            "mean_idleness": float(self._idle_sum[e] / max(steps, 1)),
            "max_idleness": float(self._idle_max[e]),
            "collisions": int(self._collisions[e]),
            "battery_failures": int(self._failures[e]),
            "sim_steps": steps,
        }


def make_vec_env(map="A", agents: Sequence[int] = DEFAULT_AGENTS, variant: str = "rl-msg",
                 seed: int | None = 0, strict: bool = True, episode_env: dict | None = None,
                 **env_kwargs) -> PatrolVecEnv:
    """Build the parameter-shared SB3 vector env of a training run.

    Args:
        map: shipped map name ("A" .. "D"), a map file path or a MapSpec.
        agents: team size of each parallel episode; ``num_envs = len(agents) * max_agents``.
        variant: a key of :data:`patrolsb3.sb3.VARIANTS` (sets the env's ``comm``).
        seed: seed of the first reset (episode i gets seed + i); None for fresh entropy.
        strict: True: a masked action raises in the env; False: masked moves act as Stay
            (``invalid_action="stay"``), for algorithms without masks.
        episode_env: {parallel episode index: EnvConfig overrides} for episodes that run with
            other settings than ``env_kwargs`` (only settings that keep the spaces, see
            :meth:`PatrolParallelEnv.reconfigure`), e.g. short low-battery episodes beside
            long ones.
        **env_kwargs: other EnvConfig fields (``episode_steps``, ``message_timing``, ...).

    Returns:
        A :class:`PatrolVecEnv`, seeded but not yet reset.

    Raises:
        ValueError: unknown variant, empty ``agents``, or a team size the env refuses.
        TypeError: ``comm`` / ``invalid_action`` given directly (use ``variant`` / ``strict``),
            or an unknown EnvConfig field.
    """
    for key, instead in (("comm", "variant"), ("invalid_action", "strict")):
        if key in env_kwargs:
            raise TypeError(f"make_vec_env sets {key!r} from {instead!r}; do not pass it directly")
    agents = [int(k) for k in agents]
    if not agents:
        raise ValueError("agents must list at least one team size (one per parallel episode)")
    config = {**variant_overrides(variant), **env_kwargs,
              "invalid_action": "raise" if strict else "stay"}
    template = PatrolParallelEnv(map=map, n_agents=agents[0], **config)
    for k in agents:
        template._check_team(k)  # the env's own rule for a valid team
    markov = ss.pettingzoo_env_to_vec_env_v1(EpisodeResets(template, agents[0]))
    venv = ss.concat_vec_envs_v1(markov, len(agents), num_cpus=0, base_class="stable_baselines3")
    vec_env = PatrolVecEnv(venv)
    for i, overrides in (episode_env or {}).items():
        if not 0 <= int(i) < len(agents):
            raise ValueError(f"episode_env: no parallel episode {i} (there are {len(agents)})")
        vec_env.get_env(int(i)).reconfigure(**overrides)
    vec_env.set_agents(agents)
    vec_env.seed(seed)
    return vec_env
