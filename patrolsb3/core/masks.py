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
    target = spec.neighbour[pos]                               # (E, A, 5)
    A = pos.shape[1]
    other = ~np.eye(A, dtype=bool)[None, :, None, :]           # (1, A, 1, A) j != i
    occupied = (active[:, None, None, :] & other
                & (target[..., None] == pos[:, None, None, :])).any(-1)  # (E, A, 5)
    mask = spec.move_ok[pos] & (~occupied | station_cells(spec)[target])
    mask[..., STAY] = True
    mask[~active] = np.array([False, False, False, False, True])
    return mask
