"""The paper's curriculum of team sizes (docs/model.md, section 7) and its learning-rate drop."""
from __future__ import annotations

from typing import Callable

import numpy as np
from stable_baselines3.common.callbacks import BaseCallback

CURRICULUM = [
    [1, 1, 1, 1, 2, 2, 2, 2],
    [1, 1, 1, 1, 2, 2, 3, 3],
    [1, 1, 1, 1, 2, 3, 3, 4],
    [1, 1, 1, 1, 2, 3, 4, 5],
]
"""Team size of each of the 8 parallel episodes, per stage."""

SWITCH_FRACTIONS = (200 / 1500, 400 / 1500, 600 / 1500)
"""Progress (timesteps done / total) at which stages 1, 2, 3 start: the paper switches at
episodes 200 / 400 / 600 of 1500, scaled to the run's length."""


def curriculum_stage(progress_fraction: float) -> int:
    """The curriculum stage (0 .. 3) at a training progress.

    Args:
        progress_fraction: timesteps done / total timesteps (values beyond [0, 1] are clipped).

    Returns:
        Index into :data:`CURRICULUM`.
    """
    return sum(progress_fraction >= s for s in SWITCH_FRACTIONS)


def lr_schedule(lr: float = 2e-4, lr_late: float = 1e-4, drop_at: float = 2 / 3) -> Callable[[float], float]:
    """The paper's learning rate: ``lr``, then ``lr_late`` after ``drop_at`` of training.

    Args:
        lr: rate at the start.
        lr_late: rate from progress ``drop_at`` on.
        drop_at: fraction of training (0 .. 1) at which the rate drops.

    Returns:
        An SB3 schedule: a function of ``progress_remaining`` (1 at the start, 0 at the end).
    """
    if not 0.0 <= drop_at <= 1.0:
        raise ValueError(f"drop_at must be a fraction of training in [0, 1], got {drop_at}")

    def schedule(progress_remaining: float) -> float:
        return lr if 1.0 - progress_remaining < drop_at else lr_late

    return schedule


def find_set_agents(venv):
    """The innermost-reachable vector env with ``set_agents``, unwrapping VecEnvWrappers
    (VecMonitor, VecNormalize, ...) through ``.venv``.

    Raises:
        TypeError: no env in the chain has ``set_agents`` (not built by make_vec_env).
    """
    env = venv
    while env is not None:
        if "set_agents" in dir(type(env)):
            return env
        env = getattr(env, "__dict__", {}).get("venv")
    raise TypeError(f"the training env {type(venv).__name__} has no set_agents in its wrapper "
                    f"chain; build it with patrolsb3.sb3.make_vec_env")


class CurriculumCallback(BaseCallback):
    """Sets the training env's team sizes to the curriculum stage of the run's progress.

    The stage is recomputed from ``model.num_timesteps`` at training start, so a resumed run
    continues at the right stage. At training start, if the episodes that ``learn`` has just
    reset do not deploy the stage's teams, the env is reset again (and the model's last
    observation with it) so that training never starts on the wrong teams; later stage changes
    apply to each parallel episode from its next reset. Logged as ``curriculum/stage``.

    Args:
        total_timesteps: timesteps of the whole run (progress = num_timesteps / total_timesteps).
        curriculum: team sizes per stage (default :data:`CURRICULUM`); each row must have one
            entry per parallel episode of the training env.
        verbose: SB3 verbosity.
    """

    def __init__(self, total_timesteps: int, curriculum=None, verbose: int = 0):
        super().__init__(verbose)
        if total_timesteps <= 0:
            raise ValueError(f"total_timesteps must be positive, got {total_timesteps}")
        self.total_timesteps = int(total_timesteps)
        self.curriculum = [list(row) for row in (curriculum or CURRICULUM)]
        self.stage = None  # current stage index, None before training starts

    def _stage_now(self) -> int:
        stage = curriculum_stage(self.num_timesteps / self.total_timesteps)
        return min(stage, len(self.curriculum) - 1)

    def _apply(self, stage: int) -> None:
        find_set_agents(self.training_env).set_agents(self.curriculum[stage])
        self.stage = stage
        if self.verbose:
            print(f"curriculum: stage {stage} {self.curriculum[stage]} at {self.num_timesteps} steps")

    def _on_training_start(self) -> None:
        self._apply(self._stage_now())
        env = find_set_agents(self.training_env)
        deployed = env.running_agents()
        if deployed != env.get_agents() and getattr(self.model, "_last_obs", None) is not None:
            self._restart_episodes()
        self.logger.record("curriculum/stage", self.stage)

    def _restart_episodes(self) -> None:
        """Reset the training env so the stage's teams are deployed now, and hand the model
        the new first observation (as ``learn``'s own setup does)."""
        self.model._last_obs = self.training_env.reset()
        self.model._last_episode_starts = np.ones((self.training_env.num_envs,), dtype=bool)
        normalize = self.model.get_vec_normalize_env()
        if normalize is not None:
            self.model._last_original_obs = normalize.get_original_obs()

    def _on_step(self) -> bool:
        stage = self._stage_now()
        if stage != self.stage:
            self._apply(stage)
        self.logger.record("curriculum/stage", self.stage)
        return True
