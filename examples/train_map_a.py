"""Train a learned variant on map A with the zoo's recipe: ``python examples/train_map_a.py``.

Stage 1 (the patrol, full batteries) then stage 2 (the recharge, unshielded), as the
paper-setting zoo is trained (:func:`patrolsb3.sb3.recipes.train_in_stages`). A run shorter than
an episode still writes curve.csv (its header) and says so.
"""
import argparse
import sys

from patrolsb3.core.maps import MapError
from patrolsb3.sb3.hyperparams import parse_set
from patrolsb3.sb3.recipes import train_in_stages

if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--timesteps", type=int, default=10_000_000,
                        help="agent-steps of both stages (default 10 M, a fifth in stage 1): about 1.7 CPU "
                             "hours in fp32, 1.1 with bf16 on a CPU that has it (the zoo's entries: 18 M "
                             "agent-steps in about 3 fp32 CPU hours)")
    parser.add_argument("--variant", default="rl-msg", help="rl-msg | rl-no-msg | rl-intention")
    parser.add_argument("--out", default="runs/", help="root of the run folders (default runs/)")
    parser.add_argument("--run-id", default=None, help="run folder name (default seed<seed>)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--resume", action="store_true", help="continue the unfinished stage")
    parser.add_argument("--set", nargs="+", action="extend", default=[], metavar="KEY=VALUE",
                        help="hyperparameter overrides on top of the recipe, e.g. n_steps=128")
    args = parser.parse_args()
    try:
        run = train_in_stages("A", variant=args.variant, timesteps=args.timesteps, seed=args.seed, out=args.out,
                              run_id=args.run_id, resume=args.resume, overrides=parse_set(args.set),
                              command="python " + " ".join(sys.argv))
    except (MapError, ValueError, TypeError, FileNotFoundError) as exc:
        print(f"train_map_a.py: error: {exc}", file=sys.stderr)
        raise SystemExit(2)
    print(f"run folder: {run}")
