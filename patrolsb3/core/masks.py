"""Action masks: which moves an agent may choose (one rule, used by the simulator's check,
the observations, the env's info and the heuristics)."""
from __future__ import annotations

import numpy as np

from .maps import STATION, STAY, MapSpec
from .state import State


def station_cells(spec: MapSpec) -> np.ndarray:
    """(H*W,) bool, True on charging stations (cells any number of agents may share)."""
    return spec.kinds.ravel() == STATION


def action_mask(spec: MapSpec, state: State) -> np.ndarray:
    """Valid moves of every slot.

    A move is valid when it stays in the grid, does not enter an obstacle and does not enter
    a cell occupied by another active agent (stations excepted). ``Stay`` is always valid;
    inactive slots may only stay.

    Returns:
        (E, A, 5) bool in action order Up, Down, Left, Right, Stay.
    """
    pos, active = state.pos, state.active                      # (E, A)
    E, A = pos.shape
    target = spec.neighbour[pos]                               # (E, A, 5)
    # occupancy grid: active agents per cell, minus the slot itself where it targets its own cell
    cells = spec.kinds.size
    flat = (np.arange(E)[:, None] * cells + pos)[active]
    occupancy = np.bincount(flat, minlength=E * cells).reshape(E, cells)   # (E, H*W)
    others = occupancy[np.arange(E)[:, None, None], target] - (active[..., None] & (target == pos[..., None]))
    occupied = others > 0                                      # (E, A, 5)
    mask = spec.move_ok[pos] & (~occupied | station_cells(spec)[target])
    mask[..., STAY] = True
    mask[~active] = np.array([False, False, False, False, True])
    return mask


def composite_action_mask(spec: MapSpec, cfg, state: State, message_phase: bool) -> tuple[np.ndarray, np.ndarray]:
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

    Returns:
        message (E, A, n_symbols) bool and move (E, A, 5) bool.
    """
    move = action_mask(spec, state)                                        # (E, A, 5)
    E, A = state.pos.shape
    message = np.zeros((E, A, cfg.n_symbols), dtype=bool)
    chooses_message = cfg.comm != "none" and (message_phase or cfg.message_timing == "delayed")
    active = state.active
    if chooses_message:
        if cfg.comm == "intention":
            message[..., :5] = move
        else:
            message[...] = True
        message[~active] = False
        message[~active, 0] = True
    else:
        message[..., 0] = True
    if message_phase:
        move = np.zeros_like(move)
        move[..., STAY] = True
    return message, move
