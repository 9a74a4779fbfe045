"""The agent protocol, once: phases, message symbols, composite masks and the flat layout.

Everything that stands between the simulator (:mod:`patrolsb3.core.step`) and a policy lives
here, and every client is a thin view over it: the PettingZoo env (one episode), the training
vector env (all parallel episodes in one batched call) and the zoo policy (evaluation).

* **Phases.** With same-step messages (``comm`` 'learned' or 'intention', ``message_timing``
  'same_step') one simulator step takes two decisions: a *message phase* (every active agent
  sends a symbol; the move must be Stay) and a *move phase* (everyone has seen this step's
  symbols; the message must be index 0; the simulator steps). Otherwise there is one phase, the
  move phase (with delayed messages, message and move are chosen together and the symbols are
  shown at the next step).
* **Symbols.** The action's message half is an index m = 0 .. n_symbols-1; the symbol shown on
  the grid is m + 1 (0 is silence, shown by inactive slots). In the intention mode the index is
  the intended move.
* **Composite mask.** One (n_symbols + 5,) bool row per slot: message mask, then move mask
  (:func:`patrolsb3.core.masks.composite_action_mask` for the rule of each phase).
* **Flat observation.** ``[grid (2, H, W) in C order, vector (vector_size), critic
  (3 * max_agents)]``, described by :class:`ObservationLayout`; the critic part is the
  centralised state and a policy's actor never reads it.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from .config import EnvConfig
from .maps import STAY, MapSpec
from .masks import action_mask, composite_action_mask
from .observe import PHASE_INDEX, actor_observation, critic_state, draw_positions, grid_channels, vector_size
from .state import State
from .step import InvalidActionError, StepInfo, step as core_step

MESSAGE_PHASE, MOVE_PHASE = 0, 1
PHASE_NAMES = ("message", "move")
N_MOVES = 5


def first_phase(cfg: EnvConfig) -> int:
    """The phase an episode starts in (and every simulator step starts with)."""
    return MESSAGE_PHASE if cfg.two_phase else MOVE_PHASE


def next_phase(cfg: EnvConfig, phase: int) -> int:
    """The phase after ``phase``: message -> move -> message ... with same-step messages."""
    return (MOVE_PHASE if phase == MESSAGE_PHASE else MESSAGE_PHASE) if cfg.two_phase else MOVE_PHASE


def phases_per_step(cfg: EnvConfig) -> int:
    """Decisions per simulator step: 2 with same-step messages, else 1."""
    return 2 if cfg.two_phase else 1


def protocol_signature(cfg: EnvConfig) -> tuple:
    """What fixes the spaces and phases: two configs with the same signature can run side by
    side in one vector env (per-episode settings such as ``episode_steps`` may differ)."""
    return (cfg.max_agents, cfg.n_symbols, cfg.two_phase, vector_size(cfg), grid_channels(cfg), cfg.comm)


def check_team(spec: MapSpec, cfg: EnvConfig, n_agents) -> int:
    """A team size the env can deploy: 1 .. max_agents and at most the map's vertex count.

    Raises:
        ValueError: names the team size and the limit it breaks.
    """
    if isinstance(n_agents, (bool, np.bool_)) or not isinstance(n_agents, (int, np.integer)):
        raise ValueError(f"n_agents must be a whole number, got {n_agents!r}")
    if not 1 <= int(n_agents) <= cfg.max_agents:
        raise ValueError(f"n_agents={n_agents} must be between 1 and max_agents={cfg.max_agents}")
    if int(n_agents) > spec.n_vertices:
        raise ValueError(f"n_agents={n_agents} is larger than the {spec.n_vertices} "
                         f"vertices of map {spec.name}")
    return int(n_agents)


def symbols_of(message_index: np.ndarray, active: np.ndarray) -> np.ndarray:
    """Symbols shown on the grid: index m -> symbol m + 1 for active slots, 0 (silence) else.

    Args:
        message_index: (E, A) int message halves of the actions.
        active: (E, A) bool.

    Returns:
        (E, A) int64 symbols 0 .. n_symbols.
    """
    return np.where(active, np.asarray(message_index, dtype=np.int64) + 1, 0)


def mask_size(cfg: EnvConfig) -> int:
    """Length of a composite mask row: n_symbols + 5."""
    return cfg.n_symbols + N_MOVES


@dataclasses.dataclass(frozen=True)
class ObservationLayout:
    """Where each part of a flat observation row sits.

    Attributes:
        grid_shape: (C, H, W) grid: C = 2 (positions and messages, idleness) or 2 + n_symbols
            (positions, idleness, one plane per symbol), see ``EnvConfig.message_encoding``.
        vector_size: length of the actor's vector part.
        critic_size: length of the centralised critic part (3 * max_agents).
        max_agents: slots per episode.
    """

    grid_shape: tuple
    vector_size: int
    critic_size: int
    max_agents: int

    @classmethod
    def of(cls, spec: MapSpec, cfg: EnvConfig) -> "ObservationLayout":
        """The layout of ``cfg`` on map ``spec``."""
        H, W = spec.shape
        return cls((grid_channels(cfg), H, W), vector_size(cfg), 3 * cfg.max_agents, cfg.max_agents)

    @property
    def grid_size(self) -> int:
        """2 * H * W."""
        return int(np.prod(self.grid_shape))

    @property
    def size(self) -> int:
        """Length of a flat row."""
        return self.grid_size + self.vector_size + self.critic_size

    def flatten(self, grid: np.ndarray, vector: np.ndarray, critic: np.ndarray) -> np.ndarray:
        """One flat float32 array of the three parts.

        Args:
            grid: (..., 2, H, W); vector: (..., vector_size); critic: (..., critic_size), with
                the same leading axes (none for one agent).

        Returns:
            (..., size) float32.
        """
        batch = vector.shape[:-1]
        out = np.empty(batch + (self.size,), dtype=np.float32)
        out[..., :self.grid_size] = grid.reshape(batch + (self.grid_size,))
        out[..., self.grid_size:self.grid_size + self.vector_size] = vector
        out[..., self.grid_size + self.vector_size:] = critic
        return out

    def split(self, flat: np.ndarray) -> dict:
        """The inverse of :meth:`flatten`: {"grid": (..., 2, H, W), "vector", "critic"} views."""
        g, v = self.grid_size, self.vector_size
        batch = flat.shape[:-1]
        return {"grid": flat[..., :g].reshape(batch + tuple(self.grid_shape)),
                "vector": flat[..., g:g + v], "critic": flat[..., g + v:]}

    def symbol_columns(self) -> slice:
        """The columns of a flat row that hold the symbol planes (grid channels 2 .. C-1, with
        ``message_encoding='planes'``): +1 on an agent's own cell for its own symbol, -1 on each
        other agent's cell for theirs. Empty with 'scalar' messages (C = 2)."""
        H, W = self.grid_shape[1:]
        return slice(2 * H * W, self.grid_size)

    def phase_column(self) -> int:
        """The column of a flat row that says the phase (1 in a move phase): the actor vector's
        ``PHASE_INDEX``."""
        return self.grid_size + PHASE_INDEX

    def to_dict(self) -> dict:
        """Plain dict (policy kwargs, config files)."""
        return {"grid_shape": tuple(self.grid_shape), "vector_size": int(self.vector_size),
                "critic_size": int(self.critic_size), "max_agents": int(self.max_agents)}


@dataclasses.dataclass
class Decision:
    """What every slot sees and may do at one phase of a batch of episodes.

    Attributes:
        phase: MESSAGE_PHASE or MOVE_PHASE.
        grid: (E, A, 2, H, W) float32 actor grids.
        vector: (E, A, vector_size) float32 actor vectors.
        critic: (E, 3 * max_agents) float32 centralised state.
        masks: (E, A, n_symbols + 5) bool composite masks (message, then move).
        move_mask: (E, A, 5) bool moves the state allows (:func:`patrolsb3.core.masks.action_mask`),
            whatever the phase (in a message phase the composite mask allows Stay only).
    """

    phase: int
    grid: np.ndarray
    vector: np.ndarray
    critic: np.ndarray
    masks: np.ndarray
    move_mask: np.ndarray

    def flat(self, layout: ObservationLayout) -> np.ndarray:
        """(E, A, layout.size) float32 flat rows, every slot with its episode's critic part."""
        E, A = self.vector.shape[:2]
        return layout.flatten(self.grid, self.vector,
                              np.broadcast_to(self.critic[:, None, :], (E, A, self.critic.shape[-1])))


def decide(spec: MapSpec, cfg: EnvConfig, state: State, phase: int) -> Decision:
    """Observations and masks of every slot at ``phase`` (the move mask computed once)."""
    move_mask = action_mask(spec, state, cfg)                                  # (E, A, 5)
    grid, vector = actor_observation(spec, cfg, state, phase=phase, mask=move_mask)
    message, move = composite_action_mask(spec, cfg, state, message_phase=phase == MESSAGE_PHASE,
                                          move_mask=move_mask)
    return Decision(phase, grid, vector, critic_state(spec, cfg, state),
                    np.concatenate([message, move], axis=-1), move_mask)


def next_decision(spec: MapSpec, cfg: EnvConfig, state: State, applied_phase: int,
                  previous: Decision) -> Decision:
    """The decision of the phase after ``applied_phase``, once its actions were applied to
    ``state`` (:func:`apply_actions`); equal to :func:`decide` of that phase.

    A message phase changes nothing but the symbols shown, so the move phase after it keeps
    what symbols cannot change (idleness channel, vector, critic state, move mask) from
    ``previous``, the message phase's decision, and redraws only the position and symbol
    channels; after a move phase (the simulator stepped) everything is computed anew.

    Args:
        applied_phase: the phase whose actions were just applied.
        previous: the decision of ``applied_phase`` (the one those actions answered).
    """
    phase = next_phase(cfg, applied_phase)
    if applied_phase != MESSAGE_PHASE:
        return decide(spec, cfg, state, phase)
    E, A = state.pos.shape
    grid = previous.grid.copy()                                                # (E, A, C, H, W)
    draw_positions(spec, cfg, state, grid.reshape(E, A, grid.shape[2], -1))
    vector = previous.vector.copy()                                            # (E, A, vector_size)
    vector[..., PHASE_INDEX] = phase
    message, move = composite_action_mask(spec, cfg, state, message_phase=False,
                                          move_mask=previous.move_mask)
    return Decision(phase, grid, vector, previous.critic, np.concatenate([message, move], axis=-1),
                    previous.move_mask)


def agent_label(episode: int, slot: int, n_envs: int) -> str:
    """How errors name a slot: ``drone_<slot>``, with its episode when there are several."""
    return f"drone_{slot}" if n_envs == 1 else f"episode {episode}, drone_{slot}"


def check_actions(cfg: EnvConfig, phase: int, actions: np.ndarray, masks: np.ndarray) -> np.ndarray:
    """Check the message half of every action (and, in a message phase, that the move is Stay).

    Moves of a move phase are the simulator's to check (:func:`patrolsb3.core.step.check_moves`,
    same ``invalid_action`` rule).

    Args:
        cfg: environment parameters (``invalid_action``, ``n_symbols``).
        phase: the phase the actions answer.
        actions: (E, A, 2) int (message index, move).
        masks: (E, A, n_symbols + 5) bool, the masks of this phase.

    Returns:
        (E, A, 2) int64 actions; with ``invalid_action='stay'`` illegal halves are repaired
        (message: the first legal index; move in a message phase: Stay).

    Raises:
        InvalidActionError: an illegal action with ``invalid_action='raise'``; the message names
            the slot (and its episode when there are several).
    """
    actions = np.array(actions, dtype=np.int64)
    n = cfg.n_symbols
    message, move = actions[..., 0], actions[..., 1]
    if phase != MESSAGE_PHASE and not message.any() and masks[..., 0].all():
        return actions                   # silence everywhere, and silence is legal everywhere
    in_range = message.view(np.uint64) < n                                   # negatives wrap to huge
    E, A = message.shape
    chosen = np.where(in_range, message, 0).reshape(E * A)
    message_ok = in_range & masks.reshape(E * A, -1)[np.arange(E * A), chosen].reshape(E, A)
    ok = message_ok & (move == STAY) if phase == MESSAGE_PHASE else message_ok
    if ok.all():
        return actions
    if cfg.invalid_action == "raise":
        e, i = (int(v) for v in np.argwhere(~ok)[0])
        label = agent_label(e, i, actions.shape[0])
        if phase == MESSAGE_PHASE:
            raise InvalidActionError(
                f"{label}: action {(int(message[e, i]), int(move[e, i]))} is not legal in the message "
                f"phase (message must be allowed by its mask, move must be Stay)")
        legal = np.flatnonzero(masks[e, i, :n])
        only = "only 0 is legal (its mask allows no message in this phase)" if list(legal) == [0] \
            else f"its mask allows {legal.tolist()}"
        raise InvalidActionError(f"{label} sent message index {int(message[e, i])} where {only}")
    actions[..., 0] = np.where(message_ok, message, np.argmax(masks[..., :n], axis=-1))
    if phase == MESSAGE_PHASE:
        actions[..., 1] = STAY
    return actions


def apply_actions(spec: MapSpec, cfg: EnvConfig, state: State, phase: int,
                  actions: np.ndarray, decision: Decision | None = None) -> StepInfo | None:
    """Carry out one phase's checked actions on ``state``, in place.

    A message phase shows the symbols (``state.messages``) and returns None; a move phase steps
    the simulator and returns its :class:`StepInfo`. With same-step messages the symbols are
    cleared after the move; with delayed messages the symbols chosen now are shown at the next
    step.

    Args:
        actions: (E, A, 2) int64 from :func:`check_actions`.
        decision: the decision these actions answer, if the caller has it: the simulator then
            checks the moves against its move mask instead of evaluating the rule again (not
            with the return guard, whose narrower mask the simulator does not apply).
    """
    active = state.active
    allowed = None if decision is None or cfg.return_guard else decision.move_mask
    if phase == MESSAGE_PHASE:
        state.messages = symbols_of(actions[..., 0], active)
        return None
    if cfg.comm == "none" or cfg.two_phase:
        info = core_step(spec, cfg, state, actions[..., 1], allowed=allowed)
    else:  # delayed messages: chosen now, shown at the next step
        symbols = symbols_of(actions[..., 0], active)
        info = core_step(spec, cfg, state, actions[..., 1], messages=np.zeros_like(symbols),
                         allowed=allowed)
        state.messages = np.where(state.active, symbols, 0)
    if cfg.two_phase:
        state.messages = np.zeros_like(state.messages)
    return info
