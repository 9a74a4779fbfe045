"""The curriculum of team sizes, its callback, and the learning-rate drop."""
from __future__ import annotations

import gymnasium as gym
import pytest
import torch
from sb3_contrib import MaskablePPO
from stable_baselines3.common.callbacks import BaseCallback, CallbackList
from stable_baselines3.common.vec_env import DummyVecEnv, VecMonitor

from patrolsb3.core import parse_map
from patrolsb3.sb3 import CURRICULUM, CurriculumCallback, curriculum_stage, lr_schedule, make_vec_env
from patrolsb3.sb3.curriculum import find_set_agents

from conftest import NON_SQUARE

torch.set_num_threads(1)


@pytest.mark.parametrize("progress,stage", [
    (0.0, 0), (199 / 1500, 0), (200 / 1500, 1), (399 / 1500, 1), (400 / 1500, 2),
    (599 / 1500, 2), (600 / 1500, 3), (1.0, 3), (1.2, 3)])
def test_curriculum_stage_switch_points(progress, stage):
    assert curriculum_stage(progress) == stage


def test_curriculum_is_the_papers():
    assert CURRICULUM == [[1, 1, 1, 1, 2, 2, 2, 2], [1, 1, 1, 1, 2, 2, 3, 3],
                          [1, 1, 1, 1, 2, 3, 3, 4], [1, 1, 1, 1, 2, 3, 4, 5]]


def test_lr_schedule_drops_after_two_thirds():
    schedule = lr_schedule()
    assert schedule(1.0) == 2e-4
    assert schedule(0.34) == 2e-4   # 66 % done
    assert schedule(0.33) == 1e-4   # 67 % done
    assert schedule(0.0) == 1e-4
    assert lr_schedule(3e-4, 3e-5, drop_at=0.5)(0.4) == 3e-5
    with pytest.raises(ValueError, match="drop_at"):
        lr_schedule(drop_at=1.5)


class Recorder(BaseCallback):
    """Records the curriculum's stage and the teams the env deploys, at start and each step."""

    def __init__(self, curriculum, venv):
        super().__init__()
        self.curriculum, self.venv = curriculum, venv
        self.start_teams, self.stages, self.logged = None, [], []

    def _deployed(self):
        return self.venv.running_agents()

    def _on_training_start(self):
        self.start_teams = self._deployed()

    def _on_step(self):
        self.stages.append(self.curriculum.stage)
        self.logged.append(self.logger.name_to_value["curriculum/stage"])
        return True


def tiny_model(venv):
    return MaskablePPO("MlpPolicy", venv, n_steps=4, batch_size=160, n_epochs=1, seed=0,
                       policy_kwargs={"net_arch": [16]})


@pytest.fixture
def venv():
    spec = parse_map(NON_SQUARE, name="non_square")
    return make_vec_env(spec, agents=CURRICULUM[-1], variant="rl-no-msg", seed=0, episode_steps=3)


def test_callback_walks_the_stages_and_switches_teams(venv):
    total = 4 * 40 * 8  # 8 rollouts of 4 steps x 40 rows
    model = tiny_model(VecMonitor(venv))
    curriculum = CurriculumCallback(total)
    recorder = Recorder(curriculum, venv)
    model.learn(total, callback=CallbackList([curriculum, recorder]))
    assert recorder.start_teams == CURRICULUM[0]  # restarted at once on the stage-0 teams
    seen = [s for i, s in enumerate(recorder.stages) if i == 0 or s != recorder.stages[i - 1]]
    assert seen == [0, 1, 2, 3]
    assert curriculum.stage == 3
    assert venv.get_agents() == CURRICULUM[3]
    assert venv.running_agents() == CURRICULUM[3]  # episodes of 3 steps
    assert recorder.logged == recorder.stages


def test_resumed_run_starts_at_its_stage(venv):
    total = 1500
    model = tiny_model(venv)
    model.num_timesteps = 500  # a third done: stage 2 (400/1500 <= 1/3 < 600/1500)
    curriculum = CurriculumCallback(total)
    recorder = Recorder(curriculum, venv)
    model.learn(160, callback=CallbackList([curriculum, recorder]), reset_num_timesteps=False)
    assert recorder.stages[0] == 2
    assert recorder.start_teams == CURRICULUM[2]


def test_callback_refuses_an_env_without_set_agents():
    env = DummyVecEnv([lambda: gym.make("CartPole-v1")])
    with pytest.raises(TypeError, match="make_vec_env"):
        find_set_agents(VecMonitor(env))
    with pytest.raises(ValueError, match="total_timesteps"):
        CurriculumCallback(0)
