"""What the budget buys: issue 43's E2 (the paper's recipe) evaluated at several training budgets,
one markdown table, from the 24-h evaluations (eval.json, seed 0) of its three seeds at each.

    python docs/experiments/2026-12-08-scripts/budget_table.py \
        16000000=DIR 32000000=DIR 75000000=zoo/paper-recipe/A/rl-msg [--out FILE]

Each DIR holds ``seed<k>/eval.json`` (``zoo/recipe_trial.sh budget`` keeps those of 16 M and 32 M
agent-steps in ``zoo/comparison-recipes/budget/<steps>/``; the full budget is the shelf's entries).
A row per budget and team size: the mean over seeds of AVG^h, MAX^h, collisions a day and the
battery failure rate, with each seed's figure in brackets. 10 agent-steps are one episode step
for rl-msg (5 slots x 2 phases), so 16 M agent-steps are 1.6 M episode steps.
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

FIGURES = (("avg_idleness", "AVG^h", "{:.1f}"), ("max_idleness", "MAX^h", "{:.1f}"),
           ("collisions", "collisions / day", "{:.1f}"), ("battery_failure_rate", "BF rate", "{:.2f}"))
AGENT_STEPS_PER_EPISODE_STEP = 10


def seed_figures(folder: Path) -> dict[str, dict[int, dict[str, float]]]:
    """{seed folder name: {team size: {figure: mean}}} from each ``seed<k>/eval.json`` of ``folder``."""
    found = {}
    for path in sorted(folder.glob("seed*/eval.json")):
        results = json.loads(path.read_text())["results"]
        found[path.parent.name] = {r["n_agents"]: {key: r["summary"][key]["mean"] if isinstance(r["summary"][key], dict)
                                                   else r["summary"][key] for key, _, _ in FIGURES}
                                   for r in results}
    if not found:
        raise SystemExit(f"budget_table.py: {folder}: no seed<k>/eval.json")
    return found


def table(budgets: list[tuple[int, Path]]) -> str:
    """The markdown table: a row per budget and team size."""
    lines = ["| agent-steps (episode steps) | seeds | agents | " + " | ".join(name for _, name, _ in FIGURES) + " |",
             "|---|---|---|" + "---|" * len(FIGURES)]
    for steps, folder in budgets:
        seeds = seed_figures(folder)
        sizes = sorted(set.intersection(*(set(per_size) for per_size in seeds.values())))
        for n in sizes:
            cells = []
            for key, _, fmt in FIGURES:
                values = [seeds[s][n][key] for s in seeds]
                cells.append(fmt.format(np.mean(values)) + " (" + ", ".join(fmt.format(v) for v in values) + ")")
            lines.append(f"| {steps:,} ({steps // AGENT_STEPS_PER_EPISODE_STEP:,}) | {','.join(s[4:] for s in seeds)} "
                         f"| {n} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("budgets", nargs="+", metavar="STEPS=DIR")
    parser.add_argument("--out", default=None, help="write the table here too")
    args = parser.parse_args()
    budgets = []
    for item in args.budgets:
        steps, sep, folder = item.partition("=")
        if not sep or not steps.isdigit():
            raise SystemExit(f"budget_table.py: {item!r}: give STEPS=DIR, e.g. 16000000=zoo/comparison-recipes/budget/16000000")
        if not Path(folder).is_dir():
            raise SystemExit(f"budget_table.py: {folder}: no such folder")
        budgets.append((int(steps), Path(folder)))
    text = table(budgets)
    print(text, end="")
    if args.out:
        Path(args.out).write_text(text)


if __name__ == "__main__":
    main()
