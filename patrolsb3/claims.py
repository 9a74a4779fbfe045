"""The paper's claims, one row each, tested on a comparison's figures (``patrolsb3 claims``).

Read from a comparison folder's ``results.csv`` (``patrolsb3 compare``): every (map, team
size, strategy, metric) with its mean and 95 % interval. A heuristic's interval is over its
episodes (scipy's bootstrap of the mean); a zoo column's is over its training seeds, each seed's
mean one draw (Student's t: the training seed is the unit); a battery failure rate's is exact
(Clopper-Pearson) over the episodes (:mod:`patrolsb3.stats`). Idleness and collisions follow
the paper's convention (episodes without a battery failure).

How a verdict is reached, per (map, team size) cell: one strategy is *significantly* lower
than another when its whole interval lies below the other's and both cells are testable: at
least 10 episodes, and for a zoo column at least 3 training seeds (fewer: "too few to test",
counted in the figure; one seed gives a figure, not a verdict). A claim that X is lowest
**holds** when X is significantly lowest in every cell it covers, **does not hold** when
another strategy is significantly lower than X in some cell, and is **inconclusive** otherwise.
A claim that X is *no worse* holds when no other strategy is significantly better in any cell.
Thresholds (near-zero failures: a rate of 0.05 at most; recharge above b_l) hold when the
whole interval is on the claimed side and fail when it is all on the other. A cell without an
interval (a result stored before intervals existed) cannot be significant either way. The
comparisons are not yet paired nor adjusted for their number (issue 44).
"""
from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path

from .names import display_name
from .runs import ComparisonFolder, read_curve
from .stats import MIN_SEEDS, seed_interval, testable

MSG, NOMSG, INTENTION = "zoo:rl-msg", "zoo:rl-no-msg", "zoo:rl-intention"
LEARNED = (MSG, NOMSG, INTENTION)
HEURISTICS = ("CR", "PART", "SEBS")
PAPER_STRATEGIES = HEURISTICS + LEARNED
LABEL = {name: display_name(name) for name in PAPER_STRATEGIES}
"""How each strategy is named in a claim (:func:`patrolsb3.names.display_name`)."""
NEAR_ZERO = 0.05
"""A battery failure rate 'near zero' (the paper's word) is at most this."""
HOLDS, FAILS, OPEN = "holds", "does not hold", "inconclusive"


@dataclass(frozen=True)
class Figure:
    """A mean with its 95 % interval (nan when unknown), and whether its cell has enough
    episodes and training seeds to decide a comparison (:func:`patrolsb3.stats.testable`)."""
    mean: float
    low: float
    high: float
    testable: bool = True

    def text(self, digits: int = 1) -> str:
        if math.isnan(self.mean):
            return "-"
        if math.isnan(self.low):
            return f"{self.mean:.{digits}f}"
        return f"{self.mean:.{digits}f} [{self.low:.{digits}f}, {self.high:.{digits}f}]"


def below(a: Figure, b: Figure) -> bool:
    """a is significantly lower than b (a's interval wholly below b's, both cells testable)."""
    return a.testable and b.testable and not (math.isnan(a.high) or math.isnan(b.low)) and a.high < b.low


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
    return figures


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


def lowest(figures: dict, who: str, rivals, metric: str, maps=None, sizes=None, highest: bool = False) -> dict:
    """Whether ``who`` has the lowest (or ``highest``) ``metric`` against ``rivals`` in every
    cell: {"verdict", "figure", "cells"} (module docstring). The figure says who wins where: the
    cells where ``who`` is best, each rival that beats it and in which cells, the level cells,
    and one example with both intervals."""
    wins = losses = compared = unmeasured = too_few = level = 0
    worst, beaten_by = None, {}                 # beaten_by: rival -> cells where it beats ``who``
    for m, n in _cells(figures, who, metric, maps, sizes):
        mine = figures[(m, n, who, metric)]
        others = {r: figures[(m, n, r, metric)] for r in rivals if (m, n, r, metric) in figures
                  and r != who and not math.isnan(figures[(m, n, r, metric)].mean)}
        if not others:
            continue
        compared += 1
        cell_testable = all(f.testable for f in (mine, *others.values()))
        too_few += not cell_testable
        unmeasured += cell_testable and any(math.isnan(f.low) for f in (mine, *others.values()))
        better = (lambda a, b: below(b, a)) if highest else below       # a beats b
        if all(better(mine, o) for o in others.values()):
            wins += 1
        beaten = {r: o for r, o in others.items() if better(o, mine)}
        where = f"{m}" + (f" n={n}" if n else "")
        for r in beaten:
            beaten_by.setdefault(r, []).append(where)
        if beaten:
            losses += 1
            if worst is None:
                r, o = next(iter(beaten.items()))
                worst = f"map {where}: {LABEL.get(who, who)} {mine.text()} vs {LABEL.get(r, r)} {o.text()}"
        elif cell_testable and not all(better(mine, o) for o in others.values()):
            level += 1
    if compared == 0:
        return {"verdict": OPEN, "figure": "not measured (no such cells in this comparison)", "cells": 0}
    word = "highest" if highest else "lowest"
    figure = f"significantly {word} in {wins} of {compared} cells; significantly beaten in {losses}"
    if beaten_by:            # who wins where
        figure += " (" + "; ".join(f"by {LABEL.get(r, r)} in {len(c)}: {', '.join(c)}" for r, c in beaten_by.items()) + ")"
    figure += f"; level in {level}"
    figure += _untested_and_example(unmeasured, too_few, worst)
    verdict = FAILS if losses else HOLDS if wins == compared else OPEN
    return {"verdict": verdict, "figure": figure, "cells": compared, "unmeasured": unmeasured}


def _untested_and_example(unmeasured: int, too_few: int, example: str | None) -> str:
    """The tail of a claim's figure: the cells without an interval, those below the floor, an example."""
    tail = f"; {unmeasured} cells without an interval" if unmeasured else ""
    if too_few:
        tail += f"; {too_few} cells too few to test (fewer than 3 training seeds or 10 episodes)"
    return tail + (f" (e.g. {example})" if example else "")


def no_worse(figures: dict, who: str, rivals, metric: str, maps=None) -> dict:
    """Whether no rival is significantly lower than ``who`` in any cell."""
    result = lowest(figures, who, rivals, metric, maps)
    if result["cells"] and result["verdict"] == OPEN and not result["unmeasured"]:
        result["verdict"] = HOLDS                     # no rival significantly better anywhere
    return result


def threshold(figures: dict, who_list, metric: str, limit: float, above: bool, maps=None) -> dict:
    """Whether every cell of ``who_list`` has ``metric`` above (or at most) ``limit``."""
    held = failed = compared = unmeasured = too_few = 0
    example = None
    for who in who_list:
        for m, n in _cells(figures, who, metric, maps):
            f = figures[(m, n, who, metric)]
            compared += 1
            unmeasured += f.testable and math.isnan(f.low)
            too_few += not f.testable
            if above:
                ok, bad = f.low > limit, f.high < limit
            else:
                ok, bad = f.high <= limit, f.low > limit
            ok, bad = ok and f.testable, bad and f.testable
            held += ok
            failed += bad
            if bad and example is None:
                example = f"map {m} n={n}: {LABEL.get(who, who)} {f.text(2)}"
    if compared == 0:
        return {"verdict": OPEN, "figure": "not measured (no such cells in this comparison)", "cells": 0}
    figure = f"{held} of {compared} cells clearly {'above' if above else 'at or below'} {limit:g}, {failed} clearly not"
    figure += _untested_and_example(unmeasured, too_few, example)
    return {"verdict": FAILS if failed else HOLDS if held == compared else OPEN, "figure": figure,
            "cells": compared}


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
            figures[(m, 0, f"zoo:{variant}", "training_reward")] = Figure(
                sum(tails) / len(tails), low, high, testable=len(tails) >= MIN_SEEDS)
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
    """``who`` is not significantly lower than ``than`` in any cell."""
    compared = better = 0
    for m, n in _cells(figures, who, metric):
        rival = figures.get((m, n, than, metric))
        if rival is not None and not math.isnan(rival.mean):
            compared += 1
            better += below(figures[(m, n, who, metric)], rival)
    if compared == 0:
        return {"verdict": OPEN, "figure": "not measured (no such cells in this comparison)", "cells": 0}
    return {"verdict": FAILS if better else HOLDS, "cells": compared,
            "figure": f"{LABEL[who]} significantly lower than {LABEL[than]} in {better} of {compared} cells"}


def claims_table(rows: list[dict]) -> str:
    """The claims as a markdown table."""
    lines = ["| the paper's claim | our figure (95 % intervals over episodes, and over training seeds where a zoo column pools several) | verdict |", "|---|---|---|"]
    lines += [f"| {r['claim']} | {r['figure']} | **{r['verdict']}** |" for r in rows]
    return "\n".join(lines)
