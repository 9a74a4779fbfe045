"""Invariants over long random runs, and the batched core equal to the PettingZoo env step for step.

The runs use a small battery, short swaps and strong wind so that pushes, collisions, swaps and
battery failures all happen within a few hundred steps; each test checks that they did.
"""
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import patrolsb3
from patrolsb3.core import action_mask, load_map, make_config, reset_state, step
from patrolsb3.core.maps import OBSTACLE, STATION
from patrolsb3.core.protocol import MESSAGE_PHASE
from patrolsb3.core.state import ABSENT, ACTIVE, FAILED, SWAPPING

STRESS = dict(b_max=60.0, swap_time=(3, 8), p_dyn_max=0.3, episode_steps=10**6)
DELTAS = [(-1, 0), (1, 0), (0, -1), (0, 1), (0, 0)]   # Up, Down, Left, Right, Stay


def random_valid_moves(mask, rng):
    """(E, A) random moves among the True entries of an (E, A, 5) mask."""
    return np.argmax(rng.random(mask.shape) * mask, axis=-1)


def wandering_moves(spec, state, mask, rng, p_home=0.3):
    """Random valid moves, but with probability p_home the first step toward the station
    (when the mask allows it), so that swaps happen even on maps with a remote station."""
    home = spec.first_action(state.pos, spec.station)                         # (E, A)
    home_ok = np.take_along_axis(mask, home[..., None].astype(np.int64), axis=-1)[..., 0]
    go_home = home_ok & (rng.random(home.shape) < p_home)
    return np.where(go_home, home, random_valid_moves(mask, rng))


def expected_mask(spec, state, e, k):
    """The mask of slot k of episode e rebuilt from the grid by row / column arithmetic."""
    H, W = spec.shape
    if state.status[e, k] != ACTIVE:
        return [False] * 4 + [True]
    r, c = divmod(int(state.pos[e, k]), W)
    others = {int(state.pos[e, j]) for j in range(state.pos.shape[1])
              if j != k and state.status[e, j] == ACTIVE}
    out = []
    for dr, dc in DELTAS:
        rr, cc = r + dr, c + dc
        ok = 0 <= rr < H and 0 <= cc < W and spec.kinds[rr, cc] != OBSTACLE
        if ok and (dr, dc) != (0, 0):
            ok = spec.kinds[rr, cc] == STATION or rr * W + cc not in others
        out.append(bool(ok))
    return out


def check_invariants(spec, cfg, state, info):
    E, A = state.pos.shape
    kinds = spec.kinds.ravel()
    active = state.status == ACTIVE
    for e in range(E):
        cells = state.pos[e][active[e] & (kinds[state.pos[e]] != STATION)]
        assert len(cells) == len(set(cells.tolist())), "two active agents share a cell"
        # idleness is zero exactly on the vertices where agents that acted now stand
        stood = {int(spec.vertex_of_cell[p]) for p, a in zip(state.pos[e], info.acted[e])
                 if a and spec.vertex_of_cell[p] >= 0}
        assert set(np.flatnonzero(state.idle[e] == 0).tolist()) == stood
        assert all(state.idle[e, spec.vertex_of_cell[p]] == 0
                   for p in state.pos[e][active[e]] if spec.vertex_of_cell[p] >= 0)
    assert (state.battery >= 0).all() and (state.battery <= cfg.b_max).all()
    assert (kinds[state.pos] != OBSTACLE).all()
    assert (state.pos[state.status == SWAPPING] == spec.station).all()
    assert (state.swap_left[state.status == SWAPPING] >= 1).all()
    assert (state.swap_left[state.status == SWAPPING] <= cfg.swap_time[1]).all()
    assert (info.reward[~info.acted] == 0).all()
    assert (info.collisions <= info.collided.sum(axis=1)).all()
    # every event involves two agents or more; one agent can be in two swapped pairs only when
    # the other two stand together on a station and both head for its cell (seed 8001, map A)
    assert (info.collided.sum(axis=1) >= 2 * (info.collisions > 0)).all()


@pytest.mark.parametrize("map_name", ["A", "B", "C", "D"])
def test_invariants_over_a_long_random_run(map_name):
    spec = load_map(map_name)
    cfg = make_config(map_name, max_agents=5, **STRESS)
    rng = np.random.default_rng(7)
    state = reset_state(spec, cfg, [5, 4, 3, 2, 1, 5], n_envs=6, seed=11)
    absent = state.status == ABSENT
    seen = dict(collisions=0, swaps=0, swap_ends=0, failures=0, pushes=0)
    previous = state.status.copy()
    for t in range(400):
        mask = action_mask(spec, state)
        for e in range(state.n_envs):
            for k in range(cfg.max_agents):
                assert list(mask[e, k]) == expected_mask(spec, state, e, k)
        info = step(spec, cfg, state, wandering_moves(spec, state, mask, rng))
        check_invariants(spec, cfg, state, info)
        # absent slots stay absent, failed ones stay failed
        assert (state.status[absent] == ABSENT).all()
        assert (state.status[previous == FAILED] == FAILED).all()
        previous = state.status.copy()
        seen["collisions"] += int(info.collisions.sum())
        seen["swaps"] += int(info.swap_started.sum())
        seen["swap_ends"] += int(info.swap_ended.sum())
        seen["failures"] += int(info.battery_failed.sum())
        seen["pushes"] += int(info.pushed.sum())
    assert all(v > 0 for v in seen.values()), seen


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2**31 - 1), map_name=st.sampled_from(["A", "B", "C", "D"]),
       n_agents=st.integers(1, 5), p_dyn_max=st.floats(0.0, 1.0))
def test_invariants_hold_for_any_seed_and_wind(seed, map_name, n_agents, p_dyn_max):
    spec = load_map(map_name)
    cfg = make_config(map_name, **{**STRESS, "p_dyn_max": p_dyn_max})
    rng = np.random.default_rng(seed)
    state = reset_state(spec, cfg, n_agents, n_envs=4, seed=seed)
    for _ in range(60):
        mask = action_mask(spec, state)
        info = step(spec, cfg, state, wandering_moves(spec, state, mask, rng))
        check_invariants(spec, cfg, state, info)


@pytest.mark.parametrize("map_name, comm", [("A", "none"), ("D", "learned"), ("B", "intention")])
def test_batched_core_equals_the_pettingzoo_env_step_for_step(map_name, comm):
    overrides = dict(b_max=80.0, swap_time=(3, 8), p_dyn_max=0.2, episode_steps=250, comm=comm)
    spec = load_map(map_name)
    cfg = make_config(map_name, **overrides)
    env = patrolsb3.parallel_env(map_name, n_agents=4, **overrides)
    obs, infos = env.reset(seed=123)
    team = list(env.agents)                            # the 4 deployed slots
    state = reset_state(spec, cfg, 4, n_envs=1, seed=123)
    rng = np.random.default_rng(0)
    A = cfg.max_agents
    n_sim_steps, events = 0, 0
    while env.agents:
        assert np.array_equal(env.core_state.pos, state.pos)
        symbols = np.zeros(A, dtype=np.int64)
        if infos["drone_0"]["phase"] == MESSAGE_PHASE:
            actions = {}
            for i, a in enumerate(env.agents):
                allowed = np.flatnonzero(infos[a]["action_mask"][0])
                actions[a] = (int(rng.choice(allowed)), 4)
                symbols[i] = actions[a][0] + 1 if state.status[0, i] == ACTIVE else 0
            obs, rewards, terms, truncs, infos = env.step(actions)
        mask = action_mask(spec, state)[0]
        moves = np.full(A, 4, dtype=np.int64)          # slots beyond the team: Stay
        actions = {}
        for i, a in enumerate(env.agents):
            assert list(infos[a]["action_mask"][1]) == list(mask[i].astype(np.int8))
            moves[i] = rng.choice(np.flatnonzero(mask[i]))
            actions[a] = (0, int(moves[i]))
        obs, rewards, terms, truncs, infos = env.step(actions)
        info = step(spec, cfg, state, moves[None], messages=symbols[None])
        n_sim_steps += 1
        events += int(info.collisions[0]) + int(info.swap_started.sum()) + int(info.battery_failed.sum())
        assert np.array_equal(env.core_state.pos, state.pos)
        assert np.array_equal(env.core_state.status, state.status)
        assert np.array_equal(env.core_state.battery, state.battery)
        assert np.array_equal(env.core_state.idle, state.idle)
        assert [rewards[a] for a in team] == list(info.reward[0, :len(team)])
        assert (info.reward[0, len(team):] == 0).all()
        assert [infos[a]["collided"] for a in team] == list(info.collided[0, :len(team)])
        grid = np.stack([obs[a]["grid"] for a in team])
        shown = state.copy()
        if comm != "none":
            shown.messages[:] = 0          # same-step symbols are cleared after the move phase
        assert np.array_equal(grid, patrolsb3.core.actor_observation(spec, cfg, shown)[0][0, :len(team)])
        if any(terms.values()):
            break
    assert n_sim_steps >= 50 and events > 0


@pytest.mark.slow
@pytest.mark.parametrize("map_name", ["A", "B", "C", "D"])
def test_invariants_over_a_million_steps_per_map(map_name):
    """1,000 episodes x 1,000 steps of stress settings (pushes, short batteries, faults): the
    cheap invariants every step, the full check every 50 (run with ``pytest -m slow``)."""
    spec = load_map(map_name)
    cfg = make_config(map_name, **{**STRESS, "fault_prob": 1e-4})
    rng = np.random.default_rng(1)
    state = reset_state(spec, cfg, np.arange(1000) % 5 + 1, n_envs=1000, seed=1)
    kinds = spec.kinds.ravel()
    for t in range(1000):
        mask = action_mask(spec, state)
        info = step(spec, cfg, state, wandering_moves(spec, state, mask, rng))
        assert (state.battery >= 0).all() and (state.battery <= cfg.b_max).all()
        assert (kinds[state.pos] != OBSTACLE).all() and np.isfinite(info.reward).all()
        assert (info.collisions <= info.collided.sum(axis=1)).all()
        if t % 50 == 0:
            check_invariants(spec, cfg, state, info)
