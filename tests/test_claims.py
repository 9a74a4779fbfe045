"""patrolsb3.claims: verdicts from intervals (holds / does not hold / inconclusive), each claim's
cells, and the command."""
import csv
import json

import pytest

from patrolsb3 import cli
from patrolsb3.claims import (FAILS, HOLDS, OPEN, Figure, below, claims, fault_tolerance, lowest, no_worse,
                              read_figures, threshold)

FIELDS = ["map", "n", "strategy", "metric", "mean", "std", "ci95_low", "ci95_high"]


def write_results(path, rows):
    with path.open("w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(FIELDS)
        writer.writerows(rows)
    return path


def fig(mean, half=1.0):
    return Figure(mean, mean - half, mean + half)


def test_significance_is_intervals_that_do_not_overlap():
    assert below(fig(1), fig(5)) and not below(fig(1), fig(2.5)) and not below(fig(5), fig(1))
    assert not below(Figure(1, float("nan"), float("nan")), fig(5))     # no interval: never significant


def test_lowest_holds_fails_or_stays_open():
    figures = {("A", 1, "me", "x"): fig(1), ("A", 1, "you", "x"): fig(5),
               ("A", 2, "me", "x"): fig(1), ("A", 2, "you", "x"): fig(2)}
    assert lowest(figures, "me", ["you"], "x", sizes=[1])["verdict"] == HOLDS
    assert lowest(figures, "me", ["you"], "x")["verdict"] == OPEN                  # n=2 overlaps
    assert lowest(figures, "you", ["me"], "x")["verdict"] == FAILS
    assert lowest(figures, "you", ["me"], "x", highest=True)["verdict"] == OPEN
    assert no_worse(figures, "me", ["you"], "x")["verdict"] == HOLDS
    assert no_worse(figures, "you", ["me"], "x")["verdict"] == FAILS
    assert lowest(figures, "me", ["nobody"], "x")["verdict"] == OPEN


def test_no_worse_without_intervals_is_inconclusive():
    nan = float("nan")
    figures = {("A", 1, "me", "x"): Figure(1, nan, nan), ("A", 1, "you", "x"): Figure(5, nan, nan)}
    result = no_worse(figures, "me", ["you"], "x")
    assert result["verdict"] == OPEN and "without an interval" in result["figure"]


def test_thresholds():
    figures = {("A", 1, "zoo:rl-msg", "bf"): fig(0.01, 0.01), ("C", 1, "zoo:rl-msg", "bf"): fig(0.5, 0.1)}
    assert threshold(figures, ["zoo:rl-msg"], "bf", 0.05, above=False, maps=["A"])["verdict"] == HOLDS
    result = threshold(figures, ["zoo:rl-msg"], "bf", 0.05, above=False)
    assert result["verdict"] == FAILS and "map C" in result["figure"]


def test_every_claim_has_a_row_and_the_clear_cases_get_their_verdict(tmp_path):
    rows = []
    for m in "ABCD":
        for n in (1, 2):
            for s, avg, mx, coll, bf, swap in (("CR", 50, 150, 30, 0.0, 25), ("PART", 45, 120, 5, 0.0, 25),
                                               ("SEBS", 40, 100, 3, 0.0, 25),
                                               ("zoo:rl-msg", 30, 60, 1, 0.0, 30),
                                               ("zoo:rl-no-msg", 35, 80, 2, 0.2, 30),
                                               ("zoo:rl-intention", 38, 90, 2, 0.3, 10)):
                for metric, v in (("avg_idleness", avg), ("max_idleness", mx), ("collisions", coll),
                                  ("battery_failure_rate", bf), ("swap_battery_pct", swap)):
                    half = 0.01 if metric == "battery_failure_rate" else 1.0
                    rows.append([m, n, s, metric, v, 0, v - half, v + half])
    figures = read_figures(write_results(tmp_path / "results.csv", rows))
    verdicts = {r["claim"]: r["verdict"] for r in claims(figures)}
    assert len(verdicts) == 10
    assert verdicts["RL-MSG has the lowest MAX^h on every map"] == HOLDS
    assert verdicts["CR collides most"] == HOLDS
    assert verdicts["All learned variants recharge above b_l (battery % at swap > 20)"] == FAILS   # intention at 10
    assert verdicts["RL-MSG's training reward is the highest"] == OPEN                             # no curves
    assert verdicts["The team keeps patrolling when agents fail"] == OPEN                          # no fault run
    assert verdicts["RL-INTENTION is no better than RL-NO-MSG at recharging and worse than RL-MSG at "
                    "patrolling"] == HOLDS


def test_fault_tolerance_reads_the_segments_after_a_failure():
    result = {"strategy": "SEBS", "map": "A", "n_agents": 3, "faults": [[100, 1]],
              "summary": {"segments": [{"start": 0, "end": 101, "max_idleness": {"mean": 20.0}},
                                       {"start": 101, "end": 400, "max_idleness": {"mean": 40.0}}]}}
    assert fault_tolerance(result)["verdict"] == HOLDS
    result["summary"]["segments"][1]["max_idleness"]["mean"] = 350.0        # some vertex never visited again
    assert fault_tolerance(result)["verdict"] == FAILS


def test_the_command_on_a_comparison_and_its_refusals(tmp_path, capsys):
    common = ["compare", "--maps", "A", "--agents", "1-2", "--strategies", "CR,SEBS,zoo:rl-msg", "--episodes",
              "2", "--steps", "60", "--no-progress", "--rerun-zoo", "--out", str(tmp_path / "c")]
    assert cli.main(common) == 0
    assert "## The paper's claims on these figures" in (tmp_path / "c" / "report.md").read_text()
    capsys.readouterr()
    assert cli.main(["claims", str(tmp_path / "c"), "--json", str(tmp_path / "claims.json")]) == 0
    out = capsys.readouterr().out
    assert out.count("\n| ") == 10 and "CR collides most" in out          # ten claims
    assert cli.main(["claims", str(tmp_path / "nothing")]) == 2
    assert "no results.csv" in capsys.readouterr().err
    before = (tmp_path / "c" / "results.csv").read_text()                 # its own input is refused
    assert cli.main(["claims", str(tmp_path / "c"), "--json", str(tmp_path / "c" / "results.csv")]) == 2
    err = capsys.readouterr().err
    assert "--json" in err and "is an input of this command" in err
    assert (tmp_path / "c" / "results.csv").read_text() == before
    assert cli.main(["claims", str(tmp_path / "c"), "--faults-result", str(tmp_path / "c" / "report.md")]) == 2
    assert "not an 'evaluate --json' result" in capsys.readouterr().err
    # compare takes the fault run too, so that the report's table has that row; a bad file
    # stops it before any work, naming the argument
    assert cli.main(common[:-1] + [str(tmp_path / "d"), "--faults-result", str(tmp_path / "none.json")]) == 2
    assert "--faults-result" in capsys.readouterr().err and not (tmp_path / "d").exists()
    faults = {"strategy": "SEBS", "map": "A", "n_agents": 3, "faults": [[20, 1]],
              "summary": {"segments": [{"start": 0, "end": 21, "max_idleness": {"mean": 20.0}},
                                       {"start": 21, "end": 60, "max_idleness": {"mean": 30.0}}]}}
    (tmp_path / "faults.json").write_text(json.dumps(faults))
    assert cli.main(common[:-1] + [str(tmp_path / "d"), "--faults-result", str(tmp_path / "faults.json")]) == 0
    row = [l for l in (tmp_path / "d" / "report.md").read_text().splitlines() if "agents fail" in l][0]
    assert "SEBS on A, n=3" in row and "**holds**" in row


def test_claims_on_the_guarded_entries_only_when_asked(tmp_path, capsys):
    from patrolsb3 import zoo
    if not zoo.available("A", "rl-msg", guard=True):
        pytest.skip("needs the zoo's guarded A/rl-msg")
    assert cli.main(["compare", "--maps", "A", "--agents", "1", "--strategies", "CR,SEBS,zoo:rl-msg:guarded",
                     "--episodes", "1", "--steps", "40", "--no-progress", "--rerun-zoo", "--out", str(tmp_path / "g")]) == 0
    capsys.readouterr()
    first_row = lambda text: next(line for line in text.splitlines() if "lowest MAX^h on every map" in line)
    assert cli.main(["claims", str(tmp_path / "g")]) == 0
    assert "not measured" in first_row(capsys.readouterr().out)      # the shield does not stand for RL-MSG
    assert cli.main(["claims", str(tmp_path / "g"), "--guarded"]) == 0
    assert "not measured" not in first_row(capsys.readouterr().out)  # asked for: it does


@pytest.mark.parametrize("sizes", [[1]])
def test_lowest_restricted_to_sizes(sizes):
    figures = {("A", 1, "me", "x"): fig(1), ("A", 1, "you", "x"): fig(5), ("A", 3, "me", "x"): fig(9),
               ("A", 3, "you", "x"): fig(1)}
    assert lowest(figures, "me", ["you"], "x", sizes=sizes)["verdict"] == HOLDS


def test_the_training_reward_claim_takes_every_seed_as_a_unit(tmp_path):
    from patrolsb3.claims import training_reward

    def curve(name, rewards):
        path = tmp_path / name / "curve.csv"
        path.parent.mkdir(parents=True)
        path.write_text("timesteps,reward\n" + "".join(f"{10 * (i + 1)},{r}\n" for i, r in enumerate(rewards)))
        return path
    msg = [curve(f"msg{k}", [0, 0, 0, 0, v]) for k, v in enumerate((100.0, 101.0, 99.0))]
    nomsg = [curve(f"nomsg{k}", [0, 0, 0, 0, v]) for k, v in enumerate((50.0, 52.0, 48.0))]
    result = training_reward({"A": {"rl-msg": msg, "rl-no-msg": nomsg}})
    assert result["verdict"] == "holds"                          # three seeds each, far apart
    result = training_reward({"A": {"rl-msg": msg, "rl-no-msg": nomsg[:1]}})
    assert result["verdict"] == "inconclusive" and "too few to test" in result["figure"]   # one seed: a figure only


def test_the_figure_says_who_wins_where():
    from patrolsb3.claims import Figure, lowest
    figures = {("A", 1, "zoo:rl-msg", "max_idleness"): Figure(5.0, 4.9, 5.1),
               ("A", 1, "CR", "max_idleness"): Figure(1.0, 0.9, 1.1),
               ("A", 2, "zoo:rl-msg", "max_idleness"): Figure(3.0, 2.0, 4.0),
               ("A", 2, "CR", "max_idleness"): Figure(3.1, 2.1, 4.1)}
    figure = lowest(figures, "zoo:rl-msg", ["CR"], "max_idleness")["figure"]
    assert "significantly beaten in 1 (by CR in 1: A n=1); level in 1" in figure
