"""All parallel episodes of a training run as one PettingZoo ``ParallelEnv``, stepped by one
batched simulator call.

Why: a training run steps 8 parallel episodes together. As 8 separate PettingZoo envs under
SuperSuit, each step was 8 one-episode simulator calls and 8 sets of observations; the
simulator is batched over episodes (``State`` has a leading episode axis), so one call for
all of them costs about what one of those calls did. The agents of this env are the slots of
every episode (``e<episode>_drone_<slot>``), so SuperSuit's ``pettingzoo_env_to_vec_env_v1``
still turns it into the shared-policy vector env (one row per slot), as the project's shape
asks; :mod:`patrolsb3.sb3.vec_env` builds that stack.

Episodes run in lockstep (same phase at every env step: a message phase then a move phase with
same-step messages) but end on their own (a battery failure of the whole team, or an
``episode_steps`` of their own). An episode that ends is restarted in place at once, its
terminal observation in the info of each of its agents (``terminal_observation``). When every
episode ends at the same step, SuperSuit's vector env sees every agent done and resets the env
itself (putting in ``terminal_observation`` the observations returned), as it does for any
PettingZoo env; so this env does not restart them then.

Parallel episodes may run with other settings than the rest (the ``mix`` hyperparameter:
e.g. short low-battery episodes beside long ones), as long as the spaces and phases are the
same (:func:`patrolsb3.core.protocol.protocol_signature`); episodes of equal settings are one
group and one simulator call, so a run without a mix makes one call per step.
"""
from __future__ import annotations

from typing import Sequence

import numpy as np
from gymnasium import spaces
from pettingzoo import ParallelEnv

from ..core import protocol
from ..core.config import ENV_VERSION, EnvConfig
from ..core.maps import MapSpec
from ..core.state import reset_episodes, reset_state


class EpisodeGroup:
    """Parallel episodes that share one EnvConfig, and their batched simulator state.

    Attributes:
        cfg: their settings.
        episodes: (G,) int64 indices among all parallel episodes.
        rows: (G * max_agents,) int64 their rows (episode-major, then slot).
        state: the batched ``State`` of these G episodes (set by the env's reset).
        decision: their :class:`patrolsb3.core.protocol.Decision` of the current phase.
    """

    def __init__(self, cfg: EnvConfig, episodes: Sequence[int]):
        self.cfg = cfg
        self.episodes = np.asarray(episodes, dtype=np.int64)
        A = cfg.max_agents
        self.rows = (self.episodes[:, None] * A + np.arange(A)).reshape(-1)
        self.state = None
        self.decision = None


class BatchedPatrolEnv(ParallelEnv):
    """Every slot of every parallel episode as one agent of a PettingZoo ``ParallelEnv``.

    Agents: ``e<e>_drone_<i>`` for episode e = 0..E-1 and slot i = 0..max_agents-1, in that
    order (row ``e * max_agents + i`` of the vector env). All stay in ``agents`` for good;
    slots an episode does not deploy are padding: only (0, Stay) is legal, reward 0.

    Observation: Box(-1, 1, (layout.size,), float32), the flat layout of
    :class:`patrolsb3.core.protocol.ObservationLayout`. Action: MultiDiscrete([n_symbols, 5]).
    Info of every agent: ``action_mask`` ((n_symbols + 5,) bool, message then move); at the end
    of its episode also ``terminal_observation`` (when restarted in place), ``episode``
    ({"r": the slot's return, "l": env steps}) and ``team_episode`` (:meth:`_team_summary`).

    Args:
        spec: the map.
        configs: one EnvConfig per parallel episode, all with one protocol signature.
        teams: team size of each parallel episode.
    """

    metadata = {"name": f"{ENV_VERSION}_batched", "render_modes": [], "is_parallelizable": True}

    def __init__(self, spec: MapSpec, configs: Sequence[EnvConfig], teams: Sequence[int]):
        if len(configs) != len(teams) or not configs:
            raise ValueError(f"one config per parallel episode: {len(configs)} configs, {len(teams)} teams")
        signatures = {protocol.protocol_signature(c) for c in configs}
        if len(signatures) != 1:
            raise ValueError("parallel episodes must share their spaces and phases (max_agents, comm, "
                             "message_timing, n_symbols, local_idleness)")
        self.spec_map = spec
        self.configs = list(configs)
        self.cfg = configs[0]
        self.n_episodes = E = len(configs)
        self.max_agents = A = self.cfg.max_agents
        self.layout = protocol.ObservationLayout.of(spec, self.cfg)
        self.groups = []
        for cfg in dict.fromkeys(configs):            # distinct configs, first-seen order
            self.groups.append(EpisodeGroup(cfg, [e for e in range(E) if configs[e] == cfg]))
        self.teams = np.array([protocol.check_team(spec, c, k) for c, k in zip(configs, teams)])  # (E,) next
        self.running = self.teams.copy()              # (E,) teams of the running episodes
        self.possible_agents = [f"e{e}_drone_{i}" for e in range(E) for i in range(A)]
        self.agents = list(self.possible_agents)
        self.render_mode = None
        self._obs_space = spaces.Box(-1.0, 1.0, (self.layout.size,), np.float32)
        self._act_space = spaces.MultiDiscrete([self.cfg.n_symbols, protocol.N_MOVES])
        self.rng = np.random.default_rng()
        self.phase = protocol.first_phase(self.cfg)
        N = E * A
        self.observations = np.zeros((N, self.layout.size), dtype=np.float32)   # (N, size) current rows
        self.masks = np.zeros((N, protocol.mask_size(self.cfg)), dtype=bool)     # (N, n_symbols + 5)
        self._returns = np.zeros(N)                   # (N,) return of each row's episode so far
        self._lengths = np.zeros(N, dtype=np.int64)   # (N,) env steps of each row's episode
        self._sim_steps = np.zeros(E, dtype=np.int64)  # (E,) simulator steps so far
        self._idle_sum = np.zeros(E)                  # (E,) sum over sim steps of mean idleness
        self._idle_max = np.zeros(E)                  # (E,) worst instantaneous max idleness
        self._collisions = np.zeros(E, dtype=np.int64)  # (E,) collision events
        self._failures = np.zeros(E, dtype=np.int64)  # (E,) battery failures

    def observation_space(self, agent):
        return self._obs_space

    def action_space(self, agent):
        return self._act_space

    # ------------------------------------------------------------------ rows
    def deployed_rows(self) -> np.ndarray:
        """(N,) bool: rows of slots their running episode deploys (the others are padding)."""
        return (np.arange(self.max_agents)[None, :] < self.running[:, None]).reshape(-1)

    def set_teams(self, teams: Sequence[int]) -> None:
        """Team size of each parallel episode from its next start.

        Raises:
            ValueError: wrong length or a team size the env refuses.
        """
        teams = [int(k) for k in teams]
        if len(teams) != self.n_episodes:
            raise ValueError(f"set_agents needs {self.n_episodes} team sizes (one per parallel "
                             f"episode), got {len(teams)}: {teams}")
        self.teams = np.array([protocol.check_team(self.spec_map, c, k) for c, k in zip(self.configs, teams)])

    # ------------------------------------------------------------------ API
    def reset(self, seed=None, options=None):
        """Start every parallel episode (seed: of the generator all episodes draw from)."""
        if options:
            raise NotImplementedError(f"reset options are not taken ({options!r}); team sizes go "
                                      f"through set_teams")
        if seed is not None:
            self.rng = np.random.default_rng(seed)
        for group in self.groups:
            group.state = reset_state(self.spec_map, group.cfg, self.teams[group.episodes],
                                      n_envs=len(group.episodes), rng=self.rng)
        self.running = self.teams.copy()
        self._returns[:] = 0.0
        self._lengths[:] = 0
        self._clear_summaries(np.arange(self.n_episodes))
        self._decide(protocol.first_phase(self.cfg))
        return self._observation_dict(), self._info_dicts()

    def step(self, actions):
        """One phase of every parallel episode; PettingZoo's (obs, rewards, terms, truncs, infos)."""
        A, N = self.max_agents, self.n_episodes * self.max_agents
        act = np.array([actions[a] for a in self.possible_agents], dtype=np.int64).reshape(N, 2)
        phase = self.phase
        rewards = np.zeros(N)                         # (N,)
        terminated = np.zeros(self.n_episodes, dtype=bool)  # (E,)
        truncated = np.zeros(self.n_episodes, dtype=bool)   # (E,)
        failed = np.zeros((self.n_episodes, A), dtype=bool)  # (E, A) battery failures this step
        for group in self.groups:
            e, rows = group.episodes, group.rows
            group_act = protocol.check_actions(group.cfg, phase, act[rows].reshape(len(e), A, 2),
                                               self.masks[rows].reshape(len(e), A, -1))
            info = protocol.apply_actions(self.spec_map, group.cfg, group.state, phase, group_act,
                                          group.decision)
            group.decision = protocol.next_decision(self.spec_map, group.cfg, group.state, phase,
                                                    group.decision)
            if info is None:
                continue
            rewards[rows] = info.reward.reshape(-1)
            terminated[e] = info.terminated
            truncated[e] = info.truncated & ~info.terminated
            failed[e] = info.battery_failed
            self._sim_steps[e] += 1
            self._idle_sum[e] += info.mean_idleness
            self._idle_max[e] = np.maximum(self._idle_max[e], info.max_idleness)
            self._collisions[e] += info.collisions
        self._failures += failed.sum(axis=1)
        self._returns += rewards
        self._lengths += 1
        ended = terminated | truncated                                         # (E,)
        extra = [dict() for _ in range(N)]
        for e in np.flatnonzero(ended):
            summary = self._team_summary(e)
            for k in range(e * A, (e + 1) * A):
                extra[k] = {"episode": {"r": float(self._returns[k]), "l": int(self._lengths[k])},
                            "team_episode": dict(summary)}
        self._show(protocol.next_phase(self.cfg, phase))
        if ended.any() and not ended.all():   # restart these now; all at once is SuperSuit's reset
            for k in np.flatnonzero(np.repeat(ended, A)):
                extra[k]["terminal_observation"] = self.observations[k].copy()
            self._restart(np.flatnonzero(ended))
        row_terms = np.repeat(terminated, A)
        row_truncs = np.repeat(truncated, A)
        names = self.possible_agents
        infos = self._info_dicts()
        for k in np.flatnonzero(np.repeat(ended, A)):
            infos[names[k]].update(extra[k])
        return (self._observation_dict(), dict(zip(names, rewards.tolist())),
                dict(zip(names, row_terms.tolist())), dict(zip(names, row_truncs.tolist())), infos)

    def close(self):
        pass

    # ------------------------------------------------------------------ bookkeeping
    def _restart(self, ended: np.ndarray) -> None:
        """Restart the parallel episodes ``ended`` (indices) in place with their next teams."""
        A = self.max_agents
        for group in self.groups:
            local = np.flatnonzero(np.isin(group.episodes, ended))
            if len(local):
                reset_episodes(self.spec_map, group.cfg, group.state, local,
                               self.teams[group.episodes[local]])
        self.running[ended] = self.teams[ended]
        rows = (ended[:, None] * A + np.arange(A)).reshape(-1)
        self._returns[rows] = 0.0
        self._lengths[rows] = 0
        self._clear_summaries(ended)
        self._decide(protocol.first_phase(self.cfg))

    def _decide(self, phase: int) -> None:
        """Enter ``phase`` from the current states: every group's decision computed anew."""
        for group in self.groups:
            group.decision = protocol.decide(self.spec_map, group.cfg, group.state, phase)
        self._show(phase)

    def _show(self, phase: int) -> None:
        """Every row's flat observation and mask from the groups' decisions of ``phase`` (new
        arrays: the rows handed out before, terminal observations among them, stay as they were)."""
        self.phase = phase
        self.observations = np.empty_like(self.observations)
        self.masks = np.empty_like(self.masks)
        for group in self.groups:
            decision = group.decision
            if len(self.groups) == 1:
                self.observations = decision.flat(self.layout).reshape(len(group.rows), -1)
                self.masks = decision.masks.reshape(len(group.rows), -1)
            else:
                self.observations[group.rows] = decision.flat(self.layout).reshape(len(group.rows), -1)
                self.masks[group.rows] = decision.masks.reshape(len(group.rows), -1)

    def _observation_dict(self) -> dict:
        return dict(zip(self.possible_agents, self.observations))

    def _info_dicts(self) -> dict:
        return {name: {"action_mask": mask} for name, mask in zip(self.possible_agents, self.masks)}

    def _clear_summaries(self, episodes: np.ndarray) -> None:
        self._sim_steps[episodes] = 0
        self._idle_sum[episodes] = 0.0
        self._idle_max[episodes] = 0.0
        self._collisions[episodes] = 0
        self._failures[episodes] = 0

    def _team_summary(self, e: int) -> dict:
        """Episode ``e``'s summary for the learning curve.

        Returns:
            reward: mean over deployed slots of their return; n_agents: team size;
            mean_idleness: time average of the mean vertex idleness (AVG^h); max_idleness:
            worst instantaneous vertex idleness; collisions: events; battery_failures: slots
            whose battery ran out; sim_steps: simulator steps.
        """
        A, n = self.max_agents, int(self.running[e])
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
