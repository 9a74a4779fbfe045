"""Train the paper's RL-MSG policy on map A: ``python examples/train_map_a.py [--timesteps N]``.

Thin wrapper of :func:`patrolsb3.sb3.train.train` (the same as ``patrolsb3 train --map A``).
"""
import argparse

from patrolsb3.sb3.train import train

if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--timesteps", type=int, default=None, help="total agent-steps (default: hyperparameters)")
    parser.add_argument("--variant", default="rl-msg")
    parser.add_argument("--out", default="runs/")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--resume", action="store_true")
    args = parser.parse_args()
    print(train(map="A", variant=args.variant, timesteps=args.timesteps, out=args.out, seed=args.seed,
                resume=args.resume))
