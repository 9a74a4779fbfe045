"""PettingZoo ``ParallelEnv`` over the batched core: the one-episode view (n_envs = 1)."""
from __future__ import annotations

import functools

import numpy as np
from gymnasium import spaces
from pettingzoo import ParallelEnv
from pettingzoo.utils.conversions import parallel_to_aec

from .core import protocol
from .core.config import ENV_VERSION, EnvConfig, make_config
from .core.maps import STAY, load_map
from .core.observe import grid_channels, vector_size
from .core.state import reset_state

INFO_KEYS = ("action_mask", "action_mask_flat", "phase", "status", "battery", "step", "collided",
             "collisions", "pushed", "swap_started", "swap_battery", "battery_failed", "fault_failed",
             "mean_idleness", "max_idleness", "team_patrol_reward")
"""The keys of every agent's info, at every step: ``action_mask`` (message (n_symbols,), move
(5,)) int8, PettingZoo's convention for MultiDiscrete; ``action_mask_flat`` the same as one
(n_symbols + 5,) int8 array; ``phase`` 0 message / 1 move (:mod:`patrolsb3.core.protocol`);
``status`` 0 active, 1 swapping, 2 failed (``core.state.STATUS_NAMES``); ``battery`` fraction;
``step`` simulator steps done; then what the last simulator step did (all 0 / False in a message
phase): ``collided``, ``collisions`` (events), ``pushed``, ``swap_started``, ``swap_battery``
(fraction at the swap's start, -1 when none started), ``battery_failed``, ``fault_failed``,
``mean_idleness`` and ``max_idleness`` (over vertices, after the step), ``team_patrol_reward``."""


class PatrolParallelEnv(ParallelEnv):
    """Multi-drone patrolling of a grid map (the paper's model, docs/model.md, sections 1-5).

    Agents: the team, ``drone_0 .. drone_{n_agents-1}`` (``possible_agents`` lists every slot
    up to ``max_agents``); they stay in ``agents`` for the whole episode. A swapping or failed
    agent is *inactive*: its only legal action is (0, Stay), its reward is 0 and its observation
    says inactive. (Padding every episode to ``max_agents`` rows is the training adapter's
    business, :mod:`patrolsb3.sb3.batched_env`.)

    Observation (``Dict``), per agent:
        * ``grid``: Box(-1, 1, (C, H, W), float32): channel 0 positions and messages, channel 1
          normalised idleness (see :mod:`patrolsb3.core.observe`).
        * ``vector``: Box(-1, 1, (15,), float32): battery fraction, own move mask (5), phase
          (0 message, 1 move), active flag, home distance, battery margin, home direction (5).
        * ``critic``: Box(0, 1, (3 * max_agents,), float32): every slot's battery fraction and
          position (centralised critic state; a policy's actor must not read it).

    Action: ``MultiDiscrete([n_symbols, 5])`` = (message, move); message index m means symbol
    m + 1; moves are Up, Down, Left, Right, Stay. ``info[agent]["action_mask"]`` is a tuple of
    two int8 arrays (16,) and (5,), PettingZoo's convention for MultiDiscrete, and
    ``info[agent]["action_mask_flat"]`` the same as one (21,) array. Every info has the keys of
    :data:`INFO_KEYS`, numeric, at every step.

    Phases: with ``comm='learned'`` or ``'intention'`` and ``message_timing='same_step'``
    every simulator step takes two env steps: a message phase (the move must be Stay; the
    reward is 0) and a move phase (the message must be index 0; the simulator steps and the
    rewards come). In the intention mode the message index is the intended move (symbol =
    move + 1). With ``comm='none'`` or ``'delayed'`` timing each env step is one simulator
    step; delayed messages are shown at the next step.

    Reward: the paper's R = R_p + R_b + R_c (:mod:`patrolsb3.core.reward`).
    Termination: every deployed agent has failed. Truncation: ``episode_steps`` simulator
    steps.
    """

    metadata = {"name": ENV_VERSION, "render_modes": ["rgb_array", "human"], "render_fps": 10,
                "is_parallelizable": True}

    def __init__(self, map="A", n_agents: int = 3, seed=None, render_mode=None,
                 config: EnvConfig | None = None, **config_overrides):
        """Build the env.

        Args:
            map: shipped map name ("A" .. "D"), a path to a map file, or a MapSpec.
            n_agents: agents deployed at each reset (1 .. max_agents); ``reset(options=
                {"n_agents": k})`` changes it.
            seed: seed of the first reset when ``reset`` gets none.
            render_mode: None, "rgb_array" or "human" (a matplotlib window).
            config: a full EnvConfig; otherwise one is built from the map's paper values and
                ``config_overrides`` (any EnvConfig field).
        """
        self.spec_map = load_map(map)
        self.cfg = config if config is not None else make_config(self.spec_map.name, **config_overrides)
        if config is not None and config_overrides:
            raise TypeError("give either config= or keyword overrides, not both")
        self._check_team(n_agents)
        self.n_agents = int(n_agents)
        self.render_mode = render_mode
        if render_mode not in (None, "rgb_array", "human"):
            raise ValueError(f"render_mode must be None, 'rgb_array' or 'human', got {render_mode!r}")
        self.possible_agents = [f"drone_{i}" for i in range(self.cfg.max_agents)]
        self.agents = []
        self._seed = seed
        self.core_state = None
        self.phase = protocol.first_phase(self.cfg)
        self._decision = None   # protocol.Decision of the current phase
        H, W = self.spec_map.shape
        A = self.cfg.max_agents
        self._obs_space = spaces.Dict({
            "grid": spaces.Box(-1.0, 1.0, (grid_channels(self.cfg), H, W), np.float32),
            "vector": spaces.Box(-1.0, 1.0, (vector_size(self.cfg),), np.float32),
            "critic": spaces.Box(0.0, 1.0, (3 * A,), np.float32),
        })
        self._act_space = spaces.MultiDiscrete([self.cfg.n_symbols, 5])
        self._viewer = None

    def __str__(self) -> str:
        """What the env is, in one line (PettingZoo's default prints only its name)."""
        H, W = self.spec_map.shape
        messages = {"learned": "learned 16-symbol messages", "intention": "intention messages",
                    "none": "no messages"}.get(self.cfg.comm, self.cfg.comm)
        if self.cfg.comm == "learned" and self.cfg.n_symbols != 16:
            messages = f"learned {self.cfg.n_symbols}-symbol messages"
        return (f"{self.metadata.get('name', 'patrol')}: map {self.spec_map.name} ({H} x {W}, "
                f"{self.spec_map.n_vertices} vertices), {self.n_agents} agents of up to {self.cfg.max_agents}, "
                f"{messages} ({self.cfg.message_timing}), {self.cfg.episode_steps:,}-step episodes")

    __repr__ = __str__

    def reconfigure(self, **overrides) -> None:
        """Change EnvConfig fields that leave the spaces as they are (``episode_steps``,
        ``init_battery``, rewards, wind ...), effective from the next reset; a training run
        uses it to give some parallel episodes other settings (the ``mix`` hyperparameter).

        Raises:
            ValueError: a field that would change the observation or action spaces or the
                phases (``max_agents``, ``comm``, ``message_timing``, ``local_idleness``, ...).
            TypeError: an unknown EnvConfig field.
        """
        cfg = make_config(None, **{**self.cfg.to_dict(), **overrides})
        if protocol.protocol_signature(cfg) != protocol.protocol_signature(self.cfg):
            changed = [k for k in overrides if getattr(cfg, k) != getattr(self.cfg, k)]
            raise ValueError(f"reconfigure: {', '.join(changed)} would change the spaces or phases "
                             f"of the env; only settings that keep them can differ per episode")
        self.cfg = cfg

    def _check_team(self, n_agents):
        protocol.check_team(self.spec_map, self.cfg, n_agents)

    @functools.lru_cache(maxsize=None)
    def observation_space(self, agent):
        return self._obs_space

    @functools.lru_cache(maxsize=None)
    def action_space(self, agent):
        return self._act_space

    # ------------------------------------------------------------------ API
    def reset(self, seed=None, options=None):
        """Start an episode. ``options={"n_agents": k}`` changes the team size."""
        if seed is None and self._seed is not None:
            seed, self._seed = self._seed, None
        if options and "n_agents" in options:
            self._check_team(options["n_agents"])
            self.n_agents = int(options["n_agents"])
        self.core_state = reset_state(self.spec_map, self.cfg, self.n_agents, n_envs=1, seed=seed)
        self.agents = self.possible_agents[:self.n_agents]
        self._last_info = None
        self.episode_collisions = 0
        idle = self.core_state.idle[0]                                          # (V,)
        self._idleness = float(idle.sum() / idle.size), float(idle.max())       # (mean, max) now
        self._decide(protocol.first_phase(self.cfg))
        return self._observations(), self._infos(None)

    def _checked_action(self, name: str, action) -> np.ndarray:
        """One agent's action as (2,) int64: a pair of whole numbers, or a ValueError naming it."""
        value = np.asarray(action)
        if value.shape != (2,) or value.dtype == object or not np.issubdtype(value.dtype, np.number):
            raise ValueError(f"step(): the action of {name} must be a (message, move) pair of whole numbers, "
                             f"got {action!r}")
        if np.issubdtype(value.dtype, np.floating) and not (np.all(np.isfinite(value))
                                                          and np.all(value == np.round(value))):
            raise ValueError(f"step(): the action of {name} must be whole numbers, got {action!r}")
        return value.astype(np.int64)

    def step(self, actions):
        """Apply one (message, move) action per agent; see the class docstring for phases.

        Raises:
            RuntimeError: step before reset, or after the episode ended.
            TypeError: ``actions`` is not a dict.
            ValueError: an agent not in the episode, or an action that is not a pair of whole
                numbers (illegal values are the masks' business: ``invalid_action``).
        """
        if self.core_state is None:
            raise RuntimeError("step() before reset(): call reset() to start an episode")
        if not isinstance(actions, dict):
            raise TypeError(f"step() takes a dict {{agent: (message, move)}}, got {type(actions).__name__}")
        if actions and not self.agents:
            raise RuntimeError("step(): the episode has ended; call reset() to start another")
        if unknown := sorted(set(actions) - set(self.agents)):
            raise ValueError(f"step(): unknown agent(s) {unknown}; this episode's agents are {self.agents}")
        act = np.zeros((1, self.cfg.max_agents, 2), dtype=np.int64)             # (1, A, 2)
        act[0, :, 1] = STAY                                                    # slots not deployed
        for i, name in enumerate(self.agents):
            if name in actions and actions[name] is not None:
                act[0, i] = self._checked_action(name, actions[name])
        phase = self.phase
        act = protocol.check_actions(self.cfg, phase, act, self._decision.masks)
        info = protocol.apply_actions(self.spec_map, self.cfg, self.core_state, phase, act,
                                      self._decision)
        self._decision = protocol.next_decision(self.spec_map, self.cfg, self.core_state, phase,
                                                self._decision)
        self.phase = self._decision.phase
        if info is None:  # a message phase: symbols shown, the simulator did not step
            zeros = {a: 0.0 for a in self.agents}
            falses = {a: False for a in self.agents}
            return self._observations(), zeros, falses, dict(falses), self._infos(None)
        self.episode_collisions += int(info.collisions[0])
        self._last_info = info
        rewards = dict(zip(self.agents, info.reward[0].tolist()))
        term = bool(info.terminated[0])
        trunc = bool(info.truncated[0]) and not term
        terminations = {a: term for a in self.agents}
        truncations = {a: trunc for a in self.agents}
        obs, infos = self._observations(), self._infos(info)
        if term or trunc:
            self.agents = []
        return obs, rewards, terminations, truncations, infos

    def _decide(self, phase: int) -> None:
        """Enter ``phase``: observations and masks of the current state, computed once."""
        self.phase = phase
        self._decision = protocol.decide(self.spec_map, self.cfg, self.core_state, phase)

    def _observations(self):
        d = self._decision
        return {name: {"grid": d.grid[0, i], "vector": d.vector[0, i], "critic": d.critic[0]}
                for i, name in enumerate(self.agents)}

    def _infos(self, info):
        """The info of every agent: the same keys and numeric values at every step (see
        :data:`INFO_KEYS`); the simulator's figures are 0 in a message phase."""
        s = self.core_state
        masks = self._decision.masks[0].astype(np.int8)                          # (A, n_symbols + 5)
        n = self.cfg.n_symbols
        battery = (s.battery[0] / self.cfg.b_max).tolist()
        status = s.status[0].tolist()
        phase, t, k = int(self.phase), int(s.t[0]), len(self.agents)
        if info is None:
            falses = [False] * k
            collided = pushed = started = battery_failed = fault_failed = falses
            swap_battery = [-1.0] * k
            collisions, team = 0, 0.0
            mean_idleness, max_idleness = self._idleness   # a message phase leaves the idleness as it is
        else:
            collided, pushed = info.collided[0].tolist(), info.pushed[0].tolist()
            started = info.swap_started[0].tolist()
            # -1 (not nan) when no swap started: nan != nan breaks seed checks
            swap_battery = np.where(info.swap_started[0], info.swap_battery[0], -1.0).tolist()
            battery_failed, fault_failed = info.battery_failed[0].tolist(), info.fault_failed[0].tolist()
            collisions, team = int(info.collisions[0]), float(info.team_patrol[0])
            mean_idleness, max_idleness = float(info.mean_idleness[0]), float(info.max_idleness[0])
            self._idleness = mean_idleness, max_idleness
        out = {}
        for i, name in enumerate(self.agents):   # values in the order of INFO_KEYS
            row = masks[i]
            out[name] = dict(zip(INFO_KEYS, (
                (row[:n], row[n:]), row, phase, status[i], battery[i], t, collided[i], collisions,
                pushed[i], started[i], swap_battery[i], battery_failed[i], fault_failed[i],
                mean_idleness, max_idleness, team)))
        return out

    # ------------------------------------------------------------------ rendering
    def render(self):
        """An RGB frame (H_px, W_px, 3) uint8 in 'rgb_array' mode; a window in 'human' mode."""
        if self.render_mode is None:
            raise ValueError("render() needs render_mode='rgb_array' or 'human' at construction")
        if self.core_state is None:
            raise RuntimeError("render() before reset(): call reset() to start an episode")
        from .render import render_frame, show_frame
        frame = render_frame(self.spec_map, self.cfg, self.core_state)
        if self.render_mode == "human":
            self._viewer = show_frame(frame, self._viewer)
            return None
        return frame

    def close(self):
        self._viewer = None

    @property
    def last_step_info(self):
        """What the simulator's last step did (``core.step``'s ``StepInfo`` of this episode, the
        batch axis of length 1): None before the episode's first move phase; a message phase
        leaves it as it was (the simulator did not step: ``core_state.t`` says when it did).
        Metrics read it (``agents.play_episode``)."""
        return self._last_info

    def state_array(self):
        """The core's batched state of this episode (n_envs = 1); heuristics may read it."""
        return self.core_state


def parallel_env(map="A", n_agents: int = 3, seed=None, render_mode=None, **config) -> PatrolParallelEnv:
    """The patrolling world as a PettingZoo ``ParallelEnv`` (see :class:`PatrolParallelEnv`)."""
    return PatrolParallelEnv(map=map, n_agents=n_agents, seed=seed, render_mode=render_mode, **config)


def env(map="A", n_agents: int = 3, seed=None, render_mode=None, **config):
    """The AEC view of :func:`parallel_env` (PettingZoo's ``parallel_to_aec``)."""
    return parallel_to_aec(parallel_env(map=map, n_agents=n_agents, seed=seed,
                                        render_mode=render_mode, **config))
