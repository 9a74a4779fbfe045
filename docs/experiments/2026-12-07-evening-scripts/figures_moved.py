"""How a map's zoo figures moved when they were evaluated again under paired draws: each entry's
eval.json now against the one at commit 1dab448 (the old draws), per metric and team size.

    python docs/experiments/2026-12-07-evening-scripts/figures_moved.py A
"""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

OLD = "1dab448"
METRICS = (("avg_idleness", "AVG^h"), ("max_idleness", "MAX^h"), ("collisions", "collisions"),
           ("battery_failure_rate", "BF rate"))


def means(data: dict, metric: str) -> list[float]:
    return [r["summary"][metric]["mean"] for r in sorted(data["results"], key=lambda r: r["n_agents"])]


def main(map_name: str) -> None:
    print("| entry | metric | n = 1..5 before | n = 1..5 now |\n|---|---|---|---|")
    for path in sorted(Path("zoo", map_name.upper()).glob("*/seed*/eval.json")):
        now = json.loads(path.read_text())
        if now.get("draws") is None:
            continue                        # not evaluated again yet
        old = json.loads(subprocess.run(["git", "show", f"{OLD}:{path}"], capture_output=True, text=True,
                                        check=True).stdout)
        for metric, label in METRICS:
            before = ", ".join(f"{v:.1f}" if v is not None else "-" for v in means(old, metric))
            after = ", ".join(f"{v:.1f}" if v is not None else "-" for v in means(now, metric))
            print(f"| {path.parent.parent.name}/{path.parent.name} | {label} | {before} | {after} |")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "A")
