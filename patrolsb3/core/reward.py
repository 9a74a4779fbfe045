"""The paper's rewards (Eq. 1-4): R = R_p + R_b + R_c per agent per step."""
from __future__ import annotations

import numpy as np

from .config import EnvConfig


def normalised_idleness(idle: np.ndarray, visited: np.ndarray, c_norm: float) -> np.ndarray:
    """f(i) = 1 - exp(-i / c_norm); a never-visited vertex counts as infinitely idle (f = 1).

    Args:
        idle: (..., V) idleness.
        visited: (..., V) bool.
        c_norm: normalisation constant.

    Returns:
        (..., V) float values in [0, 1].
    """
    return np.where(visited, -np.expm1(-idle / c_norm), 1.0)


def team_patrol_reward(f: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """R'_p(t) = (2 - mean_v f - max_v f) / 2 for (E, V) normalised idleness.

    Returns:
        (rp, mean_f, max_f), each (E,).
    """
    mean_f = f.mean(axis=1)
    max_f = f.max(axis=1)
    return (2.0 - mean_f - max_f) / 2.0, mean_f, max_f


def difference_reward(f_without_k: np.ndarray, on_vertex: np.ndarray, mean_f: np.ndarray,
                      max_f: np.ndarray, n_vertices: int) -> np.ndarray:
    """D_k = R'_p(t) - R'_{p,-k}(t), where -k means agent k's cell was not reset this step.

    With the reset the vertex counts f = 0; without it, ``f_without_k``. So
    D_k = (f_without_k / V + max(0, f_without_k - max_f)) / 2.

    Args:
        f_without_k: (E, A) f of agent k's vertex had it not been reset.
        on_vertex: (E, A) bool, agent k is active and stands on a vertex (not the station).
        mean_f, max_f: (E,) statistics of f after all resets.
        n_vertices: V.

    Returns:
        (E, A) difference reward, 0 where ``on_vertex`` is False.
    """
    d = (f_without_k / n_vertices + np.maximum(0.0, f_without_k - max_f[:, None])) / 2.0
    return np.where(on_vertex, d, 0.0)


def battery_reward(battery: np.ndarray, cfg: EnvConfig) -> np.ndarray:
    """R_b: -c_pb when the battery is empty; -(c_pbb + c_pbm (b_l - b) / b_l) for 0 < b <= b_l.

    Args:
        battery: (E, A) battery units after this step's drain.

    Returns:
        (E, A) penalty (<= 0).
    """
    b_l = cfg.b_low
    low = -(cfg.c_pbb + cfg.c_pbm * (b_l - battery) / b_l)
    return np.where(battery <= 0, -cfg.c_pb, np.where(battery <= b_l, low, 0.0))


def collision_reward(collided: np.ndarray, cfg: EnvConfig) -> np.ndarray:
    """R_c: -c_pc to every agent in a collision event; (E, A)."""
    return np.where(collided, -cfg.c_pc, 0.0)
