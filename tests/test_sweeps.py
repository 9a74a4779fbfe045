"""patrolsb3.sweeps: the sweep file, its trials and run folders, what is done and what is not
(no Ray needed: tests/test_distributed.py runs sweeps on Ray)."""
import pytest

from patrolsb3 import cli
from patrolsb3.sweeps import (SweepError, Trial, TrialOutcome, check_trial, read_sweep, run_id, summary_table,
                              trial_state)

SWEEP = """
out: {out}
timesteps: 400
recipe: zoo-stage1
set:
  n_steps: 10
grid:
  map: [A, C]
  variant: [rl-msg, rl-no-msg]
  seed: [0, 1]
  set:
    learning_rate: [3.0e-4, 1.0e-4]
    env.c_home: [0.0]
"""


def write(tmp_path, text):
    path = tmp_path / "sweep.yml"
    path.write_text(text)
    return path


def test_the_grid_is_the_product_of_its_lists_each_trial_a_run_folder(tmp_path):
    trials = read_sweep(write(tmp_path, SWEEP.format(out=tmp_path / "runs")))
    assert len(trials) == 2 * 2 * 2 * 2
    first = trials[0]
    assert (first.map, first.variant, first.seed) == ("A", "rl-msg", 0)
    assert first.run_dir == tmp_path / "runs" / "A" / "rl-msg" / "seed0_learning_rate=0.0003_env.c_home=0.0"
    assert first.name == "A/rl-msg/seed0_learning_rate=0.0003_env.c_home=0.0"
    # recipe, then the sweep's set, then the grid's values
    assert first.overrides["n_steps"] == 10 and first.overrides["learning_rate"] == 3e-4
    assert first.overrides["env"]["c_home"] == 0.0 and first.overrides["env"]["episode_steps"] == 300
    assert first.varied == {"learning_rate": 3e-4, "env.c_home": 0.0}
    assert first.recipe == "zoo-stage1"          # given to train, which records it in config.yml
    assert read_sweep(write(tmp_path, SWEEP.format(out="x")), out=tmp_path / "o")[0].run_dir.parts[-4] == "o"


def test_run_id_without_varied_settings_is_the_seed():
    assert run_id(2, {}) == "seed2"


@pytest.mark.parametrize("text, match", [
    ("grid: [A]\ntimesteps: 10\nout: o", "'grid' must be a mapping"),
    ("grid: {map: A}\ntimesteps: 10\nout: o", "grid value of 'map' must be a non-empty list"),
    ("grid: {colour: [red]}\ntimesteps: 10\nout: o", "unknown grid key"),
    ("grid: {map: [A]}\ntimesteps: 10\nout: o\nepochs: 3", "unknown key"),
    ("grid: {map: [A]}\ntimesteps: 2.5\nout: o", "'timesteps' must be a whole number"),
    ("grid: {map: [A]}\ntimesteps: 10", "no 'out' folder"),
    ("grid: {map: [A], seed: [0.5]}\ntimesteps: 10\nout: o", "seeds must be whole numbers"),
    ("grid: {map: [A, A]}\ntimesteps: 10\nout: o", "share a run folder"),
    ("grid: {map: [A\n", "not valid YAML"),
])
def test_a_bad_sweep_file_is_refused_in_one_line_naming_it(tmp_path, text, match):
    with pytest.raises(SweepError, match=match) as info:
        read_sweep(write(tmp_path, text))
    assert "sweep.yml" in str(info.value) and "\n" not in str(info.value)


def test_a_trial_with_a_bad_setting_is_found_before_it_starts(tmp_path):
    good, = read_sweep(write(tmp_path, "out: o\ntimesteps: 400\ngrid: {map: [A]}"))
    assert check_trial(good) == ""
    bad = Trial(**{**good.__dict__, "overrides": {"n_epochs": 0}})
    assert "n_epochs must be a whole number >= 1" in check_trial(bad)
    assert "rl-shout" in check_trial(Trial(**{**good.__dict__, "variant": "rl-shout"}))


def test_trial_state_reads_the_run_folder(tmp_path):
    import zipfile
    trial, = read_sweep(write(tmp_path, f"out: {tmp_path}\ntimesteps: 400\ngrid: {{map: [A]}}"))
    assert trial_state(trial) == "new"
    (trial.run_dir / "checkpoints").mkdir(parents=True)
    with zipfile.ZipFile(trial.run_dir / "checkpoints" / "model_200_steps.zip", "w") as z:
        z.writestr("data", '{"num_timesteps": 200}')
    assert trial_state(trial) == "resumable"
    with zipfile.ZipFile(trial.run_dir / "model.zip", "w") as z:
        z.writestr("data", '{"num_timesteps": 400}')
    assert trial_state(trial) == "finished"
    table = summary_table([TrialOutcome(trial, "skipped")])
    assert "| A/rl-msg/seed0 | skipped | 400 |" in table


def test_sweep_dry_run_lists_the_trials_and_starts_nothing(tmp_path, capsys):
    path = write(tmp_path, f"out: {tmp_path / 'runs'}\ntimesteps: 400\ngrid: {{map: [A], seed: [0, 1]}}")
    assert cli.main(["sweep", str(path), "--dry-run"]) == 0
    out = capsys.readouterr().out
    assert "2 trials, 0 finished before, 2 to run" in out and "| A/rl-msg/seed1 | pending |" in out
    assert not (tmp_path / "runs").exists()


def test_sweep_cli_refuses_a_bad_file_in_one_line(tmp_path, capsys):
    assert cli.main(["sweep", str(tmp_path / "missing.yml")]) == 2
    assert "no such sweep file" in capsys.readouterr().err


def test_without_ray_sweep_and_compare_ray_say_how_to_install_it(tmp_path, capsys, monkeypatch):
    import sys
    monkeypatch.setitem(sys.modules, "ray", None)              # import ray -> ImportError
    path = write(tmp_path, f"out: {tmp_path / 'runs'}\ntimesteps: 400\ngrid: {{map: [A]}}")
    assert cli.main(["sweep", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and 'pip install -e ".[ray]"' in err
    assert cli.main(["compare", "--maps", "A", "--agents", "1", "--strategies", "CR", "--episodes", "1",
                     "--steps", "10", "--out", str(tmp_path / "c"), "--ray", "--no-progress"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and 'pip install -e ".[ray]"' in err
    assert not (tmp_path / "runs").exists() and not (tmp_path / "c" / "results.json").exists()


def test_a_relative_out_is_made_absolute_from_the_working_directory(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    trial, = read_sweep(write(tmp_path, "out: runs/rel\ntimesteps: 400\ngrid: {map: [A]}"))
    assert trial.run_dir == tmp_path / "runs" / "rel" / "A" / "rl-msg" / "seed0"


def test_a_folder_with_files_and_no_checkpoint_is_blocked_not_new(tmp_path):
    trial, = read_sweep(write(tmp_path, f"out: {tmp_path}\ntimesteps: 400\ngrid: {{map: [A]}}"))
    trial.run_dir.mkdir(parents=True)
    assert trial_state(trial) == "new"                               # empty: the sweep may start it
    (trial.run_dir / "curve.csv").write_text("timesteps\n")
    assert trial_state(trial) == "blocked"


def test_a_trial_records_its_sweeps_recipe_in_the_run_config(tmp_path):
    import yaml

    from patrolsb3.sweeps import Trial, run_trial
    tiny = {"n_steps": 16, "n_minibatches": 2, "n_envs": 2, "eval_freq": 0, "checkpoint_freq": 10**9,
            "env": {"episode_steps": 20}, "policy_kwargs": {"dense_sizes": [32, 16], "lstm_hidden_size": 8}}
    trial = Trial(map="A", variant="rl-no-msg", seed=0, timesteps=320, overrides=tiny, varied={},
                  run_dir=tmp_path / "A" / "rl-no-msg" / "seed0", recipe="paper")
    assert run_trial(trial)["timesteps"] >= 320
    assert yaml.safe_load((trial.run_dir / "config.yml").read_text())["recipe"] == "paper"


def test_a_trial_stopped_by_an_interrupted_sweep_says_so_and_how_to_go_on():
    from patrolsb3.distributed import trial_outcome
    assert trial_outcome({}, "", 1600)["status"] == "stopped"              # Tune stopped it: no report, no error
    assert "run the sweep again to continue from its newest checkpoint" in trial_outcome({}, "", 1600)["error"]
    assert trial_outcome({"timesteps": 1600, "seconds": 3.0}, "", 1600) == {"status": "finished", "seconds": 3.0,
                                                                             "error": ""}
    assert trial_outcome({"timesteps": 800}, "", 1600)["error"] == "the trial ended at 800 of its 1,600 agent-steps"
    assert trial_outcome({}, "ValueError: bad", 1600) == {"status": "error", "seconds": 0.0, "error": "ValueError: bad"}
