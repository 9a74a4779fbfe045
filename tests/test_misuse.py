"""Misuse of the command line, one case a test (issue 47): values that make no sense are refused
in one line naming the option, before any work, and leave nothing behind. (The cases about
shared files live beside the modules they test: test_sb3_train (run folders, resume),
test_sweeps / test_distributed (sweeps), test_zoo (export), test_result_store (compare),
test_claims (claims' own input), test_env_api (the PettingZoo env).)"""
import pytest

from patrolsb3 import cli


@pytest.mark.parametrize("argv, message", [
    (["evaluate", "--strategy", "CR", "--episodes", "0"], "--episodes must be a whole number >= 1, got 0"),
    (["evaluate", "--strategy", "CR", "--seed", "-1"], "--seed must be a whole number >= 0, got -1"),
    (["evaluate", "--strategy", "CR", "--agents", "0"], "--agents must be a whole number >= 1, got 0"),
    (["evaluate", "--strategy", "CR", "--agents", "2", "--faults", "100:3"], "3 agents fail in a team of 2"),
    (["compare", "--agents", "5-1", "--strategies", "CR", "--out", "o"], "the range 5-1 is reversed (write 1-5)"),
    (["compare", "--maps", "A,A", "--strategies", "CR", "--out", "o"], "--maps A,A: A given more than once"),
    (["zoo", "validate", "runs/x", "--last", "0"], "--last must be a whole number >= 1, got 0"),
    (["zoo", "validate", "runs/x", "--last", "-2"], "--last must be a whole number >= 1, got -2"),
    (["zoo", "eval", "A", "rl-msg", "--episodes", "0"], "--episodes must be a whole number >= 1, got 0"),
    (["zoo", "choose", "A", "rl-msg", "--episodes", "0"], "--episodes must be a whole number >= 1, got 0"),
    (["zoo", "listening", "A", "rl-msg", "--episodes", "0"], "--episodes must be a whole number >= 1, got 0"),
    (["zoo", "ablation", "A", "rl-msg", "--episodes", "0"], "--episodes must be a whole number >= 1, got 0"),
    (["zoo", "show", "A", "rl-msg", "--seed-of-entry", "-1"], "--seed-of-entry must be a whole number >= 0"),
    (["bench", "train", "--repeats", "0"], "--repeats must be a whole number >= 1, got 0"),
    (["train", "--seed", "-1", "--timesteps", "10"], "--seed must be a whole number >= 0, got -1"),
    (["train", "--timesteps", "0"], "--timesteps must be a whole number >= 1, got 0"),
])
def test_a_value_that_makes_no_sense_is_refused_in_one_line(argv, message, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert cli.main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and len(err.splitlines()) == 1
    assert not any(tmp_path.iterdir())                   # nothing written


def _damaged_entry(tmp_path):
    """A zoo entry of a tiny trained run, then its eval.json cut in the middle."""
    from patrolsb3 import zoo
    from patrolsb3.sb3.train import train
    (tmp_path / "room.txt").write_text("S.....\n......\n......\n")
    hp = {"n_steps": 8, "n_minibatches": 1, "n_envs": 1, "eval_freq": 0, "checkpoint_freq": 10**9,
          "env": {"episode_steps": 10}, "policy_kwargs": {"dense_sizes": [8], "lstm_hidden_size": 4}}
    run = train(map=str(tmp_path / "room.txt"), timesteps=80, run_dir=tmp_path / "run", hyperparams=hp,
                progress_bar=False)
    entry = zoo.export(run, zoo_dir=tmp_path / "zoo")
    from patrolsb3.zoo.evaluation import write_zoo_eval
    text = write_zoo_eval(entry, episodes=1, steps=10, progress=False).read_text()
    (entry / "eval.json").write_text(text[:len(text) // 2])
    return entry


def test_a_damaged_file_is_named_in_one_line_by_every_command_that_reads_it(tmp_path, capsys, monkeypatch):
    entry = _damaged_entry(tmp_path)
    monkeypatch.setenv("PATROLSB3_ZOO", str(tmp_path / "zoo"))
    capsys.readouterr()
    for argv in (["zoo", "list"], ["zoo", "show", "ROOM", "rl-msg"]):
        assert cli.main(argv) == 2
        err = capsys.readouterr().err.strip()
        assert f"{entry / 'eval.json'}: not valid JSON, cut or damaged" in err and len(err.splitlines()) == 1
    # zoo eval rewrites it
    assert cli.main(["zoo", "eval", "ROOM", "rl-msg", "--episodes", "1", "--steps", "10"]) == 0
    assert cli.main(["zoo", "show", "ROOM", "rl-msg"]) == 0
    # a results.csv, a curve.csv, a hyperparameter file
    (tmp_path / "c").mkdir()
    (tmp_path / "c" / "results.csv").write_text("map,n,strategy\nA,1")
    assert cli.main(["claims", str(tmp_path / "c")]) == 2
    assert "results.csv: not a results.csv written by 'patrolsb3 compare'" in capsys.readouterr().err
    from patrolsb3.runs import read_curve
    (tmp_path / "curve.csv").write_text("timesteps,reward\n10,1.5\n20,")
    with pytest.raises(ValueError, match="curve.csv: not a curve.csv of 'patrolsb3 train', or cut or damaged"):
        read_curve(tmp_path / "curve.csv")
    (tmp_path / "hp.yml").write_text("default: {gamma: [0.9\n")
    capsys.readouterr()
    assert cli.main(["train", "--hyperparams", str(tmp_path / "hp.yml"), "--timesteps", "10",
                     "--out", str(tmp_path / "runs")]) == 2
    err = capsys.readouterr().err.strip()
    assert "hp.yml: not valid YAML, cut or damaged" in err and len(err.splitlines()) == 1
    assert not (tmp_path / "runs").exists()


def test_a_run_too_big_for_this_machine_is_refused_and_a_big_checkpoint_announced(tmp_path, capsys, monkeypatch):
    from patrolsb3.sb3 import train as train_module
    monkeypatch.setattr(train_module, "physical_memory", lambda: 24 * 2 ** 30)       # this machine's 24 GiB
    assert cli.main(["train", "--map", "A", "--timesteps", "1000", "--out", str(tmp_path / "runs"),
                     "--set", "env.max_agents=1000"]) == 2
    err = capsys.readouterr().err.strip()
    assert "the rollout buffer would need about" in err and "MiB, more than 80 %" in err and len(err.splitlines()) == 1
    assert not (tmp_path / "runs").exists()
    monkeypatch.setattr(train_module, "CHECKPOINT_WARN_BYTES", 2 ** 20)
    estimate = train_module.memory_estimate({"n_steps": 8, "policy_kwargs": {}}, _layout(), 40, 2, 5000)
    train_module.check_memory(estimate)
    assert "note: each checkpoint of this run will be about 14 MiB (1,239,207 parameters" in capsys.readouterr().err


def _layout():
    from patrolsb3.sb3.vec_env import make_vec_env
    env = make_vec_env("A", agents=[1] * 8, variant="rl-msg", seed=0)
    env.close()
    return env.layout


def test_evaluate_and_compare_take_a_zoo_dir(tmp_path, capsys, monkeypatch):
    import os

    from patrolsb3.zoo import ZOO_ENV
    monkeypatch.setenv(ZOO_ENV, "")                      # restored after the test
    assert cli.main(["evaluate", "--strategy", "zoo:rl-msg", "--zoo-dir", str(tmp_path / "none")]) == 2
    assert "--zoo-dir" in capsys.readouterr().err and os.environ[ZOO_ENV] == ""
    (tmp_path / "zoo").mkdir()
    assert cli.main(["evaluate", "--strategy", "zoo:rl-msg", "--map", "A", "--episodes", "1", "--steps", "5",
                     "--zoo-dir", str(tmp_path / "zoo"), "--no-progress"]) == 2     # an empty zoo: no entry
    assert os.environ[ZOO_ENV] == str((tmp_path / "zoo").resolve())
    assert "zoo" in capsys.readouterr().err


@pytest.mark.parametrize("command", [["evaluate", "--strategy", "CR", "--episodes", "1", "--steps", "5", "--json"],
                                     ["render", "--strategy", "CR", "--steps", "5", "--out"]])
def test_an_output_that_is_an_input_is_refused(command, tmp_path, capsys):
    from pathlib import Path
    map_file = tmp_path / "mine.txt"
    text = (Path(__file__).resolve().parents[1] / "maps" / "map_a.txt").read_text()
    map_file.write_text(text)
    assert cli.main(command[:1] + ["--map", str(map_file)] + command[1:] + [str(map_file)]) == 2
    assert "is an input of this command" in capsys.readouterr().err
    assert map_file.read_text() == text


def test_a_damaged_default_yml_of_an_entry_is_named(tiny_zoo, tmp_path, capsys):
    import shutil
    zoo_dir = tmp_path / "zoo"
    shutil.copytree(tiny_zoo, zoo_dir)
    (zoo_dir / "A" / "rl-msg" / "default.yml").write_text("seed: [0\n")
    assert cli.main(["zoo", "show", "A", "rl-msg", "--zoo-dir", str(zoo_dir)]) == 2
    err = capsys.readouterr().err.strip()
    assert "default.yml: not valid YAML, cut or damaged" in err and len(err.splitlines()) == 1
    (zoo_dir / "A" / "rl-msg" / "default.yml").write_text("- 0\n")
    assert cli.main(["zoo", "show", "A", "rl-msg", "--zoo-dir", str(zoo_dir)]) == 2
    assert "expected a mapping with 'seed'" in capsys.readouterr().err
