"""A zoo policy or a heuristic acting in the PettingZoo env from its observations and infos:
the same episode as the evaluation's batched run, recurrent state kept and reset, refusals."""
import numpy as np
import pytest

import patrolsb3
from patrolsb3 import strategies, zoo
from patrolsb3.agents import PettingZooAgent, play_episode
from patrolsb3.core import make_config
from patrolsb3.evaluate import run_episodes

STEPS = 150


def play(env, agent, seed):
    """Idleness after every simulator step, and the collisions, of one episode."""
    obs, infos = env.reset(seed=seed)
    agent.reset()
    idle, collisions = [], 0
    while env.agents:
        stepped = infos[env.agents[0]]["phase"] == patrolsb3.core.protocol.MOVE_PHASE
        obs, rewards, terms, truncs, infos = env.step(agent.act(obs, infos))
        if stepped:
            idle.append(env.core_state.idle[0].copy())
            collisions += infos[next(iter(infos))]["collisions"]
    return np.array(idle), collisions


def test_a_zoo_policy_in_pettingzoo_plays_the_evaluations_episode(tiny_zoo):
    policy = zoo.load("A", "rl-msg", zoo_dir=tiny_zoo)
    env = patrolsb3.parallel_env("A", n_agents=3, episode_steps=STEPS, **policy.env_settings())
    assert env.agents == [] and len(env.possible_agents) == 5
    idle, collisions = play(env, PettingZooAgent(policy, env), seed=4)
    cfg = make_config("A", **{**policy.env_settings(), "episode_steps": STEPS})
    reference = run_episodes(zoo.load("A", "rl-msg", zoo_dir=tiny_zoo), policy.spec, cfg, 3, 1, seed=4)
    assert idle.mean(axis=1).mean() == pytest.approx(reference["avg_idleness"][0], rel=1e-9)
    assert collisions == reference["collisions"][0]
    figures = play_episode(env, PettingZooAgent(policy, env), seed=4)
    assert figures["steps"] == STEPS
    for key in ("avg_idleness", "max_idleness", "worst_idleness", "collisions", "battery_failures"):
        assert figures[key] == pytest.approx(float(reference[key][0]), rel=1e-9), key
    # reset() starts a new episode: the same seed gives the same episode again
    again, _ = play(env, PettingZooAgent(policy, env), seed=4)
    np.testing.assert_array_equal(idle, again)


def test_a_heuristic_in_pettingzoo_plays_the_evaluations_episode():
    env = patrolsb3.parallel_env("C", n_agents=4, episode_steps=STEPS, comm="none")
    cr = strategies.get("CR", env.spec_map, 4, cfg=env.cfg, seed=0)
    idle, collisions = play(env, PettingZooAgent(cr, env), seed=2)
    reference = run_episodes(strategies.get("CR", env.spec_map, 4, cfg=env.cfg, seed=0), env.spec_map,
                             make_config("C", comm="none", episode_steps=STEPS), 4, 1, seed=2)
    assert idle.mean(axis=1).mean() == pytest.approx(reference["avg_idleness"][0], rel=1e-9)
    assert collisions == reference["collisions"][0]


def test_a_heuristic_stays_silent_in_a_message_phase():
    env = patrolsb3.parallel_env("A", n_agents=2, episode_steps=10, comm="learned")
    agent = PettingZooAgent(strategies.get("SEBS", env.spec_map, 2, cfg=env.cfg), env)
    obs, infos = env.reset(seed=0)
    actions = agent.act(obs, infos)
    assert set(actions) == {"drone_0", "drone_1"} and all(a == (0, 4) for a in actions.values())
    env.step(actions)                                            # legal in the message phase


def test_a_policy_refuses_an_env_with_other_observations(tiny_zoo):
    policy = zoo.load("A", "rl-no-msg", zoo_dir=tiny_zoo)
    env = patrolsb3.parallel_env("A", n_agents=2, comm="learned")
    with pytest.raises(ValueError, match="env_settings"):
        PettingZooAgent(policy, env)
