"""A training run killed (SIGKILL) at random moments, again and again, checkpoint writes
included, always resumes: no run is lost, at most one checkpoint interval of work is redone,
the curve's steps never go back (slow: run with
``python -m pytest -m slow tests/test_kill_resume.py``)."""
import csv
import os
import signal
import subprocess
import sys

import numpy as np
import pytest

from patrolsb3.runs import RunFolder, model_steps

ROOM = "S.....\n......\n..5...\n......"
CHECKPOINT_FREQ = 800
ARGS = ["--variant", "rl-msg", "--timesteps", "100000", "--checkpoint-freq", str(CHECKPOINT_FREQ), "--eval-freq", "0",
        "--no-progress", "--device", "cpu", "--set", "n_steps=10", "env.episode_steps=5",
        "policy_kwargs.dense_sizes=[16,16]", "policy_kwargs.lstm_hidden_size=8"]


def reached(run: RunFolder) -> int:
    """The most agent-steps the run's records show it reached (cpu_time.csv at every rollout
    start, curve.csv at every finished episode)."""
    steps = [0]
    for path in (run.cpu_time_file, run.curve_file):
        if path.is_file():
            with path.open() as f:
                steps += [int(r["timesteps"]) for r in csv.DictReader(f) if (r.get("timesteps") or "").isdigit()]
    return max(steps)


@pytest.mark.slow
def test_sigkill_at_random_moments_never_loses_the_run(tmp_path):
    (tmp_path / "room.txt").write_text(ROOM)
    command = [sys.executable, "-c", "from patrolsb3.cli import main; raise SystemExit(main())", "train",
               "--map", str(tmp_path / "room.txt"), "--out", str(tmp_path / "runs"), *ARGS]
    rng = np.random.default_rng(0)
    kills = 0
    redone = []
    for attempt in range(30):
        run = tmp_path / "runs" / "room" / "rl-msg" / "MaskableRecurrentPPO_seed0"
        resume = ["--resume"] if list((run / "checkpoints").glob("model_*_steps.zip")) else []
        proc = subprocess.Popen(command + resume, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        try:
            proc.wait(timeout=float(rng.uniform(4.0, 9.0)))      # startup ~3 s, then checkpoints every ~0.5 s
        except subprocess.TimeoutExpired:
            os.kill(proc.pid, signal.SIGKILL)
            proc.wait()
            kills += 1
            folder = RunFolder(run)
            newest = folder.newest_checkpoint()
            if newest is not None:      # the work a resume redoes: from its checkpoint to where the kill hit
                redone.append(reached(folder) - model_steps(newest))
            continue
        assert proc.returncode == 0, proc.stderr.read().decode()[-2000:]
        break
    else:
        pytest.fail(f"the run did not finish in 30 attempts ({kills} kills)")
    assert kills >= 2
    assert redone and max(redone) <= CHECKPOINT_FREQ, redone       # at most one checkpoint interval
    assert (run / "model.zip").is_file()
    with (run / "curve.csv").open() as f:
        steps = [int(r["timesteps"]) for r in csv.DictReader(f)]
    assert steps == sorted(steps)                                  # never goes back
