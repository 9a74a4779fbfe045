"""Choosing a run's checkpoint: every checkpoint found, validated greedily, ranked."""
import math

import numpy as np
import pytest
import torch

from patrolsb3 import cli, zoo
from patrolsb3.zoo.validation import rank, run_checkpoints, validate
from patrolsb3.core import load_map, make_config, reset_state
from patrolsb3.runs import model_steps
from patrolsb3.sb3.train import train

torch.set_num_threads(1)


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """A tiny real run on a 4 x 6 room with checkpoints at 400 and 800 steps."""
    root = tmp_path_factory.mktemp("ckpt")
    map_file = root / "room.txt"
    map_file.write_text("S.....\n......\n..#...\n......\n")
    hp = {"n_steps": 16, "n_minibatches": 2, "n_envs": 2, "eval_freq": 0, "checkpoint_freq": 400,
          "env": {"episode_steps": 20}, "policy_kwargs": {"dense_sizes": [32, 16], "lstm_hidden_size": 8}}
    return train(map=str(map_file), variant="rl-no-msg", timesteps=800, run_dir=root / "run", hyperparams=hp,
                 progress_bar=False)


def test_every_checkpoint_in_step_order_then_the_final_model(run, tmp_path):
    import shutil
    paths = run_checkpoints(run)
    steps = [int(p.name.split("_")[1]) for p in paths]
    assert len(steps) >= 2 and steps == sorted(steps) and steps[-1] == 800
    assert all(p.name == f"model_{s}_steps.zip" for p, s in zip(paths, steps))
    assert model_steps(run / "model.zip") == 800          # the same model as the last checkpoint: once
    copy = tmp_path / "copy"
    shutil.copytree(run, copy)
    (copy / "checkpoints" / "model_800_steps.zip").unlink()
    assert [p.name for p in run_checkpoints(copy)][-2:] == ["model_400_steps.zip", "model.zip"]
    with pytest.raises(FileNotFoundError, match="no checkpoints"):
        run_checkpoints(tmp_path / "nothing")


def test_load_checkpoint_acts_like_the_zoo_export_of_it(run, tmp_path):
    from_run = zoo.load_checkpoint(run / "model.zip")
    zoo.export(run, zoo_dir=tmp_path / "zoo")
    exported = zoo.load("ROOM", "rl-no-msg", zoo_dir=tmp_path / "zoo", spec=from_run.spec)
    assert from_run.info["timesteps"] == 800 and from_run.cfg == exported.cfg
    sim = reset_state(from_run.spec, make_config(None, episode_steps=30), [1, 3], n_envs=2, seed=2)
    a, _ = from_run.predict(sim, episode_start=np.ones(2, bool))
    b, _ = exported.predict(sim, episode_start=np.ones(2, bool))
    np.testing.assert_array_equal(a, b)


def test_load_checkpoint_errors_name_the_file(run, tmp_path):
    with pytest.raises(zoo.ZooError, match="no checkpoint at"):
        zoo.load_checkpoint(tmp_path / "missing.zip")
    stray = tmp_path / "model.zip"
    stray.write_bytes(b"junk")
    with pytest.raises(zoo.ZooError, match="no config.yml"):
        zoo.load_checkpoint(stray)
    bad = run / "checkpoints" / "model_1_steps.zip"
    bad.write_bytes(b"not a zip")
    try:
        with pytest.raises(zoo.ZooError, match="empty, cut or corrupt"):
            zoo.load_checkpoint(bad)
    finally:
        bad.unlink()
    big = tmp_path / "big.txt"
    big.write_text("S.......\n........\n........\n........\n")
    with pytest.raises(zoo.ZooError, match="cannot act on"):
        zoo.load_checkpoint(run / "model.zip", spec=load_map(big))


def test_validate_counts_failures_like_the_evaluation(run):
    row = validate(run / "model.zip", team_sizes=(1, 2), episodes=2, steps=40, seed=3)
    assert row["timesteps"] == 800 and 0.0 <= row["bf_rate"] <= 1.0 and row["avg_idleness"] > 0
    # 40 steps from 90-100 % batteries: nobody can run out
    assert row["failures"] == 0.0
    assert math.isnan(row["swap_battery"]) or 0.0 <= row["swap_battery"] <= 1.0


def test_rank_puts_fewer_failures_before_lower_idleness():
    rows = [{"checkpoint": "a", "failures": 0.5, "avg_idleness": 10.0},
            {"checkpoint": "b", "failures": 0.0, "avg_idleness": 90.0},
            {"checkpoint": "c", "failures": 0.0, "avg_idleness": 50.0}]
    assert [r["checkpoint"] for r in rank(rows)] == ["c", "b", "a"]


def test_cli_validate_prints_every_checkpoint_and_the_best(run, capsys):
    assert cli.main(["zoo", "validate", str(run), "--agents", "1,2", "--episodes", "1", "--steps", "20",
                     "--last", "2"]) == 0
    out = capsys.readouterr().out
    assert out.count("failures/episode") == 2 and "best: " in out
    assert cli.main(["zoo", "validate", str(run), "--agents", "one"]) == 2
    assert "give team sizes like 1,3,5" in capsys.readouterr().err
