"""How far the stored figures moved when evaluated again under paired draws: for every result
that exists under both draws (old: no "draws" field; new: "per-episode-1"), the relative change
of each figure's mean, summarised as median (max) over team sizes and results.

    python docs/experiments/2026-12-07-night-scripts/moved_summary.py heuristics MAPS
    python docs/experiments/2026-12-07-night-scripts/moved_summary.py zoo PATTERN [OLD_COMMIT]

``heuristics``: zoo/comparison/results.json holds both draws of each heuristic cell.
``zoo``: each entry eval.json matching PATTERN (e.g. 'zoo/C/rl-*/seed*') now against the same file
at OLD_COMMIT (default 72b2d22, before this session's re-evaluation).
"""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np

METRICS = (("avg_idleness", "AVG^h"), ("max_idleness", "MAX^h"), ("collisions", "collisions"))


def change(old: dict, new: dict, metric: str) -> float | None:
    a, b = old["summary"][metric]["mean"], new["summary"][metric]["mean"]
    if a is None or b is None or not np.isfinite(a) or not np.isfinite(b) or abs(a) < 1e-9:
        return None
    return abs(b - a) / abs(a) * 100


def summarise(pairs: list[tuple[dict, dict]], label: str) -> None:
    parts = []
    for metric, name in METRICS:
        moved = [c for old, new in pairs if (c := change(old, new, metric)) is not None]
        if moved:
            parts.append(f"{name} {np.median(moved):.1f} % ({max(moved):.1f} %)")
    bf = [(old["summary"]["battery_failure_rate"]["mean"], new["summary"]["battery_failure_rate"]["mean"])
          for old, new in pairs]
    parts.append(f"battery failure rate: {sum(a > 0 for a, _ in bf)} cells above 0 before, {sum(b > 0 for _, b in bf)} now")
    print(f"| {label} | {len(pairs)} | " + " | ".join(parts) + " |")


def heuristics(maps: str) -> None:
    stored = json.loads(Path("zoo/comparison/results.json").read_text())
    for m in maps.upper().split(","):
        for strategy in ("CR", "PART", "SEBS", "RANDOM", "CYCLIC"):
            cells = [r for r in stored if r["map"] == m and r["strategy"] == strategy]
            old = {r["n_agents"]: r for r in cells if r.get("draws") is None}
            new = {r["n_agents"]: r for r in cells if r.get("draws") == "per-episode-1"}
            pairs = [(old[n], new[n]) for n in sorted(old) if n in new]
            if pairs:
                summarise(pairs, f"{m} {strategy}")


def zoo_entries(pattern: str, commit: str) -> None:
    for path in sorted(Path().glob(pattern + "/eval.json")):
        now = json.loads(path.read_text())
        if now.get("draws") is None:
            continue
        shown = subprocess.run(["git", "show", f"{commit}:{path}"], capture_output=True, text=True)
        if shown.returncode:
            continue
        old = json.loads(shown.stdout)
        if old.get("draws") is not None:
            continue                                        # already of the new draws at that commit
        by_n = {r["n_agents"]: r for r in old["results"]}
        summarise([(by_n[r["n_agents"]], r) for r in now["results"] if r["n_agents"] in by_n], str(path.parent))


if __name__ == "__main__":
    print("| results | cells | median (max) relative change of the mean |\n|---|---|---|")
    if sys.argv[1] == "heuristics":
        heuristics(sys.argv[2] if len(sys.argv) > 2 else "A,B,C,D")
    else:
        zoo_entries(sys.argv[2], sys.argv[3] if len(sys.argv) > 3 else "72b2d22")
