"""A zoo policy or a heuristic acting in the PettingZoo env: ``actions = agent.act(obs, infos)``.

::

    import patrolsb3
    from patrolsb3 import zoo
    from patrolsb3.agents import PettingZooAgent

    policy = zoo.load("A", "rl-msg")
    env = patrolsb3.parallel_env("A", n_agents=3, **policy.env_settings())
    agent = PettingZooAgent(policy, env)
    obs, infos = env.reset(seed=0)
    agent.reset()
    while env.agents:
        obs, rewards, terms, truncs, infos = env.step(agent.act(obs, infos))

The agent handles the phases (a message phase, then a move phase, with same-step messages:
:mod:`patrolsb3.core.protocol`): each call answers the phase the infos say. A zoo policy reads
only the env's observations and the masks of its infos (the flat layout of
:class:`~patrolsb3.core.protocol.ObservationLayout`) and keeps its recurrent state between
calls; ``reset()`` starts a new episode. A heuristic (CR, PART, SEBS, RANDOM, CYCLIC) plans on
the whole simulator state, as in the paper's comparison, so it reads the env's
``core_state``; it never speaks (its message is the first legal one).
"""
from __future__ import annotations

import numpy as np

from .core import protocol
from .core.maps import STAY
from .core.metrics import EpisodeMetrics


class PettingZooAgent:
    """Actions of every agent of a :class:`~patrolsb3.env.PatrolParallelEnv` from its own
    observations and infos (module docstring).

    Args:
        policy: a :class:`~patrolsb3.zoo.ZooPolicy` (``patrolsb3.zoo.load``), or a heuristic
            (``patrolsb3.strategies.get``, anything with SB3's ``predict`` on the simulator state).
        env: the env it acts in (a heuristic reads its ``core_state``; a zoo policy is checked
            against its settings).
        deterministic: a zoo policy's most likely legal action (True) or a sample.

    Raises:
        ValueError: a zoo policy whose observations, actions or phases differ from the env's
            (the message names the settings to pass, ``policy.env_settings()``).
    """

    def __init__(self, policy, env, deterministic: bool = True):
        self.policy = policy
        self.env = env
        self.deterministic = deterministic
        self.learned = hasattr(policy, "layout")                 # a ZooPolicy
        if self.learned:
            mine, theirs = protocol.protocol_signature(policy.cfg), protocol.protocol_signature(env.cfg)
            if mine != theirs or policy.spec.shape != env.spec_map.shape:
                raise ValueError(f"this policy was trained with other observations or phases than the "
                                 f"env's; build the env with parallel_env(map, n_agents, "
                                 f"**policy.env_settings()) = {policy.env_settings()}")
        self.reset()

    def reset(self) -> None:
        """Forget the recurrent state (or the heuristic's memory): the next call starts an episode."""
        self.state = None
        self.starting = True

    def act(self, observations: dict, infos: dict) -> dict:
        """The (message, move) action of every agent in ``observations``, for the phase its infos say.

        Args:
            observations: the env's observations (agent -> {"grid", "vector", "critic"}).
            infos: the env's infos (agent -> dict with ``action_mask_flat`` and ``phase``).

        Returns:
            agent -> (message index, move), legal under the agent's mask.
        """
        agents = list(observations)
        if not agents:
            return {}
        phase = int(infos[agents[0]]["phase"])
        masks = np.stack([np.asarray(infos[a]["action_mask_flat"], dtype=bool) for a in agents])  # (n, 21)
        if self.learned:
            actions = self._learned(observations, agents, masks)
        else:
            actions = self._heuristic(agents, masks, phase)
        self.starting = False
        return {a: (int(m), int(v)) for a, (m, v) in zip(agents, actions)}

    def _learned(self, observations: dict, agents: list, masks: np.ndarray) -> np.ndarray:
        layout = self.policy.layout
        rows = np.stack([layout.flatten(observations[a]["grid"], observations[a]["vector"],
                                        observations[a]["critic"]) for a in agents])   # (n, layout.size)
        starts = np.full(len(agents), self.starting)
        actions, self.state = self.policy.act_rows(rows, masks, self.state, starts, self.deterministic)
        return actions

    def _heuristic(self, agents: list, masks: np.ndarray, phase: int) -> np.ndarray:
        n = self.env.cfg.n_symbols
        first_message = np.argmax(masks[:, :n], axis=1)                       # (n,) it never speaks
        if phase == protocol.MESSAGE_PHASE:
            return np.stack([first_message, np.full(len(agents), STAY)], axis=1)
        start = np.full(1, self.state is None)                                 # its memory starts here
        planned, self.state = self.policy.predict(self.env.core_state, state=self.state, episode_start=start,
                                                  deterministic=True)
        moves = np.asarray(planned)[0, :len(agents), 1]                      # (n,)
        return np.stack([first_message, moves], axis=1)


def play_episode(env, agent: PettingZooAgent, seed: int | None = None, frames: bool = False) -> dict:
    """One episode of ``env`` acted by ``agent``, with the paper's metrics.

    Args:
        env: a :class:`~patrolsb3.env.PatrolParallelEnv` (``render_mode='rgb_array'`` for frames).
        agent: the :class:`PettingZooAgent` acting in it.
        seed: the reset's seed.
        frames: also return an RGB frame after every simulator step.

    Returns:
        The figures of :meth:`patrolsb3.core.metrics.EpisodeMetrics.result` for this episode as
        floats (avg_idleness, max_idleness, worst_idleness, std_idleness, collisions,
        battery_failures, swaps, ...), ``steps`` (simulator steps) and, with ``frames``, the
        list ``frames`` of (H_px, W_px, 3) uint8 arrays.
    """
    obs, infos = env.reset(seed=seed)
    agent.reset()
    metrics = EpisodeMetrics(1, env.spec_map.n_vertices)
    shots, steps = [], 0
    while env.agents:
        obs, rewards, terms, truncs, infos = env.step(agent.act(obs, infos))
        if env.last_step_info is not None and int(env.core_state.t[0]) > steps:   # the simulator stepped
            steps = int(env.core_state.t[0])
            metrics.update(env.core_state, env.last_step_info)
            if frames:
                shots.append(env.render())
    out = {k: (float(v[0]) if np.ndim(v) else v) for k, v in metrics.result().items()}
    out["steps"] = steps
    if frames:
        out["frames"] = shots
    return out
