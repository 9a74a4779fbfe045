"""Compare the zoo models with the heuristics on map A: ``python examples/compare_map_a.py``.

Thin wrapper of ``patrolsb3 compare --maps A`` (tables, plots and report.md in --out).
"""
import argparse

from patrolsb3.cli import main

if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--agents", default="1-5", help="team sizes (default 1-5)")
    parser.add_argument("--episodes", type=int, default=10, help="episodes per team size (default 10)")
    parser.add_argument("--steps", type=int, default=14400, help="steps per episode (default 14400 = 24 h)")
    parser.add_argument("--out", default="out/compare_a", help="output folder (default out/compare_a)")
    args = parser.parse_args()
    raise SystemExit(main(["compare", "--maps", "A", "--agents", args.agents, "--episodes", str(args.episodes),
                           "--steps", str(args.steps), "--out", args.out, "--no-progress"]))
