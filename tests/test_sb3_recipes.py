"""Recipes: ``paper`` trains with every value of the paper's tables and its rollout (one whole
episode of the 8 parallel episodes per update, 50 minibatches), its budget is 1,500 episodes
of 5,000 steps, and a run with it builds the paper's rollout."""
import pytest

from patrolsb3.core.config import make_config
from patrolsb3.sb3.hyperparams import merge
from patrolsb3.sb3.recipes import RECIPES, paper_budget, recipe
from patrolsb3.sb3.train import algorithm_kwargs, resolve_settings, rollout_env_steps


def test_the_paper_recipe_has_every_value_of_the_papers_tables():
    settings = resolve_settings("A", "rl-msg", merge(recipe("paper"), {"timesteps": 1000}))
    hp, cfg = settings.hyperparams, settings.env
    # Table "MAPPO hyperparameters"
    assert (hp["gamma"], hp["gae_lambda"], hp["clip_range"], hp["n_epochs"], hp["ent_coef"]) == (0.95, 0.95, 0.15, 3, 0.002)
    assert hp["n_minibatches"] == 50 and hp["n_steps"] == "episode"
    assert hp["learning_rate"] == "drop_2e-4_1e-4" and hp["curriculum"] is True and hp["n_envs"] == 8
    assert settings.teams[-1] == [1, 1, 1, 1, 2, 3, 4, 5] and settings.start_teams == [1, 1, 1, 1, 2, 2, 2, 2]
    # Tables "reward parameters" and "environment parameters", section "Model Training"
    assert cfg.episode_steps == 5000 and tuple(cfg.init_battery) == (0.9, 1.0)
    assert cfg.difference_weight == 10.0 and cfg.max_agents == 5
    assert (cfg.c_norm, cfg.c_rp, cfg.c_pb, cfg.c_pbm, cfg.c_pbb, cfg.c_pc) == (200.0, 0.5, 50.0, 20.0, 1.0, 1.0)
    assert make_config("B").c_pbb == 0.5
    assert cfg.c_home == 0.0 and cfg.local_idleness is False and cfg.message_encoding == "scalar"
    assert hp["normalize_reward"] is False and hp["policy_kwargs"]["dense_sizes"] == [512, 341, 227]
    assert hp["policy_kwargs"]["conv_channels"] == [4, 8]


def test_the_zoo_recipe_differs_where_the_docs_say():
    stage2 = resolve_settings("A", "rl-msg", merge(recipe("zoo-stage2"), {"timesteps": 1000}))
    assert stage2.env.difference_weight == 200.0 and stage2.hyperparams["gamma"] == 0.99
    assert stage2.hyperparams["curriculum"] is False and stage2.env.episode_steps == 1500
    assert set(RECIPES) == {"default", "paper", "zoo-stage1", "zoo-stage2"}
    with pytest.raises(ValueError, match="unknown recipe 'papers'; known: default, paper"):
        recipe("papers")


def test_the_papers_budget_is_1500_episodes_of_5000_steps():
    assert paper_budget(2) == 75_000_000          # 937,500 steps of the 8 episodes x 40 rows x 2 phases
    assert paper_budget(1) == 37_500_000
    assert paper_budget(2) // (40 * 2) == 937_500


def test_a_paper_rollout_is_one_whole_episode_of_every_row():
    assert rollout_env_steps("episode", 5000, 2) == 10_000 and rollout_env_steps(256, 5000, 2) == 256
    from patrolsb3.sb3.algorithms import get_algorithm
    from patrolsb3.sb3.vec_env import make_vec_env
    hp = resolve_settings("A", "rl-msg", merge(recipe("paper"), {"timesteps": 1000, "env": {"episode_steps": 30}}))
    env = make_vec_env("A", agents=[1] * 8, variant="rl-msg", seed=0, episode_steps=30)
    kwargs = algorithm_kwargs(hp.hyperparams, get_algorithm("MaskableRecurrentPPO"), env.layout,
                              env.phases_per_step, env.num_envs, episode_steps=30)
    assert kwargs["n_steps"] == 60 and kwargs["n_minibatches"] == 50
    env.close()


def test_n_steps_takes_a_count_or_episode_and_nothing_else():
    with pytest.raises(ValueError, match="n_steps must be a whole number >= 2 or 'episode', got 'episodes'"):
        resolve_settings("A", "rl-msg", {"timesteps": 1000, "n_steps": "episodes"})
