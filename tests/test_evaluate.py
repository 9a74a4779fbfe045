"""Batched evaluation: fault parsing, summaries over tests, any predict() object, the CLI."""
import csv
import json

import numpy as np
import pytest

from patrolsb3 import cli, zoo
from patrolsb3.commands.evaluate import parse_faults
from patrolsb3.core import load_map, make_config
from patrolsb3.evaluate import evaluate, load_policy, run_episodes


def test_parse_faults():
    assert parse_faults(["7200:1", "100:2"]) == ((100, 2), (7200, 1))
    for bad in ["12x", "1:2:3", "5:0", "-1:1"]:
        with pytest.raises(ValueError, match="bad --faults"):
            parse_faults([bad])


def test_evaluate_with_fault_splits_segments():
    r = evaluate("PART", "A", 1, episodes=3, tests=2, steps=300, seed=1, faults=((99, 1),),
                 progress=False)
    s = r["summary"]
    assert (r["map"], r["n_agents"], r["tests"], len(s["clean_episodes"])) == ("A", 1, 2, 2)
    before, after = s["segments"]
    assert (before["start"], before["end"], after["start"], after["end"]) == (0, 100, 100, 300)
    # the only agent fails for good at step 99: nobody resets idleness afterwards
    assert after["avg_idleness"]["mean"] > before["avg_idleness"]["mean"] + 100
    assert r["bounds"]["v_over_k"] == load_map("A").n_vertices


class CountingPolicy:
    """A recurrent-style predictor: its state counts steps and resets on episode_start."""

    def __init__(self):
        self.starts = []

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        E, A = observation.pos.shape
        self.starts.append(np.asarray(episode_start).copy())
        state = np.zeros(E, dtype=int) if state is None else state
        state = np.where(episode_start, 0, state) + 1
        actions = np.zeros((E, A, 2), dtype=np.int64)
        actions[..., 1] = 4
        return actions, state


def test_any_predictor_is_driven_alike():
    spec = load_map("B")
    cfg = make_config("B", episode_steps=5)
    policy = CountingPolicy()
    r = run_episodes(policy, spec, cfg, 2, n_envs=3, seed=0)
    assert [s.tolist() for s in policy.starts] == [[True] * 3] + [[False] * 3] * 4
    # nobody moves: every vertex but the starting ones grows by its rate each step
    assert r["collisions"].tolist() == [0.0, 0.0, 0.0]


def test_unknown_zoo_strategy_is_a_clear_error():
    spec = load_map("A")
    with pytest.raises(ValueError, match="zoo:nothing"):
        load_policy("zoo:nothing", spec, 2, make_config("A"))


def test_cli_evaluate_writes_json(tmp_path, capsys):
    out = tmp_path / "r.json"
    assert cli.main(["evaluate", "--strategy", "cr", "--map", "C", "--agents", "2", "--episodes", "2",
                     "--steps", "50", "--json", str(out), "--no-progress"]) == 0
    text = capsys.readouterr().out
    assert "MAX^h" in text and "battery failure rate" in text and "|V|/k" in text
    result = json.loads(out.read_text())
    assert result["strategy"] == "CR" and result["summary"]["clean_episodes"] == [2]
    assert cli.main(["evaluate", "--strategy", "nope", "--episodes", "1", "--steps", "2"]) == 2
    assert cli.main(["evaluate", "--strategy", "CR", "--agents", "7", "--episodes", "1",
                     "--steps", "2"]) == 2
    assert "nope" in capsys.readouterr().err


def test_cli_compare_writes_paper_tables(tmp_path):
    assert cli.main(["compare", "--maps", "A", "--agents", "1-2", "--episodes", "2", "--steps", "40",
                     "--out", str(tmp_path), "--no-progress"]) == 0
    for suffix in ("BF", "BLv", "MAX", "MEAN", "COLLISION"):
        rows = list(csv.reader((tmp_path / f"A-{suffix}.csv").open()))
        assert rows[0] == ["n", "CR", "PART", "SEBS", "INTENTION", "NOMSG", "MSG"]
        assert [r[0] for r in rows[1:]] == ["1", "2"]
        for column, variant in zip(rows[0][4:], ("rl-intention", "rl-no-msg", "rl-msg")):
            cells = [r[rows[0].index(column)] for r in rows[1:]]
            if not zoo.available("A", variant):
                assert cells == ["", ""]                      # no zoo model: empty, not invented
            elif suffix == "BF":
                assert all(c != "" for c in cells)            # a zoo model always has a failure rate
        assert all(r[1] != "" for r in rows[1:] if suffix != "BLv")
        extra = list(csv.reader((tmp_path / f"A-{suffix}-extra.csv").open()))
        assert extra[0] == ["n", "RANDOM", "CYCLIC"]
    assert (tmp_path / "A.png").stat().st_size > 1000
    assert "## Map A: MAX" in (tmp_path / "report.md").read_text()


@pytest.mark.skipif(not zoo.available("A", "rl-msg"), reason="needs the zoo's A/rl-msg")
def test_cli_compare_stochastic_samples_the_zoo_model(tmp_path):
    args = ["compare", "--maps", "A", "--agents", "2", "--episodes", "2", "--steps", "60",
            "--strategies", "zoo:rl-msg", "--no-progress"]
    assert cli.main(args + ["--out", str(tmp_path / "greedy")]) == 0
    assert cli.main(args + ["--stochastic", "--out", str(tmp_path / "sampled")]) == 0
    assert "most likely legal action" in (tmp_path / "greedy" / "report.md").read_text()
    assert "sample their actions" in (tmp_path / "sampled" / "report.md").read_text()
    greedy, sampled = (list(csv.DictReader((tmp_path / d / "results.csv").open())) for d in ("greedy", "sampled"))
    assert greedy[0]["deterministic"] == "True" and sampled[0]["deterministic"] == "False"


@pytest.mark.skipif(not zoo.available("A", "rl-msg", shelf="guarded"), reason="needs the zoo's guarded A/rl-msg")
def test_compare_shows_the_guarded_entries_only_when_asked_and_labelled(tmp_path, capsys):
    assert cli.main(["compare", "--maps", "A", "--agents", "1", "--episodes", "1", "--steps", "30",
                     "--strategies", "CR,zoo:rl-msg:guarded", "--out", str(tmp_path / "g"), "--no-progress"]) == 0
    extra = list(csv.reader((tmp_path / "g" / "A-MAX-extra.csv").open()))
    assert extra[0] == ["n", "RANDOM", "CYCLIC", "MSG-GUARDED"] and extra[1][3] != ""
    main = list(csv.reader((tmp_path / "g" / "A-MAX.csv").open()))
    assert main[1][main[0].index("MSG")] == ""                   # the shield never fills the paper's column
    report = (tmp_path / "g" / "report.md").read_text()
    assert "map A, zoo:rl-msg:guarded: behind the return guard" in report and "| RL-MSG (guarded) |" in report
    assert cli.main(["compare", "--maps", "A", "--agents", "1", "--episodes", "1", "--steps", "5",
                     "--strategies", "zoo:rl-msg:shielded", "--out", str(tmp_path / "bad")]) == 2
    assert "shelf 'shielded': not a shelf of the zoo" in capsys.readouterr().err and not (tmp_path / "bad").exists()


@pytest.mark.skipif(not zoo.available("A", "rl-msg"), reason="needs the zoo's A/rl-msg")
def test_compare_shows_a_recipe_shelf_as_its_own_labelled_column(tmp_path, capsys, monkeypatch):
    import shutil
    source = zoo.entry_dir("A", "rl-msg", seed=0)
    for place in ("A/rl-msg/seed0", "paper-recipe/A/rl-msg/seed0"):       # a zoo of one entry, shelved once
        shutil.copytree(source, tmp_path / "zoo" / place, ignore=shutil.ignore_patterns("eval.json"))
    monkeypatch.setenv(zoo.ZOO_ENV, str(tmp_path / "zoo"))
    assert cli.main(["compare", "--maps", "A", "--agents", "1", "--episodes", "1", "--steps", "30",
                     "--strategies", "CR,zoo:rl-msg,zoo:rl-msg:paper-recipe", "--out", str(tmp_path / "c"),
                     "--no-progress"]) == 0
    extra = list(csv.reader((tmp_path / "c" / "A-MAX-extra.csv").open()))
    main = list(csv.reader((tmp_path / "c" / "A-MAX.csv").open()))
    assert extra[0] == ["n", "RANDOM", "CYCLIC", "MSG-PAPER-RECIPE"]
    assert extra[1][3] == main[1][main[0].index("MSG")] != ""      # the same weights: the same figures
    report = (tmp_path / "c" / "report.md").read_text()
    assert "| RL-MSG (paper recipe) |" in report and "map A, zoo:rl-msg:paper-recipe: the paper's setting" in report
    assert cli.main(["compare", "--maps", "A", "--agents", "1", "--episodes", "1", "--steps", "5",
                     "--strategies", "zoo:rl-msg:cd10", "--out", str(tmp_path / "bad")]) == 2
    assert "no zoo model for map(s) A on the shelf 'cd10'" in capsys.readouterr().err


def test_faults_outside_the_episode_are_refused():
    with pytest.raises(ValueError, match="outside the episode"):
        evaluate("CR", "A", 2, episodes=1, steps=100, faults=((100, 1),), progress=False)


def test_compare_refuses_bad_strategies_before_running(tmp_path):
    assert cli.main(["compare", "--maps", "A", "--agents", "1", "--episodes", "1", "--steps", "5",
                     "--strategies", "CR,NOPE", "--out", str(tmp_path / "o")]) == 2
    assert not (tmp_path / "o").exists()
    assert cli.main(["compare", "--maps", "A", "--agents", "1", "--episodes", "1", "--steps", "5",
                     "--strategies", "cr,sebs", "--out", str(tmp_path / "p"), "--no-progress"]) == 0
    rows = (tmp_path / "p" / "A-MAX.csv").read_text().splitlines()
    cells = rows[1].split(",")
    assert cells[1] != "" and cells[3] != ""          # CR and SEBS columns filled from lower-case names


def test_compare_asks_for_a_default_seed_before_running(tmp_path, monkeypatch, capsys):
    # an entry with two trained seeds and no default.yml is a zoo column, not a missing one:
    # compare stops at once and says how to choose the default (the seeds' figures are pooled,
    # the default's config and training curve label the column)
    root = tmp_path / "zoo"
    for k in (0, 1):
        (root / "A" / "rl-no-msg" / f"seed{k}").mkdir(parents=True)
        (root / "A" / "rl-no-msg" / f"seed{k}" / "model.zip").write_bytes(b"")
    monkeypatch.setenv(zoo.ZOO_ENV, str(root))
    assert zoo.available("A", "rl-no-msg") and not zoo.available("A", "rl-msg")
    for strategies in ([], ["--strategies", "CR,zoo:rl-no-msg"]):
        assert cli.main(["compare", "--maps", "A", "--agents", "1", "--episodes", "1", "--steps", "5",
                         "--out", str(tmp_path / "o"), "--no-progress", *strategies]) == 2
        err = capsys.readouterr().err.strip()
        assert "seeds [0, 1] and no default.yml; run 'patrolsb3 zoo choose A rl-no-msg'" in err
        assert len(err.splitlines()) == 1 and not (tmp_path / "o").exists()




def test_a_batch_of_team_sizes_pairs_episode_j_of_every_size():
    from patrolsb3.evaluate import team_batch
    team, ids = team_batch([1, 3, 5], 2)
    assert team.tolist() == [1, 1, 3, 3, 5, 5] and ids.tolist() == [0, 1, 0, 1, 0, 1]
