"""The ``patrolsb3`` command line: ``patrolsb3 maps | render | evaluate | compare | train |
bench | zoo | sweep | claims``.

Each sub-command lives in its own module ``patrolsb3.commands.<name>`` with two functions,
``add_arguments(parser)`` and ``run(args) -> int``; modules import their heavy dependencies
(torch, SB3, Ray, pillow) inside ``run`` so that ``patrolsb3 maps`` starts fast.
"""
from __future__ import annotations

import argparse
import sys

from . import __version__
from .commands import bench, claims, compare, evaluate, maps, render, sweep, train, zoo
from .core.maps import MapError

COMMANDS = {
    "maps": (maps, "list the shipped maps, draw them in the terminal or as PNG"),
    "render": (render, "animate a run (random or heuristic) as a GIF"),
    "evaluate": (evaluate, "evaluate one strategy on one map with the paper's metrics"),
    "compare": (compare, "run every strategy and write the paper's tables and plots"),
    "train": (train, "train a parameter-shared policy with SB3"),
    "bench": (bench, "measure speed: env | evaluate | train"),
    "zoo": (zoo, "list or inspect the trained checkpoints in zoo/"),
    "sweep": (sweep, "a grid of training runs as Ray Tune trials (the ray extra), resumable"),
    "claims": (claims, "the paper's claims, one row each, tested on a comparison's figures"),
}
"""name -> (its module in :mod:`patrolsb3.commands`, its one-line help)."""


def build_parser() -> argparse.ArgumentParser:
    """The argument parser with every sub-command registered."""
    parser = argparse.ArgumentParser(
        prog="patrolsb3", description="Multi-agent drone patrolling (the paper's model, heuristics, "
                                      "SB3 training and a model zoo). One sub-command per job; "
                                      "'patrolsb3 COMMAND --help' for its options.")
    parser.add_argument("--version", action="version", version=f"patrolsb3 {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name, (module, help_text) in COMMANDS.items():
        p = sub.add_parser(name, help=help_text, description=help_text)
        module.add_arguments(p)
        p.set_defaults(_module=module)
    return parser


MINIMUMS = {"agents": 1, "episodes": 1, "tests": 1, "steps": 1, "repeats": 1, "last": 1, "timesteps": 1, "seed": 0,
            "entry_seed": 0, "checkpoint_freq": 1, "eval_freq": 0, "cpus": 1, "cpus_per_trial": 1}
"""The least value of every whole-number option of any command (by its argparse name): checked
once here, for every command, before any work."""


def check_minimums(args) -> None:
    """Refuse a whole-number option below its minimum (:data:`MINIMUMS`) in one line naming it.

    Raises:
        ValueError: e.g. "--episodes must be a whole number >= 1, got 0".
    """
    for name, low in MINIMUMS.items():
        value = getattr(args, name, None)
        if isinstance(value, int) and not isinstance(value, bool) and value < low:
            option = "--seed-of-entry" if name == "entry_seed" else "--" + name.replace("_", "-")
            raise ValueError(f"{option} must be a whole number >= {low}, got {value}")


def main(argv=None) -> int:
    """Entry point of the ``patrolsb3`` console script."""
    args = build_parser().parse_args(argv)
    try:
        check_minimums(args)
        return int(args._module.run(args) or 0)
    except (MapError, ValueError, TypeError, FileNotFoundError) as exc:
        print(f"patrolsb3 {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:   # Ctrl-C / SIGINT: train has saved a checkpoint on the way out
        hint = " (a checkpoint was saved; continue with --resume)" if args.command == "train" else ""
        print(f"patrolsb3 {args.command}: interrupted{hint}", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
