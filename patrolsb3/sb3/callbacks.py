"""Callbacks of a training run: the learning curve CSV and the periodic evaluation."""
from __future__ import annotations

from pathlib import Path

import numpy as np
from stable_baselines3.common.callbacks import BaseCallback

from ..runs import append_csv_rows as append_rows
from .evaluation import METRICS, evaluate, summarize

CURVE_FIELDS = ("timesteps", "n_agents", "reward", "mean_idleness", "max_idleness", "collisions",
                "battery_failures", "sim_steps")
EVAL_FIELDS = ("timesteps", "n_agents", "episodes") + METRICS


class LearningCurveCallback(BaseCallback):
    """One row of ``curve.csv`` per finished parallel episode (from ``team_episode`` infos):
    timesteps, n_agents, team reward (mean over the team's slots), mean / max idleness,
    collisions, battery failures, simulator steps. Appends, so a resumed run continues it.

    Args:
        path: the CSV file.
        max_agents: slots per parallel episode (rows of one episode share its summary).
    """

    def __init__(self, path: str | Path, max_agents: int, verbose: int = 0):
        super().__init__(verbose)
        self.path = Path(path)
        self.max_agents = int(max_agents)
        self.rows_written = 0

    def _on_training_start(self) -> None:
        append_rows(self.path, CURVE_FIELDS, [])    # the file exists (header) before any episode ends

    def _on_step(self) -> bool:
        dones, infos = self.locals["dones"], self.locals["infos"]
        rows, seen = [], set()
        for row in np.flatnonzero(dones):
            episode = row // self.max_agents
            if episode in seen or "team_episode" not in infos[row]:
                continue
            seen.add(episode)
            rows.append({"timesteps": self.num_timesteps, **infos[row]["team_episode"]})
        if rows:
            append_rows(self.path, CURVE_FIELDS, rows)
            self.rows_written += len(rows)
            for key in ("reward", "mean_idleness", "max_idleness"):
                self.logger.record_mean(f"team/{key}", float(np.mean([r[key] for r in rows])))
        return True


class PaperMetricsEvalCallback(BaseCallback):
    """Every ``eval_freq`` timesteps, play the episodes of ``make_eval_env()`` with the
    recurrent evaluation loop; log ``eval/n<k>/<metric>`` and append to ``eval.csv``.

    Args:
        make_eval_env: builds the evaluation vec env (short episodes at 1..5 agents).
        path: the eval CSV.
        eval_freq: timesteps between evaluations (0 disables).
    """

    def __init__(self, make_eval_env, path: str | Path, eval_freq: int, verbose: int = 0):
        super().__init__(verbose)
        self.make_eval_env = make_eval_env
        self.path = Path(path)
        self.eval_freq = int(eval_freq)
        self._next = None
        self._env = None

    def _on_training_start(self) -> None:
        self._next = (self.num_timesteps // self.eval_freq + 1) * self.eval_freq if self.eval_freq > 0 else None

    def _on_step(self) -> bool:
        if self._next is not None and self.num_timesteps >= self._next:
            self._next += self.eval_freq
            self.run_evaluation()
        return True

    def run_evaluation(self) -> list[dict]:
        """Evaluate now; returns the per-team-size summary rows."""
        if self._env is None:
            self._env = self.make_eval_env()
        rows = summarize(evaluate(self.model, self._env, deterministic=True))
        for row in rows:
            row["timesteps"] = self.num_timesteps
            for key in METRICS:
                self.logger.record(f"eval/n{row['n_agents']}/{key}", row[key])
        append_rows(self.path, EVAL_FIELDS, rows)
        return rows
