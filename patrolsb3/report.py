"""The one writer of every table and plot of evaluations.

* :func:`evaluation_text` — the terminal / markdown table of one ``evaluate()`` result.
* :func:`write_compare` — per map the paper's CSV tables ``<MAP>-BF.csv``, ``-BLv.csv``,
  ``-MAX.csv``, ``-MEAN.csv``, ``-COLLISION.csv`` with columns ``n,CR,PART,SEBS,INTENTION,
  NOMSG,MSG`` (cells are means over tests; a strategy that was not run is an empty cell; the
  column names are the paper's data-file names, which its LaTeX tables read, while every table
  of ``report.md`` and every plot says RL-INTENTION, RL-NO-MSG, RL-MSG: :mod:`patrolsb3.names`),
  the same tables for the extra strategies in ``<MAP>-<TABLE>-extra.csv`` (columns
  ``n,RANDOM,CYCLIC``), every figure with its std over tests and its 95 % interval over
  episodes in ``results.csv`` (long format), one
  ``report.md`` with all tables as mean +- std, and one PNG per map (idleness per team size,
  collisions, battery).
"""
from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np

from .claims import PAIRED_METRICS, claims, claims_table, read_figures
from .core.streams import STREAMS_VERSION
from .learning_curves import plot_learning_curves
from .names import CSV_COLUMNS, SHELVES, VARIANT_NAMES, display_name, is_learned, shelf_column, strategy_name
from .runs import ComparisonFolder

PAPER_TABLES = {"BF": "battery_failure_rate", "BLv": "swap_battery_pct", "MAX": "max_idleness",
                "MEAN": "avg_idleness", "COLLISION": "collisions"}
"""Paper table suffix -> metric key of the summary."""
PAPER_COLUMNS = ("CR", "PART", "SEBS", "INTENTION", "NOMSG", "MSG")
EXTRA_COLUMNS = ("RANDOM", "CYCLIC")
ZOO_COLUMNS = {column: strategy_name(CSV_COLUMNS[column]) for column in ("INTENTION", "NOMSG", "MSG")}
"""Paper column -> strategy name that fills it (the zoo entries in the paper's setting)."""
SHELF_COLUMNS = {shelf_column(column, shelf): strategy_name(CSV_COLUMNS[column], shelf)
                 for shelf in SHELVES for column in ZOO_COLUMNS}
"""Extra columns of the entries on the zoo's shelves (``MSG-GUARDED``, ``MSG-PAPER-RECIPE``, ...),
present only when a comparison has them."""
LABELS = {"avg_idleness": "AVG^h", "max_idleness": "MAX^h", "worst_idleness": "worst idleness",
          "std_idleness": "std across vertices", "collisions": "collisions / episode",
          "battery_failures": "battery failures / episode",
          "battery_failure_rate": "battery failure rate", "swap_battery_pct": "battery % at swap start"}


def column_strategy(column: str) -> str:
    """Strategy name behind a table column (heuristic names are their own)."""
    return ZOO_COLUMNS.get(column, SHELF_COLUMNS.get(column, column))


def mean_std(stat: dict, digits: int = 1) -> str:
    """'mean +- std' of a summary entry (std over tests), the mean alone when there is one test
    (no spread to show), '' when missing or nan."""
    if not stat or stat.get("mean") is None or math.isnan(stat["mean"]):
        return ""
    ci = stat.get("ci95")
    interval = (f" [{ci[0]:.{digits}f}, {ci[1]:.{digits}f}]" if ci and not math.isnan(ci[0]) else "")
    if len(stat.get("tests", [])) <= 1:
        return f"{stat['mean']:.{digits}f}{interval}"
    return f"{stat['mean']:.{digits}f} +- {stat['std']:.{digits}f}{interval}"


LOWER_IS_BETTER = ("avg_idleness", "max_idleness", "worst_idleness", "collisions", "battery_failures",
                   "battery_failure_rate")
"""Metrics whose best value in a table row (the lowest) is marked in bold."""


def _best_marked(cells: list[str], stats: list, metric: str) -> list[str]:
    """Bold the best (lowest) mean of a row for the metrics of LOWER_IS_BETTER (ties all bold;
    a row where every value is equal is left plain)."""
    if metric not in LOWER_IS_BETTER:
        return cells
    means = [s["mean"] if s and s.get("mean") is not None and not math.isnan(s["mean"]) else None for s in stats]
    present = [m for m in means if m is not None]
    if len(present) < 2 or min(present) == max(present):   # nothing to tell apart
        return cells
    best = min(present)
    return [f"**{c}**" if m is not None and m == best else c for c, m in zip(cells, means)]


def evaluation_text(result: dict) -> str:
    """A markdown table of one evaluation, with the bounds and fault segments."""
    s = result["summary"]
    tests, episodes = result["tests"], result["episodes"]
    lines = [f"{result['strategy']} on map {result['map']}, {result['n_agents']} agent(s): "
             f"{tests} test(s) x {episodes} episodes x {result['steps']} steps (mean, +- std over tests "
             f"when several, [95 % bootstrap interval over the episodes])",
             "", "| metric | value |", "|---|---|"]
    for key, label in LABELS.items():
        digits = 3 if key == "battery_failure_rate" else 2
        note = " (episodes without battery failure)" if key in ("avg_idleness", "max_idleness",
                                                                "worst_idleness", "std_idleness",
                                                                "collisions") else ""
        lines.append(f"| {label}{note} | {mean_std(s[key], digits)} |")
    clean = s["clean_episodes"]
    lines.append(f"| episodes without battery failure | {sum(clean)} of {tests * episodes} |")
    b = result["bounds"]
    lines.append(f"| lower bound |V|/k | {b['v_over_k']:.1f} (worst idleness >= {b['worst']:.0f}, "
                 f"AVG^h and MAX^h >= {b['avg']:.1f}) |")
    for seg in s.get("segments", []):
        lines.append(f"| steps {seg['start']}-{seg['end']}: AVG^h / MAX^h | "
                     f"{mean_std(seg['avg_idleness'])} / {mean_std(seg['max_idleness'])} |")
    return "\n".join(lines)


def _table_rows(results: list[dict], map_name: str, metric: str, columns) -> list[list]:
    by_key = {(r["map"], r["n_agents"], r["strategy"]): r for r in results}
    ns = sorted({r["n_agents"] for r in results if r["map"] == map_name})
    rows = []
    for n in ns:
        row = [n]
        for col in columns:
            r = by_key.get((map_name, n, column_strategy(col)))
            row.append(r["summary"][metric] if r else None)
        rows.append(row)
    return rows


def clean_figures(summary: dict, precision: int = 1) -> str:
    """MAX, AVG and collisions over episodes without a battery failure (the paper's tables) as
    text, or a note when every episode had one (those figures are NaN then).

    Args:
        summary: an ``evaluate()``-style summary (``{"max_idleness": {"mean": ...}, ...}``).
        precision: decimals of MAX and AVG; collisions get one more.
    """
    if math.isnan(summary["max_idleness"]["mean"]):
        return "MAX/AVG/col n/a (a battery failure in every episode)"
    return (f"MAX {summary['max_idleness']['mean']:.{precision}f} AVG {summary['avg_idleness']['mean']:.{precision}f} "
            f"col {summary['collisions']['mean']:.{precision + 1}f}")


def write_compare(results: list[dict], out_dir, plots: bool = True, learning_curves=None,
                  zoo_notes: dict | None = None, faults_result: dict | None = None) -> list[Path]:
    """Write every table, the report and the plots of a comparison.

    Args:
        results: ``evaluate()`` results (any maps, team sizes and strategies).
        out_dir: output folder (created).
        plots: also draw the PNG plots.
        learning_curves: map -> {variant: curve.csv path}; draws the paper's training figure
            (``<MAP>-training.png``) for maps that have any.
        zoo_notes: (map, strategy) -> a line about a zoo column (its setting and whether its
            figures were computed now or reused), printed in the report.
        faults_result: an ``evaluate`` result with scheduled faults, for the claims table's
            row on failing agents (:func:`patrolsb3.claims.read_faults_result`).

    Returns:
        The paths written.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    written = []
    maps = sorted({r["map"] for r in results})
    md = ["# Strategy comparison", ""]
    if results:
        r0 = results[0]
        spread = ("mean +- std over tests" if r0["tests"] > 1 else "one test") + \
            ", with a 95 % bootstrap interval over the episodes in brackets where the result has one " \
            "(results computed before 2026-12-02 have none; a zoo column that pools several training " \
            "seeds: Student's t over the seeds' means, see the notes below)"
        md += [f"{r0['tests']} test(s) x {r0['episodes']} episodes x {r0['steps']} steps per "
               f"(map, strategy, team size); {spread}. Idleness and collision figures "
               f"average over episodes without a battery failure (counts in results.csv). The best "
               f"(lowest) value of each row is in bold, ties all bold, a row of equal values plain; BLv "
               f"(battery at swap) has no best: a higher level is safer, a lower one uses more of each "
               f"battery, and the paper asks only that it stay above b_l.", ""]
        learned = [r for r in results if is_learned(r.get("strategy", ""))]
        if learned:
            sampled = any(r.get("deterministic", True) is False for r in learned)
            md += [f"Zoo models {'sample their actions from the policy' if sampled else 'take their most likely legal action'}"
                   f" ({'--stochastic' if sampled else 'deterministic, the default'}).", ""]
            for (m, strategy), note in sorted((zoo_notes or {}).items()):
                md.append(f"- map {m}, {strategy}: {note}")
            if zoo_notes:
                md.append("")
    strategies = {r.get("strategy") for r in results}
    extra_columns = EXTRA_COLUMNS + tuple(c for c, s in SHELF_COLUMNS.items() if s in strategies)
    for m in maps:
        for suffix, metric in PAPER_TABLES.items():
            md += [f"## Map {m}: {suffix} ({LABELS[metric]})", ""]
            for columns, name in ((PAPER_COLUMNS, f"{m}-{suffix}.csv"),
                                  (extra_columns, f"{m}-{suffix}-extra.csv")):
                rows = _table_rows(results, m, metric, columns)
                path = out / name
                with path.open("w", newline="") as fh:
                    writer = csv.writer(fh)
                    writer.writerow(["n", *columns])
                    for row in rows:
                        writer.writerow([row[0]] + ["" if s is None or math.isnan(s["mean"])
                                                    else f"{s['mean']:.6g}" for s in row[1:]])
                written.append(path)
            rows_all = _table_rows(results, m, metric, PAPER_COLUMNS + extra_columns)
            digits = 3 if metric == "battery_failure_rate" else 1
            md.append("| n | " + " | ".join(display_name(c) for c in PAPER_COLUMNS + extra_columns) + " |")
            md.append("|---" * (1 + len(PAPER_COLUMNS + extra_columns)) + "|")
            for row in rows_all:
                cells = _best_marked([mean_std(s, digits) for s in row[1:]], row[1:], metric)
                md.append(f"| {row[0]} | " + " | ".join(cells) + " |")
            md.append("")
        if plots:
            png = plot_map(results, m, out / f"{m}.png")
            md += [f"![map {m}]({png.name})", ""]
            written.append(png)
            curves = (learning_curves or {}).get(m)
            if curves:
                png = plot_learning_curves(curves, out / f"{m}-training.png", title=f"map {m}: training")
                md += [f"### Map {m}: learning curves of the zoo models", "",
                       f"![training on map {m}]({png.name})", ""]
                written.append(png)
    long_path = ComparisonFolder(out).results_csv
    with long_path.open("w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(["map", "n", "strategy", "metric", "mean", "std", "ci95_low", "ci95_high",
                         "clean_episodes", "episodes", "tests", "steps", "deterministic", "training_seeds"])
        for r in results:
            metrics = [m for m, v in r["summary"].items() if isinstance(v, dict) and "mean" in v]
            for metric in metrics:                 # LABELS' metrics and their *_all twins
                s = r["summary"][metric]
                low, high = s.get("ci95") or ("", "")   # results stored before the intervals have none
                seeds = len(r.get("training_seeds") or [0]) if is_learned(r["strategy"]) else ""
                writer.writerow([r["map"], r["n_agents"], r["strategy"], metric, s["mean"], s["std"], low, high,
                                 sum(r["summary"]["clean_episodes"]), r["episodes"] * r["tests"],
                                 r["tests"], r["steps"], r.get("deterministic", True), seeds])
    written.append(long_path)
    written.append(write_episodes(results, ComparisonFolder(out).episodes_csv))
    if any(is_learned(r.get("strategy", "")) for r in results):   # the claims head the report
        rows = claims(read_figures(long_path), curves=learning_curves, faults_result=faults_result)
        md[2:2] = ["## The paper's claims on these figures", "",
                   "One row per claim (`patrolsb3 claims`, which says how each verdict is reached).", "",
                   claims_table(rows), ""]
    report = ComparisonFolder(out).report
    report.write_text("\n".join(md) + "\n")
    written.append(report)
    return written


def write_episodes(results: list[dict], path) -> Path:
    """Write the per-episode values the claims pair (:data:`patrolsb3.claims.PAIRED_METRICS`) as a
    long CSV: map, n, strategy, metric, unit (a zoo column's training seed; empty for a
    heuristic or a single model), episode (its index in the evaluation, the same episode for
    every strategy: :mod:`patrolsb3.core.streams`), value (empty where the metric does not count
    the episode). Results evaluated before the paired streams (no ``draws`` field) are left out:
    their episodes do not pair."""
    path = Path(path)
    with path.open("w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(["map", "n", "strategy", "metric", "unit", "episode", "value"])
        for r in results:
            if r.get("draws") != STREAMS_VERSION:
                continue
            for metric in PAIRED_METRICS:
                s = r["summary"].get(metric)
                if not isinstance(s, dict) or "episodes" not in s:
                    continue
                units = s.get("units") or [s["episodes"]]
                labels = r.get("training_seeds") if s.get("units") else [""]
                for label, values in zip(labels, units):
                    for i, v in enumerate(values):
                        writer.writerow([r["map"], r["n_agents"], r["strategy"], metric, label, i,
                                         "" if v is None or not math.isfinite(float(v)) else v])
    return path


def _error_bars(rows: list[dict], metric: str, means: np.ndarray):
    """(2, n) distances to the 95 % interval over episodes where the results have one, else the
    std over tests where there are several, else None."""
    intervals = [r["summary"][metric].get("ci95") for r in rows]
    if all(ci is not None for ci in intervals):
        low, high = np.array(intervals, dtype=float).T
        return np.nan_to_num(np.vstack([means - low, high - means]).clip(min=0))
    if rows and len(rows[0]["summary"][metric].get("tests", [])) > 1:
        return [r["summary"][metric]["std"] for r in rows]
    return None


LEARNED_MARKERS = {"rl-msg": "s", "rl-no-msg": "^", "rl-intention": "D"}
"""Markers of the learned variants' lines (a heuristic's is a circle), so that they are told
apart without colour."""

ERROR_BAR_CAPTION = ("error bars: 95 % interval of the mean (a heuristic's over its episodes; a zoo column of "
                     "several training seeds: over the seeds' means); exact binomial for the battery failure rate")


def plot_map(results: list[dict], map_name: str, path) -> Path:
    """One PNG per map, a grid of panels: MAX^h, AVG^h, collisions, battery failure rate and
    battery % at swap start against team size, one line per strategy with its 95 % interval, and
    the legend in a panel of its own (it hides no data). Idleness and collisions on a log scale,
    so that RANDOM (thousands) does not flatten the others; the battery failure rate from 0 to 1.
    The zoo models dashed, each variant with a marker of its own; the heuristics solid, circles."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    panels = ("max_idleness", "avg_idleness", "collisions", "battery_failure_rate", "swap_battery_pct")
    fig, grid = plt.subplots(2, 3, figsize=(12, 7))
    axes, legend_ax = list(grid.flat[:len(panels)]), grid.flat[len(panels)]
    rows = [r for r in results if r["map"] == map_name]
    for strategy in sorted({r["strategy"] for r in rows}):
        mine = sorted((r for r in rows if r["strategy"] == strategy), key=lambda r: r["n_agents"])
        ns = [r["n_agents"] for r in mine]
        learned = is_learned(strategy)
        variant = strategy.split(":")[1] if learned else ""
        style = dict(marker=LEARNED_MARKERS.get(variant, "s") if learned else "o", linestyle="--" if learned else "-",
                     linewidth=2.0 if learned else 1.2, capsize=3, label=display_name(strategy))
        for ax, metric in zip(axes, panels):
            means = np.array([r["summary"][metric]["mean"] for r in mine], dtype=float)
            ax.errorbar(ns, means, yerr=_error_bars(mine, metric, means), **style)
    for ax, metric in zip(axes, panels):
        if metric in ("max_idleness", "avg_idleness", "collisions"):
            ax.set_yscale("symlog" if metric == "collisions" else "log")
        if metric == "battery_failure_rate":
            ax.set_ylim(0.0, max(0.1, min(1.0, ax.get_ylim()[1])))
        ax.set_title(LABELS[metric] + (" (log)" if metric in ("max_idleness", "avg_idleness", "collisions") else ""))
        ax.set_xlabel("agents")
        ax.grid(alpha=0.3)
    handles, labels = axes[0].get_legend_handles_labels()
    legend_ax.axis("off")
    legend_ax.legend(handles, labels, loc="center", fontsize=9, title=f"map {map_name}")
    fig.suptitle(f"map {map_name}")
    fig.text(0.5, 0.005, ERROR_BAR_CAPTION, ha="center", fontsize=8)
    fig.tight_layout(rect=(0, 0.02, 1, 1))
    fig.savefig(path, dpi=80)
    plt.close(fig)
    return Path(path)


ZOO_TABLE_METRICS = (("avg_idleness_all", "AVG^h (all)", 1), ("max_idleness_all", "MAX^h (all)", 1),
                     ("avg_idleness", "AVG^h (no BF)", 1), ("max_idleness", "MAX^h (no BF)", 1),
                     ("collisions_all", "collisions", 1), ("battery_failure_rate", "BF rate", 2),
                     ("battery_failures", "failures / ep", 2), ("swap_battery_pct", "battery % at swap", 1))
"""Columns of the zoo README's tables: (metric, header, digits)."""


def zoo_tables(results_csv, strategies=(*map(strategy_name, VARIANT_NAMES), "CR", "PART",
                                        "SEBS", "CYCLIC")) -> str:
    """Markdown tables, one per map, of zoo models against the heuristics, read from a
    comparison's ``results.csv``: rows (n, strategy), columns :data:`ZOO_TABLE_METRICS`.
    "(all)" averages over every episode, "(no BF)" over episodes without a battery failure
    (the paper's convention; empty when every episode had one)."""
    value = {key: figure.mean for key, figure in read_figures(results_csv).items()}
    out = []
    for m in sorted({k[0] for k in value}):
        present = [s for s in strategies if any(k[0] == m and k[2] == s for k in value)]
        ns = sorted({k[1] for k in value if k[0] == m})
        out += [f"### Map {m}", "", "| n | strategy | " + " | ".join(h for _, h, _ in ZOO_TABLE_METRICS) + " |",
                "|---" * (2 + len(ZOO_TABLE_METRICS)) + "|"]
        for n in ns:
            for s in present:
                cells = []
                for metric, _, digits in ZOO_TABLE_METRICS:
                    v = value.get((m, n, s, metric))
                    cells.append("" if v is None or math.isnan(v) else f"{v:.{digits}f}")
                out.append(f"| {n} | {s} | " + " | ".join(cells) + " |")
        out.append("")
    return "\n".join(out)
