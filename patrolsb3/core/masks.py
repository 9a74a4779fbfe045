"""Action masks: which moves an agent may choose (one rule, used by the simulator's check,
the observations, the env's info and the heuristics)."""
from __future__ import annotations

import functools

import numpy as np

from .maps import STATION, STAY, MapSpec
from .state import ACTIVE, State

_STAY_ONLY = np.array([False, False, False, False, True])   # (5,) the mask of an inactive slot
_STAY_ONLY.flags.writeable = False
WAIT_ALLOWANCE = 1.25
"""Extra factor on the trip home for steps spent waiting or yielding in traffic."""


@functools.lru_cache(maxsize=64)
def station_cells(spec: MapSpec) -> np.ndarray:
    """(H*W,) bool, True on charging stations (cells any number of agents may share); one
    read-only array per map."""
    cells = spec.kinds.ravel() == STATION
    cells.flags.writeable = False
    return cells


def _blocked(spec: MapSpec, state: State, target: np.ndarray) -> np.ndarray:
    """True where entering ``target`` is forbidden: off the grid or into an obstacle is
    handled by ``spec.move_ok``; this is the dynamic part, a non-station cell held by another
    active agent.

    Args:
        target: (E, A, K) cells the slots would enter (their own cell for Stay).

    Returns:
        (E, A, K) bool.
    """
    pos, active = state.pos, state.active                      # (E, A)
    held = np.where(active, pos, -1)                           # (E, A) cells of active agents, -1 none
    # (E, A, K, A): slot i's k-th target is the cell of another active slot j
    taken = (target[..., None] == held[:, None, None, :]) & _others(pos.shape[1])
    return taken.any(axis=-1) & ~station_cells(spec)[target]


@functools.lru_cache(maxsize=16)
def _others(n_slots: int) -> np.ndarray:
    """(A, 1, A) bool, True where j != i: every slot but the observer itself."""
    out = ~np.eye(n_slots, dtype=bool)[:, None, :]
    out.flags.writeable = False
    return out


def return_threshold(spec: MapSpec, cfg) -> np.ndarray:
    """Battery at or below which an agent on each cell must head for the station: the
    heuristics' recharge rule (docs/model.md, section 6), so that it arrives with about ``b_l`` left.

        threshold(cell) = steps_home(cell) * drain_high * push_factor_margin + b_l
        push_factor_margin = (1 + p_dyn_max (push_drain_factor - 1))   # pushed steps drain more
                             * (1 + 2 p_dyn_max)                         # a push costs ~2 steps
                             * WAIT_ALLOWANCE                            # waiting / yielding

    Args:
        spec: the map.
        cfg: environment parameters (drain, pushes, b_l).

    Returns:
        (H*W,) float64 battery units.
    """
    push_factor_margin = ((1 + cfg.p_dyn_max * (cfg.push_drain_factor - 1))
                          * (1 + 2 * cfg.p_dyn_max) * WAIT_ALLOWANCE)
    return spec.steps_home * cfg.drain[1] * push_factor_margin + cfg.b_low


def return_guard(spec: MapSpec, cfg, state: State, mask: np.ndarray) -> np.ndarray:
    """The shield ``env.return_guard`` puts on a learned policy's moves (OURS, not the paper's).

    An active agent whose battery is at or below :func:`return_threshold` for its cell keeps
    only the valid moves that bring it one step closer to a station; on a station (where the
    wind pushed it: a pushed arrival starts no swap) only the moves off it, so that it comes
    back on purpose at the next step. When other agents hold every cell one step closer, it
    waits (``Stay`` only), and it has right of way, as in the heuristics' planner: an agent
    that is not due and stands on such a cell may not stay (unless it has no other valid
    move), so the way clears at the next step.

    Args:
        spec: the map.
        cfg: environment parameters.
        state: batched state.
        mask: (E, A, 5) bool valid moves (:func:`action_mask`).

    Returns:
        (E, A, 5) bool, a subset of ``mask``.
    """
    pos = state.pos                                                            # (E, A)
    due = state.active & (state.battery <= return_threshold(spec, cfg)[pos])   # (E, A)
    if not due.any():
        return mask
    here = spec.steps_home[pos]                                                # (E, A)
    target = spec.neighbour[pos]                                               # (E, A, 5)
    closer = spec.move_ok[pos] & (spec.steps_home[target] < here[..., None])   # (E, A, 5) ignoring agents
    toward = mask & closer                                                     # (E, A, 5)
    on_station = here == 0                                                     # (E, A)
    blocked = due & ~on_station & ~toward.any(axis=-1)                         # (E, A) way home held
    out = mask.copy()
    go_home = due & ~on_station & ~blocked
    out[go_home] = toward[go_home]
    out[blocked] = np.array([False, False, False, False, True])
    can_move = mask[..., :STAY].any(axis=-1)                                   # (E, A) a move but Stay
    out[due & on_station & can_move, STAY] = False
    # right of way: agents standing on a cell a blocked due agent needs must move on
    needed = np.where(blocked[..., None] & closer, target, -1)                 # (E, A, 5) cells, -1 none
    holds = (pos[:, :, None, None] == needed[:, None, :, :]).any(axis=(2, 3))  # (E, A) on a needed cell
    give_way = holds & state.active & ~due & can_move
    out[give_way, STAY] = False
    return out


def action_mask(spec: MapSpec, state: State, cfg=None) -> np.ndarray:
    """Valid moves of every slot.

    A move is valid when it stays in the grid, does not enter an obstacle and does not enter
    a cell occupied by another active agent (stations excepted). ``Stay`` is always valid;
    inactive slots may only stay. With ``cfg.return_guard`` the learned policy's shield
    (:func:`return_guard`) narrows the mask further; the simulator checks moves without it.

    Args:
        spec: the map.
        state: batched state.
        cfg: environment parameters; None (or ``return_guard`` off) for the plain rule.

    Returns:
        (E, A, 5) bool in action order Up, Down, Left, Right, Stay.
    """
    pos = state.pos                                            # (E, A)
    target = spec.neighbour[pos]                               # (E, A, 5)
    mask = spec.move_ok[pos] & ~_blocked(spec, state, target)
    mask[..., STAY] = True
    mask = np.where(state.active[..., None], mask, _STAY_ONLY)
    if cfg is not None and cfg.return_guard:
        mask = return_guard(spec, cfg, state, mask)
    return mask


def move_allowed(spec: MapSpec, state: State, moves: np.ndarray) -> np.ndarray:
    """Whether each slot's chosen move is valid (the rule of :func:`action_mask`, evaluated
    for one move per slot only).

    Args:
        moves: (E, A) int64 actions 0..4.

    Returns:
        (E, A) bool.
    """
    pos = state.pos
    target = spec.neighbour[pos, moves]                        # (E, A)
    ok = spec.move_ok[pos, moves] & ~_blocked(spec, state, target[..., None])[..., 0]
    return np.where(state.active, ok | (moves == STAY), moves == STAY)


def composite_action_mask(spec: MapSpec, cfg, state: State, message_phase: bool,
                          move_mask: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Masks of the composite (message, move) action for every slot, in one phase.

    * Message phase (same-step messages): the move must be Stay; an active slot may send any
      symbol (comm 'learned'), or its intended move (comm 'intention': message index = move).
    * Move phase with same-step messages, or comm 'none': the message must be index 0; moves
      follow :func:`action_mask`.
    * Delayed messages (message and move chosen together): both halves free, as above.
    * Inactive slots: only (0, Stay).

    Args:
        spec: the map.
        cfg: environment parameters (comm, message_timing, n_symbols).
        state: batched state.
        message_phase: True in the message phase of a same-step exchange.
        move_mask: (E, A, 5) :func:`action_mask` of ``state`` if already computed.

    Returns:
        message (E, A, n_symbols) bool and move (E, A, 5) bool; a half that is the same for
        every slot (silence only, Stay only) is a read-only array shared between calls.
    """
    move = action_mask(spec, state, cfg) if move_mask is None else move_mask  # (E, A, 5)
    E, A = state.pos.shape
    chooses_message = cfg.comm != "none" and (message_phase or cfg.message_timing == "delayed")
    if chooses_message:
        message = np.empty((E, A, cfg.n_symbols), dtype=bool)
        if cfg.comm == "intention":
            message[..., :5] = move
            message[..., 5:] = False
        else:
            message[...] = True
        inactive = state.status != ACTIVE                                      # (E, A)
        message[inactive] = _only_first(cfg.n_symbols, 1, 1)[0, 0]
    else:
        message = _only_first(cfg.n_symbols, E, A)
    if message_phase:
        move = _stay_only_masks(E, A)
    return message, move


@functools.lru_cache(maxsize=64)
def _only_first(size: int, n_envs: int, n_slots: int) -> np.ndarray:
    """(n_envs, n_slots, size) read-only bool rows allowing index 0 only (silence)."""
    out = np.zeros((n_envs, n_slots, size), dtype=bool)
    out[..., 0] = True
    out.flags.writeable = False
    return out


@functools.lru_cache(maxsize=64)
def _stay_only_masks(n_envs: int, n_slots: int) -> np.ndarray:
    """(n_envs, n_slots, 5) read-only bool move masks allowing Stay only."""
    out = np.zeros((n_envs, n_slots, 5), dtype=bool)
    out[..., STAY] = True
    out.flags.writeable = False
    return out
