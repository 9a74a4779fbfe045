"""Sweeps and comparisons on a local Ray (2 CPUs): trials are run folders, a rerun starts
nothing, a trial with a checkpoint removed resumes alone, a failing trial fails alone, and
``compare --ray`` gives the serial figures. Skipped without the ray extra
(``pip install -e ".[ray]"``)."""
import json
import shutil

import pytest

ray = pytest.importorskip("ray", reason="the ray extra is not installed: pip install -e \".[ray]\"")

from patrolsb3 import cli  # noqa: E402
from patrolsb3.runs import RunFolder, model_steps  # noqa: E402

ROOM = "S.....\n......\n..5...\n......\n"
SETTINGS = """
out: {out}
timesteps: 1600
set:
  n_steps: 10
  checkpoint_freq: 400
  eval_freq: 0
  env: {{episode_steps: 5}}
  policy_kwargs: {{dense_sizes: [16, 16]}}
grid:
  map: [{room}]
  seed: [0, 1]
  set:
    policy_kwargs.lstm_hidden_size: {sizes}
"""


@pytest.fixture(scope="module", autouse=True)
def local_ray():
    from patrolsb3.distributed import connect
    connect(num_cpus=2)
    yield
    ray.shutdown()


def sweep_file(tmp_path, sizes="[8]"):
    (tmp_path / "room.txt").write_text(ROOM)
    path = tmp_path / "sweep.yml"
    path.write_text(SETTINGS.format(out=tmp_path / "runs", room=tmp_path / "room.txt", sizes=sizes))
    return path


def commands(folder):
    return RunFolder(folder).command_file.read_text().count("\n")


def test_a_sweep_makes_run_folders_a_rerun_starts_nothing_and_a_lost_checkpoint_resumes_alone(tmp_path, capsys):
    path = sweep_file(tmp_path)
    assert cli.main(["sweep", str(path)]) == 0
    out = capsys.readouterr().out
    runs = [tmp_path / "runs" / "room" / "rl-msg" / f"seed{s}_policy_kwargs.lstm_hidden_size=8" for s in (0, 1)]
    for run in runs:
        folder = RunFolder(run)
        assert model_steps(folder.model_file) == 1600 and folder.read_config()["seed"] in (0, 1)
        assert folder.curve_file.is_file() and folder.cpu_time_file.is_file()
        assert f"trial room/rl-msg/{run.name}: finished in" in out
    assert "| finished | 1,600 |" in out
    # run again: everything is finished, nothing starts
    assert cli.main(["sweep", str(path)]) == 0
    assert "2 finished before, 0 to run" in capsys.readouterr().out
    assert [commands(r) for r in runs] == [1, 1]
    # seed 1 loses its model and its last checkpoints: only it resumes, from 800
    RunFolder(runs[1]).model_file.unlink()
    for steps in (1200, 1600):
        RunFolder(runs[1]).checkpoint_file(steps).unlink()
    assert cli.main(["sweep", str(path)]) == 0
    out = capsys.readouterr().out
    assert "1 finished before, 1 to run (1 resume from a checkpoint)" in out
    assert [commands(r) for r in runs] == [1, 2]
    assert model_steps(RunFolder(runs[1]).model_file) == 1600
    with RunFolder(runs[1]).cpu_time_file.open() as f:
        steps = [int(line.split(",")[0]) for line in f.read().splitlines()[1:]]
    assert steps == sorted(steps) and steps[-1] == 1600          # cut back to 800, then on


def test_a_trial_that_fails_while_training_fails_alone(tmp_path, capsys):
    path = sweep_file(tmp_path, sizes="[8, -1]")               # a negative LSTM size fails at model build
    assert cli.main(["sweep", str(path)]) == 1
    out = capsys.readouterr().out
    good = [line for line in out.splitlines() if "lstm_hidden_size=8 |" in line]
    bad = [line for line in out.splitlines() if "lstm_hidden_size=-1 |" in line]
    assert len(good) == 2 and all("| finished | 1,600 |" in line for line in good)
    assert len(bad) == 2 and all("| error |" in line and "Error" in line for line in bad)


def test_compare_on_ray_gives_the_serial_figures(tmp_path, capsys):
    common = ["compare", "--maps", "A", "--agents", "1-2", "--strategies", "CR,SEBS", "--episodes", "2",
              "--steps", "60", "--no-progress"]
    assert cli.main(common + ["--out", str(tmp_path / "serial")]) == 0
    assert cli.main(common + ["--out", str(tmp_path / "ray"), "--ray"]) == 0
    out = capsys.readouterr().out
    assert "ray: 4 cells on 2 CPUs" in out

    def figures(folder):
        return {(r["strategy"], r["n_agents"]): r["summary"] for r in json.loads((folder / "results.json").read_text())}
    assert figures(tmp_path / "serial") == figures(tmp_path / "ray")
    # an interrupted distributed comparison resumes like a local one: a lost cell is the only one run again
    stored = json.loads((tmp_path / "ray" / "results.json").read_text())
    (tmp_path / "ray" / "results.json").write_text(json.dumps(stored[1:]))
    assert cli.main(common + ["--out", str(tmp_path / "ray"), "--ray"]) == 0
    assert "ray: 1 cells on 2 CPUs" in capsys.readouterr().out
    assert figures(tmp_path / "serial") == figures(tmp_path / "ray")
    shutil.rmtree(tmp_path / "ray")


def test_a_relative_out_is_the_working_directorys_even_on_ray(tmp_path, monkeypatch, capsys):
    """Ray runs each trial in a working directory of its own: the sweep resolves ``out`` first,
    so the run folders land where the user ran the command, at their agent-steps."""
    (tmp_path / "room.txt").write_text(ROOM)
    path = tmp_path / "sweep.yml"
    path.write_text(SETTINGS.format(out="runs/rel", room=tmp_path / "room.txt", sizes="[8]").replace(
        "seed: [0, 1]", "seed: [0]"))
    monkeypatch.chdir(tmp_path)
    assert cli.main(["sweep", str(path)]) == 0
    run = tmp_path / "runs" / "rel" / "room" / "rl-msg" / "seed0_policy_kwargs.lstm_hidden_size=8"
    assert model_steps(RunFolder(run).model_file) == 1600
    assert "| room/rl-msg/seed0_policy_kwargs.lstm_hidden_size=8 | finished | 1,600 |" in capsys.readouterr().out


def test_a_folder_the_sweep_cannot_resume_is_reported_and_left_alone(tmp_path, capsys):
    path = sweep_file(tmp_path)
    run = tmp_path / "runs" / "room" / "rl-msg" / "seed0_policy_kwargs.lstm_hidden_size=8"
    run.mkdir(parents=True)
    (run / "notes.txt").write_text("mine")
    assert cli.main(["sweep", str(path)]) == 1
    out = capsys.readouterr().out
    assert "exists with files but no checkpoint to resume; the sweep does not replace it" in out
    assert (run / "notes.txt").read_text() == "mine" and not (run / "model.zip").exists()
    other = tmp_path / "runs" / "room" / "rl-msg" / "seed1_policy_kwargs.lstm_hidden_size=8"
    assert model_steps(RunFolder(other).model_file) == 1600        # the other trial ran
