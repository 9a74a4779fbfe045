"""patrolsb3.claims: verdicts from intervals (holds / does not hold / inconclusive), each claim's
cells, and the command."""
import csv
import json

import pytest

import numpy as np

from patrolsb3 import cli
from patrolsb3.claims import (FAILS, HOLDS, OPEN, Figure, claims, difference, fault_tolerance, lowest, no_worse,
                              read_figures, threshold)
from patrolsb3.stats import holm

FIELDS = ["map", "n", "strategy", "metric", "mean", "std", "ci95_low", "ci95_high"]


def write_results(path, rows):
    with path.open("w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(FIELDS)
        writer.writerows(rows)
    return path


def episodes(mean, spread=1.0, seed=0, n=12):
    """n per-episode values around ``mean``: the episode's own noise, drawn from ``seed``."""
    return tuple(mean + spread * np.random.default_rng(seed).standard_normal(n))


def fig(mean, spread=1.0, seed=0, testable=True):
    """A heuristic-like figure: one unit of 12 episodes around ``mean``."""
    return Figure(mean, mean - spread, mean + spread, testable=testable, units=(episodes(mean, spread, seed),))


def test_lowest_holds_fails_or_stays_open():
    figures = {("A", 1, "me", "x"): fig(1, seed=1), ("A", 1, "you", "x"): fig(5, seed=2),
               ("A", 2, "me", "x"): fig(1, seed=3), ("A", 2, "you", "x"): fig(1.2, seed=4)}
    assert lowest(figures, "me", ["you"], "x", sizes=[1])["verdict"] == HOLDS
    assert lowest(figures, "me", ["you"], "x")["verdict"] == OPEN                  # n=2 level
    assert lowest(figures, "you", ["me"], "x")["verdict"] == FAILS
    assert lowest(figures, "you", ["me"], "x", highest=True)["verdict"] == OPEN
    assert no_worse(figures, "me", ["you"], "x")["verdict"] == OPEN               # n=2: level, not shown no worse
    assert no_worse(figures, "you", ["me"], "x")["verdict"] == FAILS
    assert lowest(figures, "me", ["nobody"], "x")["verdict"] == OPEN


def test_pairing_finds_a_small_steady_difference_that_unpaired_intervals_hide():
    hardness = np.linspace(0, 100, 12)                        # some episodes are much harder than others
    me = Figure(49.0, 30.0, 68.0, units=(tuple(hardness - 1.0 + 0.1 * np.sin(np.arange(12))),))
    you = Figure(50.0, 31.0, 69.0, units=(tuple(hardness),))
    d = difference(me, you)
    assert d.high < 0 and d.unit == "episodes"               # paired: clearly lower, by about 1
    assert me.high > you.low                                 # the unpaired intervals overlap widely
    assert lowest({("A", 1, "me", "x"): me, ("A", 1, "you", "x"): you}, "me", ["you"], "x")["verdict"] == HOLDS


def test_holm_adjusts_a_claims_comparisons_for_their_number():
    assert holm([0.01, 0.04, 0.03, 0.005]) == [True, False, False, True]    # a known example
    assert holm([0.04]) == [True] and holm([]) == []
    # three cells each significant alone (p about 0.03) are not, as a family of three
    rng = np.random.default_rng(7)
    base = rng.normal(0, 1, 12)
    figures = {}
    for n in (1, 2, 3):
        noise = rng.normal(0, 1, 12)
        shift = -0.72 * noise.std(ddof=1) - noise.mean()      # a mean difference about 2.2 standard errors
        figures[("A", n, "you", "x")] = Figure(0, -1, 1, units=(tuple(base),))
        figures[("A", n, "me", "x")] = Figure(0, -1, 1, units=(tuple(base + noise + shift),))
    p = [difference(figures[("A", n, "me", "x")], figures[("A", n, "you", "x")]).p for n in (1, 2, 3)]
    assert all(0.01 < v < 0.05 for v in p)
    result = lowest(figures, "me", ["you"], "x")
    assert result["verdict"] == OPEN and "level in 3" in result["figure"]
    assert lowest(figures, "me", ["you"], "x", sizes=[1])["verdict"] == HOLDS      # alone, one is enough


def test_no_worse_holds_only_where_the_data_show_it_within_the_margin():
    shared = np.random.default_rng(5).normal(50, 10, 12)            # the same hard and easy episodes
    you = Figure(50, 45, 55, units=(tuple(shared),))
    close = Figure(50.5, 45, 56, units=(tuple(shared + 0.5 + 0.1 * np.sin(np.arange(12))),))
    assert no_worse({("A", 1, "me", "x"): close, ("A", 1, "you", "x"): you}, "me", ["you"], "x")["verdict"] == HOLDS
    # +0.5 of 50 is inside the 5 % margin (2.5) and tight; +2.3 with wide noise is not shown inside it
    noisy = Figure(52.3, 40, 64, units=(tuple(shared + 2.3 + 3 * np.random.default_rng(6).normal(size=12)),))
    result = no_worse({("A", 1, "me", "x"): noisy, ("A", 1, "you", "x"): you}, "me", ["you"], "x")
    assert result["verdict"] == OPEN and "shown within it in 0 of 1" in result["figure"]
    # worse by far more than the margin, clearly: does not hold
    far = Figure(60, 55, 65, units=(tuple(shared + 10 + 0.1 * np.cos(np.arange(12))),))
    assert no_worse({("A", 1, "me", "x"): far, ("A", 1, "you", "x"): you}, "me", ["you"], "x")["verdict"] == FAILS
    # a cell below the floor keeps the claim open even where every tested cell is shown
    figures = {("A", 1, "me", "x"): close, ("A", 1, "you", "x"): you,
               ("A", 2, "me", "x"): Figure(1, 0, 2, testable=False, units=((1.0,) * 12,)),
               ("A", 2, "you", "x"): Figure(1, 0, 2, units=((1.0,) * 12,))}
    assert no_worse(figures, "me", ["you"], "x")["verdict"] == OPEN


def test_no_worse_without_per_episode_figures_is_inconclusive():
    nan = float("nan")
    figures = {("A", 1, "me", "x"): Figure(1, nan, nan), ("A", 1, "you", "x"): Figure(5, nan, nan)}
    result = no_worse(figures, "me", ["you"], "x")
    assert result["verdict"] == OPEN and "without per-episode figures" in result["figure"]


def test_thresholds():
    rate = "battery_failure_rate"
    none_in = lambda k: Figure(0.0, 0.0, 0.1, units=(tuple([0.0] * k),))
    assert threshold({("A", 1, "zoo:rl-msg", rate): none_in(100)}, ["zoo:rl-msg"], rate, 0.05,
                     above=False)["verdict"] == HOLDS
    # a rate of 0 in 30 does not show a rate of at most 0.05 (its exact upper bound is 0.116)
    assert threshold({("A", 1, "zoo:rl-msg", rate): none_in(30)}, ["zoo:rl-msg"], rate, 0.05,
                     above=False)["verdict"] == OPEN
    figures = {("A", 1, "zoo:rl-msg", rate): none_in(100),
               ("C", 1, "zoo:rl-msg", rate): Figure(0.5, 0.4, 0.6, units=(tuple([0.0, 1.0] * 15),))}
    result = threshold(figures, ["zoo:rl-msg"], rate, 0.05, above=False)
    assert result["verdict"] == FAILS and "map C" in result["figure"]
    swap = {("A", 1, "zoo:rl-msg", "swap_battery_pct"): fig(30.0, spread=2.0)}
    assert threshold(swap, ["zoo:rl-msg"], "swap_battery_pct", 20.0, above=True)["verdict"] == HOLDS


def write_episodes(path, figures):
    """An episodes.csv for ``figures`` ({(map, n, strategy, metric): units})."""
    with path.open("w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(["map", "n", "strategy", "metric", "unit", "episode", "value"])
        for (m, n, s, metric), units in figures.items():
            for k, unit in enumerate(units):
                writer.writerows([m, n, s, metric, k if len(units) > 1 else "", i, v] for i, v in enumerate(unit))


def test_every_claim_has_a_row_and_the_clear_cases_get_their_verdict(tmp_path):
    rows, units = [], {}
    for m in "ABCD":
        for n in (1, 2):
            for s, avg, mx, coll, bf, swap in (("CR", 50, 150, 30, 0.0, 25), ("PART", 45, 120, 5, 0.0, 25),
                                               ("SEBS", 40, 100, 3, 0.0, 25),
                                               ("zoo:rl-msg", 30, 60, 1, 0.0, 30),
                                               ("zoo:rl-no-msg", 35, 80, 2, 0.2, 30),
                                               ("zoo:rl-intention", 38, 90, 2, 0.3, 10)):
                seeds = 3 if s.startswith("zoo:") else 1
                for metric, v in (("avg_idleness", avg), ("max_idleness", mx), ("collisions", coll),
                                  ("battery_failure_rate", bf), ("swap_battery_pct", swap)):
                    rows.append([m, n, s, metric, v, 0, v - 1, v + 1])
                    if metric == "battery_failure_rate":      # every 1/bf-th episode fails
                        one = tuple(float(i % round(1 / bf) == 0) if bf else 0.0 for i in range(40))
                        units[(m, n, s, metric)] = (one,) * seeds
                    else:
                        units[(m, n, s, metric)] = tuple(episodes(v, 0.5, seed=k, n=40) for k in range(seeds))
    write_episodes(tmp_path / "episodes.csv", units)
    rows = [r + [40, 3 if r[2].startswith("zoo:") else ""] for r in rows]
    with (tmp_path / "results.csv").open("w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(FIELDS + ["episodes", "training_seeds"])
        writer.writerows(rows)
    figures = read_figures(tmp_path / "results.csv")
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
    # and how the zoo column was trained (the zoo's A/rl-msg: c_d 200, not the paper's 10)
    assert "Trained with" in out and "- map A, RL-MSG: " in out and "(c_d 200, gamma 0.99" in out
    assert "trained with " in (tmp_path / "c" / "report.md").read_text()
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
    if not zoo.available("A", "rl-msg", shelf="guarded"):
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
    figures = {("A", 1, "zoo:rl-msg", "max_idleness"): fig(5.0, 0.1, seed=1),
               ("A", 1, "CR", "max_idleness"): fig(1.0, 0.1, seed=2),
               ("A", 2, "zoo:rl-msg", "max_idleness"): fig(3.0, seed=3),
               ("A", 2, "CR", "max_idleness"): fig(3.1, seed=4)}
    figure = lowest(figures, "zoo:rl-msg", ["CR"], "max_idleness")["figure"]
    assert "significantly beaten in 1 (by CR in 1: A n=1); level in 1" in figure


def test_a_rival_below_the_floor_leaves_the_others_tested():
    """A one-seed zoo column in a cell does not hide that a heuristic there is clearly better."""
    figures = {("A", 1, "me", "x"): fig(10, seed=1), ("A", 1, "you", "x"): fig(1, seed=2),
               ("A", 1, "one-seed", "x"): fig(5, seed=3, testable=False)}
    result = lowest(figures, "me", ["you", "one-seed"], "x")
    assert result["verdict"] == FAILS and "by you in 1" in result["figure"]
    assert "1 cells too few to test" in result["figure"] and "level in 0" in result["figure"]
    # and it cannot be won against every rival: the winner's claim stays open
    assert lowest(figures, "you", ["me", "one-seed"], "x")["verdict"] == OPEN
