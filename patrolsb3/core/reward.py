"""The paper's rewards (Eq. 1-4): R = R_p + R_b + R_c per agent per step, and our optional
home shaping R_h (``cfg.c_home``, 0 by default)."""
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
    return np.where(visited, -np.expm1(idle / -c_norm), 1.0)   # (-i) / c: the same bits as i / (-c)


def team_patrol_reward(f: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """R'_p(t) = (2 - mean_v f - max_v f) / 2 for (E, V) normalised idleness.

    Returns:
        (rp, mean_f, max_f), each (E,).
    """
    mean_f = f.sum(axis=1) / f.shape[1]           # what f.mean(axis=1) computes, without its overhead
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
    if not (battery <= b_l).any():
        return np.zeros(battery.shape)
    low = -(cfg.c_pbb + cfg.c_pbm * (b_l - battery) / b_l)
    return np.where(battery <= 0, -cfg.c_pb, np.where(battery <= b_l, low, 0.0))


def collision_reward(collided: np.ndarray, cfg: EnvConfig) -> np.ndarray:
    """R_c: -c_pc to every agent in a collision event; (E, A)."""
    return np.where(collided, -cfg.c_pc, 0.0)


def home_potential(steps_home: np.ndarray, battery: np.ndarray, cfg: EnvConfig,
                   scale: float) -> np.ndarray:
    """OURS: Phi = -c_home * (steps home / scale) * urgency, urgency = clip((2 b_l - b) / (2 b_l), 0, 1).

    The home shaping of an agent that stays active is R_h = Phi(after the step) - Phi(before):
    once its battery is under twice b_l, each step toward the station earns about
    c_home * urgency / scale and each step away costs as much, and arriving on the station
    (0 steps home) pays back what the trip cost. A difference of potentials (Ng et al. 1999)
    leaves the best policy unchanged up to discounting; it only makes the way home found
    sooner. An agent that fails gets no R_h that step (R_b's -c_pb alone).

    Args:
        steps_home: (E, A) shortest-path steps to the nearest station.
        battery: (E, A) battery units.
        cfg: environment parameters (c_home, b_low).
        scale: distance normaliser, H + W of the map.

    Returns:
        (E, A) potential (<= 0).
    """
    urgency = np.minimum(np.maximum((2.0 * cfg.b_low - battery) / (2.0 * cfg.b_low), 0.0), 1.0)
    return -cfg.c_home * (steps_home / scale) * urgency
