"""Heuristics: their rules on hand-built cases, valid moves everywhere, batteries and bounds."""
import numpy as np
import pytest

from patrolsb3 import strategies
from patrolsb3.core import ABSENT, action_mask, load_map, make_config, parse_map, reset_state, step
from patrolsb3.core.metrics import EpisodeMetrics, idleness_lower_bounds
from patrolsb3.strategies.cyclic import build_tour
from patrolsb3.strategies.navigation import patrol_distances
from patrolsb3.strategies.part import BALANCE_TOLERANCE, _connected, partition, vertex_adjacency
from patrolsb3.strategies.sebs import G1, intention_discount, sebs_g2, sebs_probability

NAMES = ["RANDOM", "CR", "PART", "SEBS", "CYCLIC"]
CALM = dict(p_dyn_max=0.0, b_max=1e9, init_battery=(1.0, 1.0))


def run(policy, spec, cfg, sim, n_steps):
    memory = None
    for _ in range(n_steps):
        actions, memory = policy.predict(sim, memory)
        yield actions, step(spec, cfg, sim, actions[..., 1], messages=actions[..., 0],
                            compute_reward=False)


def test_registry_names_and_errors():
    spec = load_map("A")
    assert strategies.names() == NAMES
    assert isinstance(strategies.get("sebs", spec, 3), strategies.SEBSPolicy)
    with pytest.raises(ValueError, match="RANDOM, CR, PART, SEBS, CYCLIC"):
        strategies.get("greedy", spec, 3)
    with pytest.raises(ValueError, match="max_agents=5"):
        strategies.get("CR", spec, 6)


def test_cr_one_agent_corridor_sweeps_back_and_forth():
    # corridor of 7 vertices, the station above the middle one (CR never enters it);
    # priorities rise to the right so that the first choice (a tie of remembered times,
    # "last seen at the start" for both) is decided by the rates
    spec = parse_map("###S###\n1234567")
    cfg = make_config(None, max_agents=1, **CALM)
    sim = reset_state(spec, cfg, 1, n_envs=1, seed=0)
    sim.pos[0, 0] = spec.vertex_cells[0]
    visited = [int(spec.vertex_of_cell[sim.pos[0, 0]])]
    for _ in run(strategies.get("CR", spec, 1, cfg), spec, cfg, sim, 18):
        visited.append(int(spec.vertex_of_cell[sim.pos[0, 0]]))
    # remembered idleness is highest ahead until the end, then behind: a sweep
    assert visited == [0, 1, 2, 3, 4, 5, 6, 5, 4, 3, 2, 1, 0, 1, 2, 3, 4, 5, 6]


def test_sebs_formula_and_decision_by_hand():
    assert sebs_probability([0.0, 50.0, 200.0, 250.0], 0.1, 200.0) == pytest.approx(
        [0.1, 0.1 * 10 ** 0.25, 1.0, 1.0])
    assert intention_discount([0, 1, 2], 3) == pytest.approx([1.0, 4 / 7, 2 / 7])
    # agent 1 stands between vertex L (idleness 50) and vertex R (idleness 44);
    # agent 0, deciding first, stands beyond L and can only move onto L.
    spec = parse_map("S####\n.....")
    cfg = make_config(None, max_agents=2, **CALM)
    g2 = sebs_g2(spec)
    assert g2 == 5.0
    sim = reset_state(spec, cfg, 2, n_envs=2, seed=0)
    v = spec.vertex_cells
    sim.pos[:] = [[v[0], v[2]], [v[4], v[2]]]
    sim.idle[:] = [0.0, 4.0, 0.0, 3.6, 0.0]
    policy = strategies.get("SEBS", spec, 2, cfg)
    actions, _ = policy.predict(sim)
    p_left, p_right = sebs_probability([4.0, 3.6], G1, g2)
    # episode 0: agent 0 announces L, so P(L) = P(4.0) * 2^(2-1)/(2^2-1) < P(3.6): go right
    assert p_left * 2 / 3 < p_right < p_left
    assert actions[0, 0, 1] == 3 and actions[0, 1, 1] == 3
    # episode 1: agent 0 stands beyond R and announces R, so agent 1 takes L (undiscounted)
    assert actions[1, 0, 1] == 2 and actions[1, 1, 1] == 2


@pytest.mark.parametrize("map_name", ["A", "B", "C", "D"])
def test_part_partitions_connected_covering_balanced(map_name):
    spec = load_map(map_name)
    adjacency = vertex_adjacency(spec)
    for k in range(1, 6):
        owner = partition(spec, k)
        assert owner.shape == (spec.n_vertices,) and set(owner.tolist()) == set(range(k))
        for i in range(k):
            assert _connected(set(np.flatnonzero(owner == i).tolist()), adjacency)
        load = np.bincount(owner, weights=spec.rate, minlength=k)
        assert np.abs(load / (spec.rate.sum() / k) - 1).max() <= BALANCE_TOLERANCE


@pytest.mark.parametrize("map_name", ["A", "B", "C", "D"])
def test_cyclic_tour_visits_every_vertex(map_name):
    spec = load_map(map_name)
    tour = build_tour(spec)
    assert sorted(tour.tolist()) == list(range(spec.n_vertices))
    vf = spec.free_index[spec.vertex_cells[tour]]
    length = patrol_distances(spec)[vf, np.roll(vf, -1)].sum()
    # no shorter than one step per vertex, no longer than walking around a spanning tree
    assert spec.n_vertices <= length <= 2 * (spec.n_vertices - 1)


@pytest.mark.parametrize("map_name", ["A", "B", "C", "D"])
def test_cyclic_one_agent_matches_its_tour_length(map_name):
    spec = load_map(map_name)
    cfg = make_config(map_name, episode_steps=10**9, **CALM)
    policy = strategies.get("CYCLIC", spec, 1, cfg)
    L = policy.length
    sim = reset_state(spec, cfg, 1, n_envs=1, seed=2)
    metrics = EpisodeMetrics(1, spec.n_vertices)
    for _, info in run(policy, spec, cfg, sim, 12 * L):
        metrics.update(sim, info)
    r = metrics.result()
    # uniform rates would give worst = L - 1 and MAX^h = (L - 1) / 2; priorities multiply
    rates = spec.rate
    flat = parse_map(spec.to_text().translate(str.maketrans("123456789", "." * 9)))
    policy_flat = strategies.get("CYCLIC", flat, 1, cfg)
    sim = reset_state(flat, cfg, 1, n_envs=1, seed=2)
    metrics = EpisodeMetrics(1, flat.n_vertices)
    for _, info in run(policy_flat, flat, cfg, sim, 12 * L):
        metrics.update(sim, info)
    r = metrics.result()
    assert L - 1 <= r["worst_idleness"][0] <= L + 30
    assert r["max_idleness"][0] == pytest.approx((L - 1) / 2, rel=0.08)
    assert rates.min() == 1.0


@pytest.mark.parametrize("map_name", ["A", "B", "C", "D"])
def test_moves_valid_and_inactive_slots_stay(map_name):
    spec = load_map(map_name)
    cfg = make_config(map_name, b_max=150.0, swap_time=(5, 10))   # frequent swaps
    for name in NAMES:
        sim = reset_state(spec, cfg, [1, 3, 5, 2], n_envs=4, seed=5)
        policy = strategies.get(name, spec, 5, cfg, seed=5)
        memory = None
        for _ in range(150):
            actions, memory = policy.predict(sim, memory)
            mask = action_mask(spec, sim)
            assert np.take_along_axis(mask, actions[..., 1:], axis=-1).all(), name
            assert (actions[..., 1][sim.status != 0] == 4).all() and (actions[..., 0] == 0).all()
            step(spec, cfg, sim, actions[..., 1], compute_reward=False)   # raises on invalid
        assert (sim.status[0, 1:] == ABSENT).all()


def battery_failure_rates(map_name, n_envs, n_steps):
    spec = load_map(map_name)
    cfg = make_config(map_name, episode_steps=n_steps)
    rates = {}
    for name in NAMES:
        sim = reset_state(spec, cfg, np.arange(n_envs) % 5 + 1, n_envs=n_envs, seed=11)
        failed = np.zeros(n_envs, dtype=bool)
        for _, info in run(strategies.get(name, spec, 5, cfg, seed=11), spec, cfg, sim, n_steps):
            failed |= info.battery_failed.any(axis=1)
        rates[name] = failed.mean()
    return rates


@pytest.mark.parametrize("map_name", ["A", "B", "C", "D"])
def test_battery_failures_near_zero_short(map_name):
    rates = battery_failure_rates(map_name, n_envs=20, n_steps=2000)   # two recharges
    print(map_name, rates)
    assert max(rates.values()) <= 0.1, rates


@pytest.mark.slow
@pytest.mark.parametrize("map_name", ["A", "B", "C", "D"])
def test_battery_failures_near_zero_full(map_name):
    rates = battery_failure_rates(map_name, n_envs=100, n_steps=14400)
    print(map_name, rates)
    assert max(rates.values()) <= 0.05, rates


@pytest.mark.parametrize("map_name", ["A", "B", "C", "D"])
def test_no_strategy_beats_the_lower_bound(map_name):
    flat = parse_map(load_map(map_name).to_text().translate(str.maketrans("123456789", "." * 9)),
                     name=map_name)
    cfg = make_config(map_name, episode_steps=600)
    teams = np.repeat(np.arange(1, 6), 2)
    for name in NAMES:
        sim = reset_state(flat, cfg, teams, n_envs=len(teams), seed=4)
        metrics = EpisodeMetrics(len(teams), flat.n_vertices)
        for _, info in run(strategies.get(name, flat, 5, cfg, seed=4), flat, cfg, sim, 600):
            metrics.update(sim, info)
        r = metrics.result()
        for e, k in enumerate(teams):
            b = idleness_lower_bounds(flat.n_vertices, int(k), 600)
            assert r["avg_idleness"][e] >= b["avg"] - 1e-9, (name, k)
            assert r["max_idleness"][e] >= b["avg"] - 1e-9, (name, k)
            assert r["worst_idleness"][e] >= b["worst"], (name, k)


@pytest.mark.parametrize("name", NAMES)
def test_patrolling_agent_gives_way_to_an_agent_heading_home(name):
    # dead-end corridor S-a-b-c-d: agent 0 (full battery) stands next to the station, agent 1
    # (battery low, heading home) right behind it. Without the right-of-way rule agent 0 has
    # no patrol move (station ahead, agent 1 behind) and both wait until agent 1 fails.
    spec = parse_map("S....")
    cfg = make_config(None, max_agents=2, p_dyn_max=0.0, init_battery=(1.0, 1.0))
    sim = reset_state(spec, cfg, 2, n_envs=1, seed=0)
    sim.pos[0] = [1, 2]
    sim.battery[0, 1] = cfg.b_low - 5.0
    policy = strategies.get(name, spec, 2, cfg, seed=0)
    actions, memory = policy.predict(sim, None)
    assert memory["returning"][0].tolist() == [False, True]
    assert actions[0, 0, 1] == 2          # agent 0 backs onto the station (Left): its only way out
    for _, info in run(policy, spec, cfg, sim, 10):
        assert not info.battery_failed.any()
    assert (sim.status[0] == 1).all()     # both are swapping batteries now


@pytest.mark.parametrize("name", NAMES)
def test_a_corridor_full_of_patrolling_agents_empties_for_an_agent_heading_home(name):
    # the station ends a one-cell corridor (1,0)-(2,0) that opens at (3,0); patrolling agents
    # fill the corridor and its mouth, and the agent heading home waits at (3,1). The agent at
    # the mouth cannot move at all, so the ones behind it must give way (onto the station).
    spec = parse_map("S####\n.####\n.####\n.....")
    cfg = make_config(None, max_agents=4, p_dyn_max=0.0, init_battery=(1.0, 1.0), swap_time=(80, 80))
    sim = reset_state(spec, cfg, 4, n_envs=1, seed=0)
    sim.pos[0] = [5, 10, 15, 16]                    # (1,0), (2,0), (3,0) patrol; (3,1) heads home
    sim.battery[0, 3] = cfg.b_low - 5.0
    swapped = False
    for _ in run(strategies.get(name, spec, 4, cfg, seed=0), spec, cfg, sim, 30):
        swapped |= sim.status[0, 3] == 1
    assert swapped and not (sim.status[0] == 2).any()


def test_a_heuristic_built_for_another_map_refuses_the_state():
    policy = strategies.get("CR", load_map("A"), 2, make_config("A"), seed=0)
    sim = reset_state(load_map("C"), make_config("C"), [2], n_envs=1, seed=0)
    with pytest.raises(ValueError, match="was built for map A"):
        policy.predict(sim)
