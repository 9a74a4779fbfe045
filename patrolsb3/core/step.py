"""One simulator step for a batch of episodes, in the order of docs/model.md, section 2:

messages -> moves (checked against the mask) -> pushes -> collisions -> battery drain ->
idleness -> hot swaps -> failures -> rewards.

Documented choices (where the paper is silent):

* Pushes: with probability ``p_dyn`` an active agent moves one cell in a uniformly random
  direction (Up/Down/Left/Right) instead of its chosen move; a push into an obstacle or the
  border leaves it in place. A pushed target ignores the mask (the wind does not look).
* Collisions: a *swap* (two movers exchanging cells) is one event, both stay; a *contested
  cell* (two or more movers heading for the same non-station cell) is one event, one mover
  chosen uniformly at random gets it, the others stay. A mover whose target is held by an
  agent that stays is blocked without an event (iterated until stable). Every agent in an
  event gets the collision penalty. Stations hold any number of agents.
* Battery: an active agent drains U[drain] units per step, x push_drain_factor when pushed.
* A swap starts when an agent's own (not pushed) move takes it onto a station from another
  cell; it lasts ``swap_time`` steps, offline; at the end of the last of them a fresh agent
  (full battery) appears on that station. Arriving on purpose saves an agent whose battery
  ran out on the same step (the swap comes before the failure check, as in the order of docs/model.md, section 2).
* Faults: ``faults=((s, k), ...)`` makes k agents that exist (active or swapping, chosen at
  random) fail at the end of step s (0-based); ``fault_prob`` fails each active agent with
  that probability per step.
"""
from __future__ import annotations

import dataclasses
import functools

import numpy as np

from .config import EnvConfig
from .maps import ACTION_NAMES, STAY, MapSpec
from .masks import move_allowed, station_cells
from .reward import (
    battery_reward,
    collision_reward,
    difference_reward,
    home_potential,
    normalised_idleness,
    team_patrol_reward,
)
from .state import ACTIVE, FAILED, SWAPPING, State
from .streams import StepDraws


class InvalidActionError(ValueError):
    """A move that the action mask forbids reached the simulator."""


@dataclasses.dataclass
class StepInfo:
    """What happened in one step of E episodes (A slots each)."""

    reward: np.ndarray          # (E, A) float64 total reward R (0 for slots inactive at step start)
    reward_patrol: np.ndarray   # (E, A) float64 R_p
    reward_battery: np.ndarray  # (E, A) float64 R_b
    reward_collision: np.ndarray  # (E, A) float64 R_c
    reward_home: np.ndarray     # (E, A) float64 R_h, our home shaping (0 unless cfg.c_home > 0)
    acted: np.ndarray           # (E, A) bool, slot was active at the start of the step
    pushed: np.ndarray          # (E, A) bool, moved by the wind instead of its move
    collided: np.ndarray        # (E, A) bool, took part in a collision event
    collisions: np.ndarray      # (E,) int64 collision events this step
    swap_started: np.ndarray    # (E, A) bool
    swap_battery: np.ndarray    # (E, A) float64 battery fraction at swap start (nan if none)
    swap_ended: np.ndarray      # (E, A) bool, a fresh agent appeared on the station
    battery_failed: np.ndarray  # (E, A) bool, failed because the battery ran out
    fault_failed: np.ndarray    # (E, A) bool, failed by injected fault
    team_patrol: np.ndarray     # (E,) float64 R'_p(t)
    mean_idleness: np.ndarray   # (E,) float64 mean over vertices of the idleness after the step
    max_idleness: np.ndarray    # (E,) float64 max over vertices of the idleness after the step
    truncated: np.ndarray       # (E,) bool, the episode reached episode_steps
    terminated: np.ndarray      # (E,) bool, every deployed agent has failed


def check_moves(spec: MapSpec, cfg: EnvConfig, state: State, moves: np.ndarray,
                allowed: np.ndarray | None = None, active: np.ndarray | None = None) -> np.ndarray:
    """Validate moves against the action mask.

    Args:
        moves: (E, A) int action per slot (inactive slots are forced to Stay).
        allowed: (E, A, 5) bool, :func:`patrolsb3.core.masks.action_mask` of ``state`` without
            the return guard, when the caller already has it; else the rule is evaluated for
            the chosen moves only.
        active: (E, A) bool ``state.active``, when the caller already has it.

    Returns:
        (E, A) int64 moves, invalid ones replaced by Stay when cfg.invalid_action == 'stay'.

    Raises:
        InvalidActionError: a masked move when cfg.invalid_action == 'raise'.
    """
    moves = np.asarray(moves, dtype=np.int64)
    if moves.shape != state.pos.shape:
        raise ValueError(f"moves must have shape {state.pos.shape} (n_envs, max_agents), got {moves.shape}")
    if (moves.view(np.uint64) > STAY).any():     # negative moves wrap to huge values
        bad = moves[(moves < 0) | (moves > STAY)][0]
        raise InvalidActionError(f"move {bad} outside 0..4 ({', '.join(ACTION_NAMES)})")
    moves = np.where(state.active if active is None else active, moves, STAY)
    if allowed is None:
        ok = move_allowed(spec, state, moves)                                 # (E, A)
    else:   # allowed[e, a, moves[e, a]] through the flat view: one index array, not two
        ok = allowed.reshape(-1)[_row_starts(moves.size) + moves.reshape(-1)].reshape(moves.shape)
    if not ok.all():
        if cfg.invalid_action == "raise":
            e, a = np.argwhere(~ok)[0]
            r, c = spec.rowcol(state.pos[e, a])
            raise InvalidActionError(
                f"episode {e}, agent {a} at (row {r}, col {c}) chose {ACTION_NAMES[moves[e, a]]}, "
                f"which its action mask forbids (blocked, obstacle or occupied); "
                f"set invalid_action='stay' to treat masked moves as Stay")
        moves = np.where(ok, moves, STAY)
    return moves


@functools.lru_cache(maxsize=64)
def _row_starts(n_rows: int) -> np.ndarray:
    """(n_rows,) int64 0, 5, 10, ...: where each slot's row of an (E, A, 5) mask starts in its
    flat view; read-only, one per size."""
    out = np.arange(0, 5 * n_rows, 5, dtype=np.int64)
    out.flags.writeable = False
    return out


def _no_conflict(spec: MapSpec, pos: np.ndarray, target: np.ndarray, active: np.ndarray,
                 moving: np.ndarray, on_station: np.ndarray) -> bool:
    """True when no rule of :func:`resolve_collisions` can apply: off the stations, no cell is
    both held or entered twice (positions of active agents and targets of movers, together).
    Then there is no swap, no contested cell and no blocked mover, and every mover arrives."""
    cells = spec.kinds.size
    row = np.arange(pos.shape[0])[:, None] * cells                       # (E, 1)
    held = row + pos
    entered = row + target
    keys = np.sort(np.concatenate([held[active & ~station_cells(spec)[pos]], entered[moving & ~on_station]]))
    return bool((keys[1:] != keys[:-1]).all())


def resolve_collisions(spec: MapSpec, pos: np.ndarray, target: np.ndarray, active: np.ndarray,
                       tie_break: np.ndarray):
    """Apply the collision rule to simultaneous moves.

    Args:
        pos: (E, A) current cells.
        target: (E, A) cells the slots head for (their own cell when staying).
        active: (E, A) bool, slots on the grid.
        tie_break: (E, A) uniforms; the highest mover into a contested cell wins it.

    Returns:
        new_pos (E, A), collided (E, A) bool, events (E,) int64.
    """
    E, A = pos.shape
    on_station = station_cells(spec)[target]                              # (E, A)
    moving = active & (target != pos)
    if _no_conflict(spec, pos, target, active, moving, on_station):
        return np.where(moving, target, pos), np.zeros((E, A), dtype=bool), np.zeros(E, dtype=np.int64)
    # swap conflicts: i -> pos_j and j -> pos_i
    swap = (moving[:, :, None] & moving[:, None, :]
            & (target[:, :, None] == pos[:, None, :]) & (target[:, None, :] == pos[:, :, None]))
    swapped = swap.any(axis=2)                                            # (E, A)
    events = swap.sum(axis=(1, 2)) // 2
    collided = swapped.copy()
    moving &= ~swapped
    # contested cells: two or more movers heading for the same non-station cell
    same = (moving[:, :, None] & moving[:, None, :]
            & (target[:, :, None] == target[:, None, :]) & ~on_station[:, :, None])  # (E, A, A)
    contender = same.sum(axis=2) >= 2
    if contender.any():
        key = tie_break
        best = np.where(same, key[:, None, :], -1.0).max(axis=2)
        loser = contender & (key < best)
        lower = np.tril(np.ones((A, A), dtype=bool), -1)[None]           # j < i
        first_of_cell = contender & ~(same & lower).any(axis=2)
        events = events + first_of_cell.sum(axis=1)
        collided |= contender
        moving &= ~loser
    # movers whose target is held by an agent that stays are blocked (until stable)
    for _ in range(A):
        stayer = active & ~moving
        blocked = moving & ~on_station & (stayer[:, None, :]
                                          & (pos[:, None, :] == target[:, :, None])).any(axis=2)
        if not blocked.any():
            break
        moving &= ~blocked
    new_pos = np.where(moving, target, pos)
    return new_pos, collided, events.astype(np.int64)


def step(spec: MapSpec, cfg: EnvConfig, state: State, moves: np.ndarray,
         messages: np.ndarray | None = None, compute_reward: bool = True,
         allowed: np.ndarray | None = None) -> StepInfo:
    """Advance every episode of ``state`` by one step, in place.

    Args:
        spec: the map.
        cfg: environment parameters.
        state: batched state, modified in place.
        moves: (E, A) int moves (Up, Down, Left, Right, Stay = 0..4).
        messages: (E, A) int symbols 0..n_symbols shown this step (0 = silent), or None to
            keep ``state.messages`` (they are cleared for inactive slots).
        compute_reward: skip the reward arithmetic when False (heuristic evaluation).
        allowed: (E, A, 5) the unguarded action mask of ``state`` if already computed
            (:func:`check_moves`).

    Returns:
        A :class:`StepInfo`.
    """
    draws = state.streams.step()      # every episode's draws of this step, whatever happens
    E, A = state.pos.shape
    acted = state.active                                                  # (E, A) a new array
    # 1. messages
    if messages is not None:
        state.messages = np.where(acted, np.asarray(messages, dtype=np.int64), 0)
    else:
        state.messages = np.where(acted, state.messages, 0)
    # 2. moves, checked against the mask
    moves = check_moves(spec, cfg, state, moves, allowed, acted)
    pos = state.pos
    shaping = compute_reward and cfg.c_home > 0
    if shaping:
        home_scale = float(sum(spec.shape))
        phi_before = home_potential(spec.steps_home[pos], state.battery, cfg, home_scale)
    # 3. pushes by the environment
    pushed = acted & (draws.push < state.p_dyn)
    push_dir = draws.push_direction()
    target = spec.neighbour[pos, moves]                                     # (E, A)
    if pushed.any():
        target = np.where(pushed, spec.neighbour[pos, push_dir], target)
    # 4. collisions
    new_pos, collided, collisions = resolve_collisions(spec, pos, target, acted, draws.tie_break)
    # 5. battery
    drain = draws.drain(cfg.drain[0], cfg.drain[1])
    if pushed.any():
        drain = np.where(pushed, drain * cfg.push_drain_factor, drain)
    state.battery = np.where(acted, state.battery - drain, state.battery)
    # 6. idleness: grows by the rate, reset where active agents stand
    state.idle += spec.rate
    v_at = spec.vertex_of_cell[new_pos]                                    # (E, A) -1 off-vertex
    on_vertex = acted & (v_at >= 0)
    v_safe = np.maximum(v_at, 0)
    e_col = np.arange(E)[:, None]                                          # (E, 1)
    idle_without_k = state.idle[e_col, v_safe]                             # (E, A)
    visited_without_k = state.visited[e_col, v_safe]
    e_on, a_on = np.nonzero(on_vertex)
    state.idle[e_on, v_at[e_on, a_on]] = 0.0
    state.visited[e_on, v_at[e_on, a_on]] = True
    state.pos = new_pos
    # 7. hot swaps: running swaps count down, then new arrivals on purpose start one
    # (each block below is skipped when its mask is all False: the same arrays come out)
    swap_ended = swapping = state.status == SWAPPING                      # (E, A)
    if swapping.any():
        state.swap_left = np.where(swapping, state.swap_left - 1, state.swap_left)
        swap_ended = swapping & (state.swap_left <= 0)
        state.status = np.where(swap_ended, ACTIVE, state.status).astype(np.int8, copy=False)
        state.battery = np.where(swap_ended, cfg.b_max, state.battery)
    arrived = acted & ~pushed & (new_pos != pos) & station_cells(spec)[new_pos]
    durations = draws.swap_time(cfg.swap_time[0], cfg.swap_time[1])
    if arrived.any():
        swap_battery = np.where(arrived, state.battery / cfg.b_max, np.nan)
        state.status = np.where(arrived, SWAPPING, state.status).astype(np.int8, copy=False)
        state.swap_left = np.where(arrived, durations, state.swap_left)
        battery_left = np.where(arrived, np.maximum(state.battery, 1e-9), state.battery)
    else:
        swap_battery = np.full((E, A), np.nan)
        battery_left = state.battery
    # 8. failures: empty battery, then injected faults
    battery_failed = empty = state.battery <= 0                           # (E, A)
    if empty.any():
        battery_failed = acted & ~arrived & empty
        state.status = np.where(battery_failed, FAILED, state.status).astype(np.int8, copy=False)
    fault_failed = _inject_faults(cfg, state, draws)
    # an agent saved by its arrival on the station did not fail: it gets the low-battery penalty
    reward_battery = battery_reward(battery_left, cfg) if compute_reward else None
    if empty.any():
        state.battery = np.maximum(state.battery, 0.0)
    state.t += 1
    # rewards
    if compute_reward:
        f = normalised_idleness(state.idle, state.visited, cfg.c_norm)       # (E, V)
        team, mean_f, max_f = team_patrol_reward(f)
        f_without_k = normalised_idleness(idle_without_k, visited_without_k, cfg.c_norm)
        d = difference_reward(f_without_k, on_vertex, mean_f, max_f, spec.n_vertices)
        reward_patrol = np.where(acted, cfg.c_rp * team[:, None] + cfg.difference_weight * d, 0.0)
        reward_battery = np.where(acted, reward_battery, 0.0)
        reward_collision = (np.where(acted, collision_reward(collided, cfg), 0.0) if collisions.any()
                            else np.zeros((E, A)))
        reward_home = np.zeros((E, A))
        if shaping:
            phi_after = home_potential(spec.steps_home[state.pos], state.battery, cfg, home_scale)
            reward_home = np.where(acted & ~battery_failed & ~fault_failed, phi_after - phi_before, 0.0)
        reward = reward_patrol + reward_battery + reward_collision + reward_home
    else:
        team = np.full(E, np.nan)
        reward = reward_patrol = reward_battery = reward_collision = reward_home = np.zeros((E, A))
    return StepInfo(
        reward=reward, reward_patrol=reward_patrol, reward_battery=reward_battery,
        reward_collision=reward_collision, reward_home=reward_home, acted=acted, pushed=pushed,
        collided=collided, collisions=collisions, swap_started=arrived, swap_battery=swap_battery,
        swap_ended=swap_ended, battery_failed=battery_failed, fault_failed=fault_failed,
        team_patrol=team, mean_idleness=state.idle.sum(axis=1) / state.idle.shape[1],
        max_idleness=state.idle.max(axis=1), truncated=state.t >= cfg.episode_steps,
        terminated=(state.status >= FAILED).all(axis=1))   # every slot failed or absent (ABSENT > FAILED)


def _inject_faults(cfg: EnvConfig, state: State, draws: StepDraws) -> np.ndarray:
    """Fail agents by schedule (cfg.faults) and by chance (cfg.fault_prob). Returns (E, A) bool."""
    E, A = state.pos.shape
    failed = np.zeros((E, A), dtype=bool)
    if cfg.fault_prob <= 0 and not cfg.faults:
        return failed
    if cfg.fault_prob > 0:
        failed |= (state.status == ACTIVE) & (draws.chance_fault < cfg.fault_prob)
    for fault_step, k in cfg.faults:
        hit = state.t == fault_step                                        # (E,)
        if not hit.any():
            continue
        alive = (state.status == ACTIVE) | (state.status == SWAPPING)
        key = np.where(alive, draws.fault_order, np.inf)
        rank = np.argsort(np.argsort(key, axis=1), axis=1)                 # 0 = chosen first
        failed |= hit[:, None] & alive & (rank < k)
    state.status = np.where(failed, FAILED, state.status).astype(np.int8)
    state.swap_left = np.where(failed, 0, state.swap_left)
    return failed
