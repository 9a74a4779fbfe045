"""The CPU time a training run spent, measured by the run itself: ``<run>/cpu_time.csv``.

One row when each rollout starts (the update of the rollout before it done) and one when the
run stops, with its last checkpoint, at most one per agent-step count: the agent-steps reached
and the CPU seconds of the training process (every thread, ``time.process_time``) spent in
``learn()`` so far, counted across ``--resume`` calls. A resumed run first cuts the rows past
the checkpoint it resumes from, so the file always describes the path that led to its
checkpoints. A warm-started run (``--init-from``) records the CPU hours of its source in
``config.yml`` (``init_from.cpu_hours``), so :func:`cpu_hours_of` adds up a chain of stages,
which is what ``patrolsb3 zoo export`` records as the entry's budget.
"""
from __future__ import annotations

import csv
import time

from stable_baselines3.common.callbacks import BaseCallback

from ..runs import RunFolder, append_csv_rows, model_steps

CPU_TIME_FILE = RunFolder.CPU_TIME
FIELDS = ("timesteps", "cpu_seconds")


def read_rows(run_dir) -> list[tuple[int, float]]:
    """The rows of ``run_dir/cpu_time.csv`` as (timesteps, cpu_seconds), [] when there is none."""
    path = RunFolder(run_dir).cpu_time_file
    if not path.is_file():
        return []
    rows = []
    with path.open(newline="") as f:
        for r in csv.DictReader(f):
            try:
                rows.append((int(r["timesteps"]), float(r["cpu_seconds"])))
            except (TypeError, ValueError):        # a line cut by a kill: left out
                continue
    return rows


def cpu_seconds_at(run_dir, timesteps: int) -> float | None:
    """CPU seconds the run had spent when it reached ``timesteps`` (the last row at or before
    it), or None when the run has no record that far."""
    rows = [s for t, s in read_rows(run_dir) if t <= timesteps]
    return rows[-1] if rows else None


def restart_at(run_dir, timesteps: int) -> float:
    """The CPU seconds a run had spent when it reached ``timesteps`` (the checkpoint a resume
    starts from; :meth:`RunFolder.cut_back_to` has cut the rows after it), 0 without a record."""
    seconds = cpu_seconds_at(run_dir, timesteps)
    return 0.0 if seconds is None else seconds


def cpu_hours_of(model_path) -> float | None:
    """CPU hours spent to train a checkpoint (or a run's model.zip), every warm-start stage
    before it included; None when a part of that chain was not measured (a run older than
    this record, or a source without a figure)."""
    run = RunFolder.of_model(model_path)
    steps = model_steps(model_path)
    own = cpu_seconds_at(run.path, steps) if steps is not None else None
    if own is None:
        return None
    config = run.read_config()
    earlier = 0.0
    if config.get("init_from"):
        earlier = config["init_from"].get("cpu_hours")
        if earlier is None:
            return None
    return float(earlier) + own / 3600.0


class CpuTimeCallback(BaseCallback):
    """Appends (timesteps, CPU seconds) to ``cpu_time.csv`` as every rollout starts.

    Args:
        run_dir: the run folder.
        offset_seconds: CPU seconds spent before this call (a resumed run: :func:`restart_at`).
    """

    def __init__(self, run_dir, offset_seconds: float = 0.0, verbose: int = 0):
        super().__init__(verbose)
        self.path = RunFolder(run_dir).cpu_time_file
        self.offset = float(offset_seconds)
        rows = read_rows(run_dir)
        self.last_timesteps = rows[-1][0] if rows else -1     # a resume starts at its checkpoint's row
        self.started = time.process_time()

    def _on_training_start(self) -> None:
        self.started = time.process_time()

    def _on_step(self) -> bool:
        return True

    def _on_rollout_start(self) -> None:
        self.record(self.num_timesteps)

    def record(self, timesteps: int) -> None:
        """Append one row: ``timesteps`` and the CPU seconds spent so far; none when a row
        already holds these agent-steps (a resumed run's first rollout starts at its
        checkpoint, whose row the run before it wrote)."""
        if timesteps <= self.last_timesteps:
            return
        self.last_timesteps = int(timesteps)
        append_csv_rows(self.path, FIELDS, [{"timesteps": int(timesteps),
                                             "cpu_seconds": round(self.offset + time.process_time() - self.started, 3)}])
