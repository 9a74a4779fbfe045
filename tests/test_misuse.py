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
