"""The comparison's planning and its one lookup of stored figures (patrolsb3.comparison)."""
import pytest

from patrolsb3 import zoo
from patrolsb3.comparison import Protocol, StoredResults, evaluate_cells, learning_curves, plan_cells

PROTOCOL = Protocol(episodes=1, tests=1, steps=30, seed=0)


def test_plan_lists_cells_in_report_order_and_says_which_zoo_columns_are_empty(tiny_zoo, monkeypatch):
    monkeypatch.setenv(zoo.ZOO_ENV, str(tiny_zoo))
    said = []
    cells = plan_cells(["A"], [1, 2], None, say=said.append)
    names = list(dict.fromkeys(name for _, name, _ in cells))
    assert names == ["CR", "PART", "SEBS", "RANDOM", "CYCLIC", "zoo:rl-no-msg", "zoo:rl-msg"]
    assert [n for m, name, n in cells if name == "CR"] == [1, 2]
    assert len(said) == 1 and "zoo:rl-intention" in said[0]           # the tiny zoo has no rl-intention
    assert plan_cells(["A"], [3], ["sebs", "Zoo:RL-MSG"]) == [("A", "SEBS", 3), ("A", "zoo:rl-msg", 3)]


@pytest.mark.parametrize("maps, sizes, strategies, message", [
    (["A", "A"], [1], ["CR"], "A given more than once"),
    (["A"], [6], ["CR"], "at most 5 agents"),
    (["A"], [1], ["GREEDY"], "unknown strategy 'GREEDY'"),
    (["A"], [1], ["zoo:rl-intention"], "no zoo model for map(s) A"),
    (["nowhere.txt"], [1], ["CR"], "nowhere.txt"),
])
def test_plan_refuses_bad_requests_in_one_line(tiny_zoo, monkeypatch, maps, sizes, strategies, message):
    monkeypatch.setenv(zoo.ZOO_ENV, str(tiny_zoo))
    with pytest.raises((ValueError, FileNotFoundError)) as info:
        plan_cells(maps, sizes, strategies)
    assert message in str(info.value) and "\n" not in str(info.value)


def test_stored_results_keep_heuristics_in_results_json_and_never_a_zoo_model(tiny_zoo, monkeypatch, tmp_path):
    monkeypatch.setenv(zoo.ZOO_ENV, str(tiny_zoo))
    cells = [("A", "CR", 1), ("A", "zoo:rl-msg", 1)]
    stored = StoredResults(tmp_path, PROTOCOL)
    assert [stored.find(c) for c in cells] == [(None, ""), (None, "")]       # nothing stored yet
    finished = {cell: result for cell, result, _ in evaluate_cells(cells, PROTOCOL, progress=False)}
    for cell, result in finished.items():
        stored.add(cell, result)
    again = StoredResults(tmp_path, PROTOCOL)
    result, source = again.find(("A", "CR", 1))
    assert result["summary"]["avg_idleness"] == finished[("A", "CR", 1)]["summary"]["avg_idleness"]
    assert "results.json" in source
    assert again.find(("A", "zoo:rl-msg", 1)) == (None, "")                 # no eval.json of this protocol
    assert StoredResults(tmp_path, PROTOCOL, rerun_heuristics=True).find(("A", "CR", 1)) == (None, "")
    other = Protocol(episodes=1, tests=1, steps=31, seed=0)
    assert StoredResults(tmp_path, other).find(("A", "CR", 1)) == (None, "")  # another protocol: not reused


def test_learning_curves_are_the_zoo_columns_seed_curves(tiny_zoo, monkeypatch):
    monkeypatch.setenv(zoo.ZOO_ENV, str(tiny_zoo))
    curves = learning_curves([("A", "CR", 1), ("A", "zoo:rl-msg", 1), ("A", "zoo:rl-msg", 2)])
    assert list(curves) == ["A"] and list(curves["A"]) == ["rl-msg"]
    assert [p.parent.name for p in curves["A"]["rl-msg"]] == ["seed0"]
