"""Paired episodes (patrolsb3.core.streams): episode i of a seed meets the same chance under every
strategy, team size and batch."""
import numpy as np

from patrolsb3.core import load_map, make_config, reset_state, step
from patrolsb3.core.maps import STAY
from patrolsb3.core.state import ACTIVE, reset_episodes
from patrolsb3.core.streams import BLOCK, STREAM_SLOTS, EpisodeStreams
from patrolsb3.evaluate import run_episodes


def play(state, spec, cfg, choose, steps):
    """Step ``state`` with moves from ``choose(state)``; returns which slots stayed active throughout."""
    always_active = state.status == ACTIVE
    for _ in range(steps):
        step(spec, cfg, state, choose(state))
        always_active &= state.status == ACTIVE
    return always_active


def test_two_strategies_meet_the_same_starts_wind_and_drains_in_one_episode():
    spec = load_map("A")
    cfg = make_config("A", invalid_action="stay", episode_steps=100)
    random_walk = np.random.default_rng(1)
    # episode 3 of seed 11: alone with 3 agents that stay put, and in a batch of four, with 2 agents that wander
    still = reset_state(spec, cfg, 3, n_envs=1, seed=11, episode_ids=[3])
    moving = reset_state(spec, cfg, [1, 5, 2, 4], n_envs=4, seed=11, episode_ids=[7, 0, 3, 9])
    assert still.pos[0, :2].tolist() == moving.pos[2, :2].tolist()          # the same start cells
    assert np.array_equal(still.battery[0, :2], moving.battery[2, :2])
    assert np.array_equal(still.p_dyn[0, :2], moving.p_dyn[2, :2])
    a = play(still, spec, cfg, lambda s: np.full(s.pos.shape, STAY), 60)
    b = play(moving, spec, cfg, lambda s: random_walk.integers(0, 5, s.pos.shape), 60)
    both = a[0, :2] & b[2, :2]                      # slots that never swapped nor failed in either
    assert both.any()
    # the battery is what chance drained (drain and pushes): the same, whatever the agents did
    np.testing.assert_allclose(still.battery[0, :2][both], moving.battery[2, :2][both])
    # and the next draws are the same: nothing the agents did or the other episodes drew consumed any
    np.testing.assert_array_equal(still.streams.step().world[0, :2], moving.streams.step().world[2, :2])


def test_a_zoo_policy_batch_of_team_sizes_gives_each_size_its_figures_alone(tiny_zoo):
    from patrolsb3 import zoo
    policy = zoo.load("A", "rl-no-msg", zoo_dir=tiny_zoo)
    cfg = zoo.evaluation_config(policy, 200)
    team = np.repeat([1, 2, 3], 2)                                            # (6,)
    ids = np.tile(np.arange(2), 3)                                            # episode j of each size: id j
    together = run_episodes(policy, policy.spec, cfg, team, 6, seed=4, episode_ids=ids)
    alone = run_episodes(policy, policy.spec, cfg, 2, 2, seed=4)
    for metric in ("avg_idleness", "collisions", "battery_failures"):
        np.testing.assert_allclose(together[metric][team == 2], alone[metric], err_msg=metric)


def test_streams_do_not_depend_on_the_block_size_or_the_slots_used():
    five = EpisodeStreams(2, [0, 1], 5)
    twelve = EpisodeStreams(2, [1], 12)
    drawn = [five.step() for _ in range(BLOCK + 3)]                           # across a block boundary
    again = [twelve.step() for _ in range(BLOCK + 3)]
    for mine, theirs in zip(drawn, again):
        np.testing.assert_array_equal(mine.world[1], theirs.world[0, :5])
        np.testing.assert_array_equal(mine.tie_break[1], theirs.tie_break[0, :5])
    assert twelve.drawn_slots == max(12, STREAM_SLOTS)
    assert not np.array_equal(drawn[0].world[0], drawn[0].world[1])           # two episodes, two streams


def test_a_restarted_training_episode_takes_new_streams_and_leaves_the_others_alone():
    spec = load_map("A")
    cfg = make_config("A", invalid_action="stay")
    state = reset_state(spec, cfg, 2, n_envs=3, seed=0)
    other = reset_state(spec, cfg, 2, n_envs=3, seed=0)
    for s in (state, other):
        step(spec, cfg, s, np.full(s.pos.shape, STAY))
    reset_episodes(spec, cfg, state, np.array([1]), 2)
    assert state.streams.ids.tolist() == [0, 4, 2] and state.t.tolist() == [1, 0, 1]
    nxt, ref = state.streams.step(), other.streams.step()
    np.testing.assert_array_equal(nxt.world[[0, 2]], ref.world[[0, 2]])
    first_of_id_4 = EpisodeStreams(0, [4], cfg.max_agents).step()             # the new episode's first step
    np.testing.assert_array_equal(nxt.world[1], first_of_id_4.world[0])
