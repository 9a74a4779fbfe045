"""A training run's curve.csv summarised per bin of agent-steps (training episodes, not an evaluation):
the mean team size, episode length, episode return, mean idleness, collisions and battery failures
of the training episodes that finished in each bin.

    python docs/experiments/2026-12-07-late-scripts/curve_bins.py runs/e2/A/rl-msg/seed0 [--bin 1000000]
"""
from __future__ import annotations

import argparse

import numpy as np

from patrolsb3.runs import read_curve


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("runs", nargs="+")
    parser.add_argument("--bin", type=int, default=1_000_000, help="agent-steps per bin")
    args = parser.parse_args()
    columns = ("n_agents", "sim_steps", "reward", "mean_idleness", "collisions", "battery_failures")
    for run in args.runs:
        curve = read_curve(f"{run}/curve.csv")                                # {column: (N,) array}
        bins = (curve["timesteps"] // args.bin).astype(int)      # (N,)
        print(f"{run}: training episodes per {args.bin:,} agent-steps")
        print("bin(M)  episodes  " + "  ".join(f"{c:>16}" for c in columns))
        for b in np.unique(bins):
            rows = bins == b
            print(f"{b * args.bin / 1e6:6.1f}  {rows.sum():8d}  "
                  + "  ".join(f"{curve[c][rows].mean():16.2f}" for c in columns))


if __name__ == "__main__":
    main()
