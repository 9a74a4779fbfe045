"""patrolsb3.result_store and the resumable 'patrolsb3 compare' built on it."""
import json

import numpy as np
import pytest

from patrolsb3 import cli
from patrolsb3.evaluate import evaluate
from patrolsb3.result_store import ResultStore


def test_a_stored_result_stands_only_for_the_same_protocol(tmp_path):
    store = ResultStore(tmp_path)
    result = evaluate("CR", "A", 2, episodes=1, steps=30, seed=1, progress=False)
    assert store.find(result) is None
    store.add(result)
    again = ResultStore(tmp_path)                                 # read back from results.json
    stored, expected = again.find(result)["summary"], result["summary"]
    assert stored.keys() == expected.keys()
    for key in expected:                                          # NaN (e.g. no swap) comes back as NaN
        np.testing.assert_equal(stored[key], json.loads(json.dumps(expected[key])))
    text = (tmp_path / "results.json").read_text()
    assert "NaN" not in text and np.isnan(expected["swap_battery_pct"]["mean"])   # strict JSON on disk
    for change in ({"seed": 2}, {"steps": 31}, {"n_agents": 3}, {"strategy": "SEBS"}, {"episodes": 2},
                   {"env": {**result["env"], "p_dyn_max": 0.0}}, {"env_version": "patrol-v0-old"}):
        assert again.find({**result, **change}) is None, change
    # heuristics ignore the action mode; a zoo model's result is kept apart per mode
    assert again.find({**result, "deterministic": False}) is not None
    learned = {**result, "strategy": "zoo:rl-msg"}
    again.add(learned)
    assert again.find({**learned, "deterministic": False}) is None
    store.add(result)                 # the same protocol replaces, not duplicates; `again`'s result stays
    assert [r["strategy"] for r in json.loads((tmp_path / "results.json").read_text())] == ["zoo:rl-msg", "CR"]


def test_two_comparisons_on_one_folder_keep_both_results(tmp_path):
    first, second = ResultStore(tmp_path), ResultStore(tmp_path)   # opened together, as two commands would
    cr = evaluate("CR", "A", 1, episodes=1, steps=20, seed=0, progress=False)
    sebs = evaluate("SEBS", "A", 1, episodes=1, steps=20, seed=0, progress=False)
    first.add(cr)
    second.add(sebs)
    stored = ResultStore(tmp_path)
    assert stored.find(cr) is not None and stored.find(sebs) is not None


def test_a_result_stored_before_an_env_field_existed_stands_for_its_default(tmp_path):
    store = ResultStore(tmp_path)
    result = evaluate("CR", "A", 2, episodes=1, steps=30, seed=1, progress=False)
    old = {**result, "env": {k: v for k, v in result["env"].items() if k != "c_home"}}
    store.add(old)                                                # as written before c_home existed
    assert store.find(result) is not None                         # c_home at its default 0
    assert store.find({**result, "env": {**result["env"], "c_home": 50.0}}) is None
    store.add(result)                                             # the same protocol: replaces it
    assert len(json.loads((tmp_path / "results.json").read_text())) == 1


def test_a_broken_results_file_is_named(tmp_path):
    (tmp_path / "results.json").write_text("{not json")
    with pytest.raises(ValueError, match="results.json is not a results file"):
        ResultStore(tmp_path)


def test_compare_again_reuses_the_heuristics_it_ran(tmp_path, capsys):
    args = ["compare", "--maps", "A", "--agents", "1", "--episodes", "1", "--steps", "40",
            "--strategies", "CR", "--out", str(tmp_path), "--no-progress"]
    assert cli.main(args) == 0
    first = capsys.readouterr().out
    table = (tmp_path / "A-MAX.csv").read_text()
    assert "results.json" not in first
    assert cli.main(args + ["--strategies", "CR,SEBS"]) == 0
    second = capsys.readouterr().out
    assert "CR n=1" in second and "from " in second.split("CR n=1")[1].splitlines()[0]
    assert "from " not in second.split("SEBS n=1")[1].splitlines()[0]       # new: run
    assert (tmp_path / "A-MAX.csv").read_text().splitlines()[1].split(",")[1] == table.splitlines()[1].split(",")[1]
    assert cli.main(args + ["--rerun"]) == 0
    assert "results.json" not in capsys.readouterr().out


def test_compare_counts_every_file_it_writes(tmp_path, capsys):
    out = tmp_path / "c"
    assert cli.main(["compare", "--maps", "A", "--agents", "1", "--strategies", "CR", "--episodes", "1",
                     "--steps", "20", "--out", str(out), "--no-progress"]) == 0
    said = [line for line in capsys.readouterr().out.splitlines() if line.startswith("wrote ")][0]
    written = [p for p in out.iterdir() if not p.name.startswith(".")]          # lock files aside
    assert said.startswith(f"wrote {len(written)} files to ")
