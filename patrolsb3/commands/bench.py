"""``patrolsb3 bench env|evaluate|train``: print one JSON object of speed figures (medians)."""
import json

from ..bench import env, evaluate, train

TARGETS = {"env": env, "evaluate": evaluate, "train": train}
"""What ``bench`` measures: a module with ``run(repeats, quick, ...) -> dict`` each."""


def add_arguments(parser):
    parser.add_argument("target", choices=sorted(TARGETS), help="what to measure")
    parser.add_argument("--repeats", type=int, default=5, help="repeats; the median is printed")
    parser.add_argument("--quick", action="store_true", help="smaller sizes (smoke test)")
    parser.add_argument("--device", default="cpu", choices=["auto", "cpu", "cuda"],
                        help="torch device of 'bench train' (default cpu; auto = cuda when torch sees one)")
    parser.add_argument("--precision", default=None, choices=["auto", "fp32", "bf16"],
                        help="'bench train': training precision (default: the hyperparameters')")
    parser.add_argument("--set", nargs="+", action="extend", default=[], metavar="KEY=VALUE",
                        help="'bench train': hyperparameter overrides, e.g. batch_size=512")


def run(args):
    module = TARGETS[args.target]
    if args.target == "train":
        from ..sb3.algorithms import torch_device
        from ..sb3.hyperparams import parse_set
        torch_device(args.device)   # a device torch cannot use: one line, before any work
        overrides = parse_set(args.set)
        if args.precision is not None:
            overrides["precision"] = args.precision
        result = module.run(repeats=args.repeats, quick=args.quick, device=args.device, overrides=overrides)
    elif args.set or args.device != "cpu" or args.precision is not None:
        raise ValueError(f"--set, --device and --precision are options of 'bench train', not 'bench {args.target}'")
    else:
        result = module.run(repeats=args.repeats, quick=args.quick)
    print(json.dumps(result))
    return 0
