"""The table writer on hand-made results."""
import csv


from patrolsb3.report import evaluation_text, mean_std, write_compare


def fake(map_name, n, strategy, max_mean, max_std=0.5):
    metrics = ("avg_idleness", "max_idleness", "worst_idleness", "std_idleness", "collisions",
               "battery_failures", "battery_failure_rate", "swap_battery_pct")
    summary = {m: {"mean": 1.0, "std": 0.0, "tests": [1.0]} for m in metrics}
    summary["max_idleness"] = {"mean": max_mean, "std": max_std, "tests": [max_mean]}
    summary["swap_battery_pct"] = {"mean": float("nan"), "std": float("nan"), "tests": []}
    summary["clean_episodes"] = [4]
    summary["segments"] = []
    return {"strategy": strategy, "map": map_name, "n_agents": n, "episodes": 4, "tests": 1,
            "steps": 10, "summary": summary, "bounds": {"v_over_k": 10.0, "worst": 9.0, "avg": 4.5}}


def test_intervals_over_episodes_are_shown_and_drawn(tmp_path):
    from patrolsb3.stats import mean_interval as interval95
    low, high = interval95([10.0, 12.0, 14.0, 9.0, 15.0, 11.0])
    assert 9.0 < low < 11.8 < high < 15.0
    assert interval95([3.0]) == [3.0, 3.0] and interval95([2.0, 2.0]) == [2.0, 2.0]
    stat = {"mean": 11.8, "std": 0.0, "tests": [11.8], "ci95": [low, high]}
    assert mean_std(stat) == f"11.8 [{low:.1f}, {high:.1f}]"
    results = [fake("B", 1, "CR", 12.5), fake("B", 2, "CR", 7.25)]
    for r in results:
        r["summary"]["max_idleness"]["ci95"] = [r["summary"]["max_idleness"]["mean"] - 1, r["summary"]["max_idleness"]["mean"] + 2]
    write_compare(results, tmp_path, plots=True)
    assert "| 1 | 12.5 [11.5, 14.5] |" in (tmp_path / "report.md").read_text()
    assert (tmp_path / "B.png").stat().st_size > 1000


def test_mean_std_format():
    assert mean_std({"mean": 1.25, "std": 0.5, "tests": [0.75, 1.75]}, 2) == "1.25 +- 0.50"
    assert mean_std({"mean": 1.25, "std": 0.0, "tests": [1.25]}, 2) == "1.25"     # one test: no "+- 0.00"
    assert mean_std({"mean": float("nan"), "std": 0.0}) == ""


def test_write_compare_tables(tmp_path):
    results = [fake("B", 1, "CR", 12.5), fake("B", 2, "CR", 7.25), fake("B", 2, "SEBS", 6.0),
               fake("B", 1, "zoo:rl-msg", 3.0), fake("B", 1, "CYCLIC", 9.0)]
    write_compare(results, tmp_path, plots=False)
    rows = list(csv.reader((tmp_path / "B-MAX.csv").open()))
    assert rows == [["n", "CR", "PART", "SEBS", "INTENTION", "NOMSG", "MSG"],
                    ["1", "12.5", "", "", "", "", "3"],
                    ["2", "7.25", "", "6", "", "", ""]]
    assert list(csv.reader((tmp_path / "B-MAX-extra.csv").open())) == [
        ["n", "RANDOM", "CYCLIC"], ["1", "", "9"], ["2", "", ""]]
    assert list(csv.reader((tmp_path / "B-BLv.csv").open()))[1] == ["1", "", "", "", "", "", ""]
    report = (tmp_path / "report.md").read_text()
    assert "| 1 | 12.5 |  |  |  |  | **3.0** |  | 9.0 |" in report       # one test; the best in bold
    assert "one test, with a 95 % bootstrap interval over the episodes" in report
    long_rows = list(csv.DictReader((tmp_path / "results.csv").open()))
    assert len(long_rows) == 5 * 8


def test_evaluation_text_lists_every_metric():
    text = evaluation_text(fake("A", 3, "SEBS", 42.0))
    for label in ("AVG^h", "MAX^h", "worst idleness", "std across vertices", "collisions / episode",
                  "battery failures / episode", "battery failure rate", "battery % at swap start",
                  "|V|/k", "4 of 4"):
        assert label in text
    assert "| MAX^h (episodes without battery failure) | 42.00 |" in text


def test_report_draws_the_training_figure_of_zoo_curves(tmp_path):
    curve = tmp_path / "curve.csv"
    curve.write_text("timesteps,n_agents,reward\n100,1,-5\n200,2,-3\n")
    results = [fake("B", 1, "CR", 12.5), fake("B", 2, "CR", 7.25)]
    written = write_compare(results, tmp_path / "out", plots=True,
                            learning_curves={"B": {"rl-msg": curve}})
    assert tmp_path / "out" / "B-training.png" in written
    assert "![training on map B](B-training.png)" in (tmp_path / "out" / "report.md").read_text()
    # no curves, no figure
    write_compare(results, tmp_path / "bare", plots=True)
    assert not (tmp_path / "bare" / "B-training.png").exists()


def test_zoo_tables_read_the_comparison(tmp_path):
    from patrolsb3.report import zoo_tables
    zoo_row = fake("A", 2, "zoo:rl-msg", float("nan"))
    zoo_row["summary"]["max_idleness_all"] = {"mean": 321.0, "std": 0.0, "tests": [321.0]}
    write_compare([fake("A", 2, "CR", 7.25), zoo_row], tmp_path, plots=False)
    text = zoo_tables(tmp_path / "results.csv")
    assert "### Map A" in text
    assert "| 2 | zoo:rl-msg |  | 321.0 | 1.0 |  |" in text          # no AVG (all); MAX (no BF) nan
    assert "| 2 | CR |  |  | 1.0 | 7.2 |" in text


def test_clean_figures_say_when_every_episode_had_a_battery_failure():
    from patrolsb3.report import clean_figures
    nan = float("nan")
    every = {"max_idleness": {"mean": nan}, "avg_idleness": {"mean": nan}, "collisions": {"mean": nan}}
    assert clean_figures(every) == "MAX/AVG/col n/a (a battery failure in every episode)"
    some = {"max_idleness": {"mean": 267.1}, "avg_idleness": {"mean": 58.0}, "collisions": {"mean": 422.0}}
    assert clean_figures(some) == "MAX 267.1 AVG 58.0 col 422.00"

