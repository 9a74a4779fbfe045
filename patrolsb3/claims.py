"""The paper's claims, one row each, tested on a comparison's figures (``patrolsb3 claims``).

Read from a comparison folder (``patrolsb3 compare``): ``results.csv`` (every map, team size,
strategy and metric with its mean and 95 % interval) and ``episodes.csv`` (the per-episode
values, episode ``i`` the same draws for every strategy: :mod:`patrolsb3.core.streams`).
Idleness and collisions follow the paper's convention (episodes without a battery failure).

**The verdict rule** (docs/zoo.md, "How a verdict is reached"):

- Each comparison of two strategies in a cell (map, team size) is paired: the interval of the
  mean per-episode difference, with the training seed as the unit wherever a zoo column pools
  several (:func:`patrolsb3.stats.paired_difference`), and its two-sided p-value.
- A cell takes part only if it is testable: at least 10 episodes, and for a zoo column at least
  3 training seeds (fewer: "too few to test"; one seed gives a figure, not a verdict).
- A claim's condition is one family: Holm's procedure over all its comparisons (every cell and
  rival) at a family-wise 5 % (:func:`patrolsb3.stats.holm`); a difference is significant when
  Holm rejects "no difference", in the direction of its sign.
- A claim that X is lowest **holds** when X is significantly lower than every rival in every
  testable cell, **does not hold** when some rival is significantly lower than X in some cell,
  and is **inconclusive** otherwise (also when no cell is testable). "No worse" holds when no
  rival is significantly better anywhere and every cell was tested.
- A threshold (a battery failure rate of at most 0.05; a battery at swap above b_l) is tested
  per cell one-sided each way (a rate exactly, over the episodes of every seed; a mean by t over
  the seeds, or the episodes of a heuristic), Holm over the cells for each direction: it holds
  when every cell is significantly on the claimed side, fails when one is significantly on the
  other.
"""
from __future__ import annotations

import csv
import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .names import VARIANT_NAMES, display_name, strategy_name
from .runs import ComparisonFolder, read_curve
from .stats import MIN_SEEDS, RATE_METRICS, Difference, holm, paired_difference, seed_interval, testable

MSG, NOMSG, INTENTION = (strategy_name(variant) for variant in VARIANT_NAMES)
LEARNED = (MSG, NOMSG, INTENTION)
HEURISTICS = ("CR", "PART", "SEBS")
PAPER_STRATEGIES = HEURISTICS + LEARNED
LABEL = {name: display_name(name) for name in PAPER_STRATEGIES}
"""How each strategy is named in a claim (:func:`patrolsb3.names.display_name`)."""
NO_WORSE_MARGIN = 0.05
"""A claim that a strategy is "no worse" holds where it is shown to be at most this fraction of
each rival's figure worse (a non-inferiority margin; the paper gives none)."""
NEAR_ZERO = 0.05
"""A battery failure rate 'near zero' (the paper's word) is at most this."""
HOLDS, FAILS, OPEN = "holds", "does not hold", "inconclusive"


PAIRED_METRICS = ("max_idleness", "avg_idleness", "collisions", "battery_failure_rate", "swap_battery_pct")
"""The metrics the claims test, whose per-episode values a comparison keeps in episodes.csv."""


@dataclass(frozen=True)
class Figure:
    """A mean with its 95 % interval (nan when unknown), whether its cell has enough episodes and
    training seeds to decide a comparison (:func:`patrolsb3.stats.testable`), and its units: one
    tuple of per-episode values per training seed (one for a heuristic), aligned by episode, or
    None where the comparison kept none (then it cannot be paired)."""
    mean: float
    low: float
    high: float
    testable: bool = True
    units: tuple | None = None

    def text(self, digits: int = 1) -> str:
        if math.isnan(self.mean):
            return "-"
        if math.isnan(self.low):
            return f"{self.mean:.{digits}f}"
        return f"{self.mean:.{digits}f} [{self.low:.{digits}f}, {self.high:.{digits}f}]"


def difference(a: Figure, b: Figure) -> Difference | None:
    """The paired difference a - b (:func:`patrolsb3.stats.paired_difference`), None when either
    has no per-episode values."""
    if a.units is None or b.units is None:
        return None
    return paired_difference(a.units, b.units)


def read_figures(results_csv) -> dict:
    """{(map, n, strategy, metric): Figure} of a comparison's results.csv.

    Raises:
        FileNotFoundError: no results.csv there (names it).
        ValueError: a results.csv that is cut, damaged or of another kind (names it).
    """
    path = Path(results_csv)
    if path.is_dir():
        path = ComparisonFolder(path).results_csv
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no results.csv; run 'patrolsb3 compare ... --out DIR' first")

    def number(text) -> float:
        try:
            return float(text)
        except (TypeError, ValueError):
            return float("nan")
    needed = ("map", "n", "strategy", "metric", "mean")
    try:
        with path.open(newline="") as f:
            reader = csv.DictReader(f)
            if reader.fieldnames is None or not set(needed) <= set(reader.fieldnames):
                raise ValueError(f"its columns are {reader.fieldnames}, not {list(needed)} ...")
            figures = {(r["map"], int(r["n"]), r["strategy"], r["metric"]):
                       Figure(number(r["mean"]), number(r.get("ci95_low")), number(r.get("ci95_high")),
                              _testable(r)) for r in reader}
    except (ValueError, TypeError, UnicodeDecodeError, csv.Error) as exc:
        raise ValueError(f"{path}: not a results.csv written by 'patrolsb3 compare', or cut or damaged ({exc}); "
                         f"run the comparison again") from None
    if not figures:
        raise ValueError(f"{path}: holds no results; run the comparison again")
    units = read_episodes(path.with_name(ComparisonFolder.EPISODES_CSV))
    return {key: dataclasses.replace(f, units=units.get(key)) for key, f in figures.items()}


def read_episodes(episodes_csv) -> dict:
    """{(map, n, strategy, metric): units} of a comparison's episodes.csv (:func:`patrolsb3.report.write_episodes`):
    each unit a tuple of per-episode values (NaN where not counted), in unit order; {} when
    there is no such file (a comparison from before paired episodes).

    Raises:
        ValueError: a damaged episodes.csv (names it).
    """
    path = Path(episodes_csv)
    if not path.is_file():
        return {}
    found: dict = {}
    try:
        with path.open(newline="") as f:
            for r in csv.DictReader(f):
                key = (r["map"], int(r["n"]), r["strategy"], r["metric"])
                value = float(r["value"]) if r["value"].strip() else float("nan")
                found.setdefault(key, {}).setdefault(r["unit"], {})[int(r["episode"])] = value
    except (ValueError, KeyError, TypeError, UnicodeDecodeError, csv.Error) as exc:
        raise ValueError(f"{path}: not an episodes.csv written by 'patrolsb3 compare', or cut or damaged "
                         f"({exc}); run the comparison again") from None
    return {key: tuple(tuple(by_episode[i] for i in sorted(by_episode)) for by_episode in by_unit.values())
            for key, by_unit in found.items()}


def _testable(row: dict) -> bool:
    """A results.csv row's cell has the episodes and training seeds to decide (a file written
    before those columns existed: yes, as it was read then)."""
    episodes = int(row["episodes"]) if (row.get("episodes") or "").strip() else 10 ** 9
    seeds = (row.get("training_seeds") or "").strip()
    return testable(episodes, int(seeds) if seeds else None)


def _cells(figures: dict, who: str, metric: str, maps=None, sizes=None) -> list[tuple[str, int]]:
    return sorted({(m, n) for (m, n, s, k) in figures if s == who and k == metric
                   and (maps is None or m in maps) and (sizes is None or n in sizes)
                   and not math.isnan(figures[(m, n, s, k)].mean)})


def _comparisons(figures: dict, who: str, rivals, metric: str, maps=None, sizes=None):
    """Every paired comparison of ``who`` with its rivals, cell by cell.

    A cell where ``who`` is below the floor is not tested. A cell where only some rivals are
    below it is tested against the others (a rival there can still be shown better), but it
    counts as too few to test: it cannot be won against every rival.

    Returns:
        compared (cells with a rival), too_few (cells with ``who`` or a rival below the floor),
        unmeasured (cells with a comparison that has no per-episode figures), tested [((m, n),
        rival, Difference of who - rival)] and cells [((m, n), rivals in it)] of the cells
        tested against every rival.
    """
    compared = too_few = unmeasured = 0
    tested, cells = [], []
    for m, n in _cells(figures, who, metric, maps, sizes):
        mine = figures[(m, n, who, metric)]
        others = {r: figures[(m, n, r, metric)] for r in rivals if (m, n, r, metric) in figures
                  and r != who and not math.isnan(figures[(m, n, r, metric)].mean)}
        if not others:
            continue
        compared += 1
        testable = {r: o for r, o in others.items() if o.testable} if mine.testable else {}
        if len(testable) < len(others):
            too_few += 1
        diffs = {r: difference(mine, o) for r, o in testable.items()}
        if any(d is None for d in diffs.values()):
            unmeasured += 1
        if testable and len(testable) == len(others):
            cells.append(((m, n), list(others)))
        tested += [((m, n), r, d) for r, d in diffs.items() if d is not None]
    return compared, too_few, unmeasured, tested, cells


def lowest(figures: dict, who: str, rivals, metric: str, maps=None, sizes=None, highest: bool = False,
           comparisons=None) -> dict:
    """Whether ``who`` has the lowest (or ``highest``) ``metric`` against ``rivals`` in every
    cell: {"verdict", "figure", "cells"} (the verdict rule: module docstring). The figure says who
    wins where: the cells where ``who`` is best, each rival that beats it and in which cells, the
    level cells, and one example with the paired difference. ``comparisons``: what
    :func:`_comparisons` returned for these arguments, when the caller has it already."""
    compared, too_few, unmeasured, tested, cells = comparisons or _comparisons(figures, who, rivals, metric, maps, sizes)
    if compared == 0:
        return {"verdict": OPEN, "figure": "not measured (no such cells in this comparison)", "cells": 0}
    significant = holm([d.p for _, _, d in tested])
    sign = 1.0 if highest else -1.0                  # a win is a difference of this sign
    won = {(cell, r) for (cell, r, d), sig in zip(tested, significant) if sig and sign * d.mean > 0}
    lost = {(cell, r): d for (cell, r, d), sig in zip(tested, significant) if sig and sign * d.mean < 0}
    wins = sum(all((cell, r) in won for r in rivals_here) for cell, rivals_here in cells)
    losing_cells = sorted({cell for cell, _ in lost})
    beaten_by = {}
    for (cell, r) in sorted(lost):
        beaten_by.setdefault(r, []).append(_where(cell))
    level = sum(cell not in losing_cells and not all((cell, r) in won for r in rivals_here)
                for cell, rivals_here in cells)         # tested against every rival, neither won nor lost
    word = "highest" if highest else "lowest"
    figure = f"significantly {word} in {wins} of {compared} cells; significantly beaten in {len(losing_cells)}"
    if beaten_by:            # who wins where
        figure += " (" + "; ".join(f"by {LABEL.get(r, r)} in {len(c)}: {', '.join(c)}" for r, c in beaten_by.items()) + ")"
    figure += f"; level in {level}"
    example = None
    if tested:               # one cell: both figures with their intervals, and the paired difference
        if lost or won:      # a significant one; else the comparison nearest to significance
            shown = min(lost) if lost else min(won)
            note = ""
        else:
            cell, r, _ = min(tested, key=lambda c: c[2].p)
            shown, note = (cell, r), ", not significant after Holm"
        (cell, r), d = shown, next(d for c, rr, d in tested if (c, rr) == shown)
        mine, theirs = (figures[(*cell, s, metric)] for s in (who, r))
        example = (f"map {_where(cell)}: {LABEL.get(who, who)} {mine.text()} vs {LABEL.get(r, r)} {theirs.text()}, "
                   f"paired difference {d.text()} over {d.unit}, p = {d.p:.2g}{note}")
    if tested:
        figure += f"; Holm over {len(tested)} comparisons"
    figure += _untested_and_example(unmeasured, too_few, example)
    verdict = FAILS if lost else HOLDS if wins == compared else OPEN
    return {"verdict": verdict, "figure": figure, "cells": compared, "unmeasured": unmeasured}


def _where(cell) -> str:
    m, n = cell
    return f"{m}" + (f" n={n}" if n else "")


def _untested_and_example(unmeasured: int, too_few: int, example: str | None) -> str:
    """The tail of a claim's figure: the cells without an interval, those below the floor, an example."""
    tail = f"; {unmeasured} cells without per-episode figures to pair" if unmeasured else ""
    if too_few:
        tail += f"; {too_few} cells too few to test (fewer than 3 training seeds or 10 episodes)"
    return tail + (f" (e.g. {example})" if example else "")


def no_worse(figures: dict, who: str, rivals, metric: str, maps=None, margin: float = NO_WORSE_MARGIN) -> dict:
    """Whether ``who`` is no worse (no higher ``metric``) than any rival in any cell, within
    ``margin`` times the rival's mean (a non-inferiority margin).

    Each comparison is tested one-sided each way against that bound
    (:meth:`patrolsb3.stats.Difference.p_below`, ``p_above``), Holm over the claim's comparisons
    for each side. Does not hold where some rival is shown better by more than the margin. Holds
    where every cell is testable and every comparison shows ``who`` within the margin. Otherwise
    inconclusive: not significantly worse is not shown to be no worse. The figure also says who
    wins where with no margin (:func:`lowest`).
    """
    comparisons = _comparisons(figures, who, rivals, metric, maps)
    result = lowest(figures, who, rivals, metric, maps, comparisons=comparisons)
    if not result["cells"]:
        return result
    _, too_few, unmeasured, tested, _ = comparisons
    bounds = [margin * abs(figures[(*cell, r, metric)].mean) for cell, r, _ in tested]
    within = holm([d.p_below(bound) for (_, _, d), bound in zip(tested, bounds)])
    beyond = holm([d.p_above(bound) for (_, _, d), bound in zip(tested, bounds)])
    result["figure"] += (f"; with a {margin:.0%} margin: shown worse by more in {sum(beyond)}, shown within it in "
                         f"{sum(within)} of {len(tested)} comparisons")
    complete = bool(tested) and not too_few and not unmeasured
    result["verdict"] = FAILS if any(beyond) else HOLDS if complete and all(within) else OPEN
    return result


def threshold(figures: dict, who_list, metric: str, limit: float, above: bool, maps=None) -> dict:
    """Whether every cell of ``who_list`` has ``metric`` above (or at most) ``limit``: each testable
    cell tested one-sided each way (:func:`side_p_values`), Holm over the cells for each side."""
    compared = too_few = unmeasured = 0
    tested = []                        # ((m, n, who), p of the claimed side, p of the other side, Figure)
    for who in who_list:
        for m, n in _cells(figures, who, metric, maps):
            f = figures[(m, n, who, metric)]
            compared += 1
            if not f.testable:
                too_few += 1
                continue
            sides = side_p_values(f, metric, limit, above)
            if sides is None:
                unmeasured += 1
                continue
            tested.append(((m, n, who), *sides, f))
    if compared == 0:
        return {"verdict": OPEN, "figure": "not measured (no such cells in this comparison)", "cells": 0}
    held = holm([t[1] for t in tested])
    failed = holm([t[2] for t in tested])
    example = next((f"map {m} n={n}: {LABEL.get(who, who)} {f.text(2)}"
                    for ((m, n, who), _, _, f), bad in zip(tested, failed) if bad), None)
    figure = (f"{sum(held)} of {compared} cells significantly {'above' if above else 'at or below'} {limit:g}, "
              f"{sum(failed)} significantly not")
    figure += _untested_and_example(unmeasured, too_few, example)
    return {"verdict": FAILS if any(failed) else HOLDS if sum(held) == compared else OPEN, "figure": figure,
            "cells": compared}


def side_p_values(figure: Figure, metric: str, limit: float, above: bool) -> tuple[float, float] | None:
    """One-sided p-values of a cell against ``limit``: (that it is on the claimed side, that it is
    on the other), or None without per-episode values. A rate pools every seed's episodes and
    takes scipy's exact binomial test; a mean takes Student's t over the training seeds' means
    (a zoo column of several seeds) or over the episodes (a heuristic, one model)."""
    from scipy.stats import binomtest, ttest_1samp
    if figure.units is None:
        return None
    units = [np.asarray(u, dtype=np.float64) for u in figure.units]
    if metric in RATE_METRICS:
        values = np.concatenate(units)
        values = values[np.isfinite(values)]
        if len(values) == 0:
            return None
        k, n = int(values.sum()), len(values)
        less, greater = binomtest(k, n, limit, alternative="less").pvalue, binomtest(k, n, limit, alternative="greater").pvalue
    else:
        values = np.array([np.nanmean(u) for u in units if np.isfinite(u).any()]) if len(units) > 1 else units[0]
        values = values[np.isfinite(values)]
        if len(values) < 2:
            return None
        if np.ptp(values) == 0:
            less, greater = float(values[0] < limit), float(values[0] > limit)
            less, greater = 1.0 - less, 1.0 - greater       # a p of 0 on the side it lies on
        else:
            less = ttest_1samp(values, limit, alternative="less").pvalue
            greater = ttest_1samp(values, limit, alternative="greater").pvalue
    return (float(greater), float(less)) if above else (float(less), float(greater))


def both(*parts: dict) -> dict:
    """Two conditions of one claim: fails if either fails, holds if both hold."""
    verdicts = [p["verdict"] for p in parts]
    verdict = FAILS if FAILS in verdicts else HOLDS if all(v == HOLDS for v in verdicts) else OPEN
    return {"verdict": verdict, "figure": "; ".join(p["figure"] for p in parts),
            "cells": sum(p["cells"] for p in parts)}


def training_reward(curves: dict, fraction: float = 0.2) -> dict:
    """Whether RL-MSG's training reward is the highest, per map: each training seed's figure is
    the mean team reward of the last ``fraction`` of its training episodes, and a variant's is
    the mean over its seeds with Student's t over them (the training seed is the unit; fewer
    than 3 seeds: too few to test).

    Args:
        curves: {map: {variant: curve.csv path, or a list of them, one a training seed}}.
    """
    figures = {}
    for m, by_variant in curves.items():
        for variant, paths in by_variant.items():
            tails = []
            for path in ([paths] if isinstance(paths, (str, Path)) else paths):
                rewards = list(read_curve(path).get("reward", []))
                if rewards:
                    tail = rewards[-max(1, int(len(rewards) * fraction)):]
                    tails.append(sum(tail) / len(tail))
            if not tails:
                continue
            low, high = seed_interval(tails)
            figures[(m, 0, strategy_name(variant), "training_reward")] = Figure(
                sum(tails) / len(tails), low, high, testable=len(tails) >= MIN_SEEDS,
                units=tuple((t,) for t in tails))       # one value a seed: compared by Welch's t over seeds
    return lowest(figures, MSG, LEARNED, "training_reward", highest=True)


def fault_tolerance(result: dict | None) -> dict:
    """Whether the team keeps patrolling after its agents fail: from an ``evaluate --faults ...
    --json`` result, every vertex is still visited in each segment after a failure (the
    segment's MAX^h, averaged over episodes, stays below the segment's length)."""
    if not result:
        return {"verdict": OPEN, "figure": "not measured (give an 'evaluate --faults STEP:K --json' result)",
                "cells": 0}
    segments = result["summary"].get("segments") or []
    after = segments[1:]
    if not after:
        return {"verdict": OPEN, "figure": "the result has no fault (no segment after one)", "cells": 0}
    parts, ok = [], True
    for s in after:
        length = s["end"] - s["start"]
        value = s["max_idleness"]["mean"]
        if value is None or (isinstance(value, float) and math.isnan(value)):
            ok = False
            parts.append(f"steps {s['start']}-{s['end']}: no clean episode")
            continue
        ok &= value < length
        parts.append(f"steps {s['start']}-{s['end']}: MAX^h {value:.0f} (segment {length} steps)")
    figure = f"{result['strategy']} on {result['map']}, n={result['n_agents']}, faults {result.get('faults')}: " \
             + "; ".join(parts)
    return {"verdict": HOLDS if ok else FAILS, "figure": figure, "cells": len(after)}


def read_faults_result(path, argument: str = "--faults-result") -> dict:
    """An ``evaluate --faults STEP:K --json`` result, for the claim on failing agents.

    Raises:
        ValueError: one line naming ``argument`` and the file: missing, or not such a result.
    """
    import json
    path = Path(path)
    try:
        result = json.loads(path.read_text())
        result["summary"]
    except FileNotFoundError:
        raise ValueError(f"{argument} {path}: no such file") from None
    except (ValueError, KeyError, TypeError, UnicodeDecodeError):
        raise ValueError(f"{argument} {path}: not an 'evaluate --json' result") from None
    return result


def claims(figures: dict, curves: dict | None = None, faults_result: dict | None = None) -> list[dict]:
    """One row per claim of the paper: {"claim", "figure", "verdict"} (module docstring)."""
    maps = sorted({k[0] for k in figures})
    acd = [m for m in maps if m in ("A", "C", "D")]
    others = [s for s in PAPER_STRATEGIES if s != MSG]
    rows = [
        ("RL-MSG has the lowest MAX^h on every map", lowest(figures, MSG, others, "max_idleness")),
        ("RL-MSG's AVG^h is no worse than the others'", no_worse(figures, MSG, others, "avg_idleness")),
        ("RL-MSG has the fewest collisions on A, C and D, and the fewest of the learned variants on B",
         both(lowest(figures, MSG, others, "collisions", maps=acd),
              lowest(figures, MSG, LEARNED, "collisions", maps=["B"]))),
        ("CR collides most", lowest(figures, "CR", [s for s in PAPER_STRATEGIES if s != "CR"], "collisions",
                                    highest=True)),
        ("RL-MSG has the lowest battery failure rate of the learned variants, near zero (<= 0.05) on A, C, D",
         both(lowest(figures, MSG, LEARNED, "battery_failure_rate"),
              threshold(figures, [MSG], "battery_failure_rate", NEAR_ZERO, above=False, maps=acd))),
        ("All learned variants recharge above b_l (battery % at swap > 20)",
         threshold(figures, LEARNED, "swap_battery_pct", 20.0, above=True)),
        ("RL-INTENTION is no better than RL-NO-MSG at recharging and worse than RL-MSG at patrolling",
         both(_not_better(figures, INTENTION, NOMSG, "battery_failure_rate"),
              lowest(figures, MSG, [INTENTION], "avg_idleness"))),
        ("With one agent, RL-MSG has a lower MAX^h than RL-NO-MSG and RL-INTENTION",
         lowest(figures, MSG, [NOMSG, INTENTION], "max_idleness", sizes=[1])),
        ("RL-MSG's training reward is the highest",
         training_reward(curves) if curves else {"verdict": OPEN, "figure": "not measured (no training curves)",
                                                 "cells": 0}),
        ("The team keeps patrolling when agents fail", fault_tolerance(faults_result)),
    ]
    return [{"claim": claim, **result} for claim, result in rows]


def _not_better(figures: dict, who: str, than: str, metric: str) -> dict:
    """``who`` is not significantly lower than ``than`` in any testable cell (paired, Holm over the cells)."""
    compared = too_few = 0
    tested = []
    for m, n in _cells(figures, who, metric):
        rival = figures.get((m, n, than, metric))
        if rival is None or math.isnan(rival.mean):
            continue
        compared += 1
        mine = figures[(m, n, who, metric)]
        if not (mine.testable and rival.testable):
            too_few += 1
        elif (d := difference(mine, rival)) is not None:
            tested.append(d)
    if compared == 0:
        return {"verdict": OPEN, "figure": "not measured (no such cells in this comparison)", "cells": 0}
    better = sum(sig and d.mean < 0 for d, sig in zip(tested, holm([d.p for d in tested])))
    figure = (f"{LABEL[who]} significantly lower than {LABEL[than]} in {better} of {compared} cells"
              + _untested_and_example(compared - too_few - len(tested), too_few, None))
    verdict = FAILS if better else HOLDS if len(tested) == compared else OPEN
    return {"verdict": verdict, "cells": compared, "figure": figure}


def claims_table(rows: list[dict]) -> str:
    """The claims as a markdown table."""
    lines = ["| the paper's claim | our figure (paired differences on the same episodes, 95 % intervals over training seeds where a zoo column pools several, Holm over each claim's comparisons) | verdict |", "|---|---|---|"]
    lines += [f"| {r['claim']} | {r['figure']} | **{r['verdict']}** |" for r in rows]
    return "\n".join(lines)


def recipes_note(trained: dict) -> str:
    """The lines under the claims table that say how each zoo column was trained.

    Args:
        trained: {(MAP, strategy label): phrase of :func:`patrolsb3.zoo.trained_with`}.
    """
    if not trained:
        return ""
    lines = ["Trained with (the recipe of each zoo column's seeds; docs/training.md compares the recipes):"]
    lines += [f"- map {m}, {label}: {phrase}" for (m, label), phrase in sorted(trained.items())]
    return "\n".join(lines)
