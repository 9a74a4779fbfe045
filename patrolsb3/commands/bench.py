"""``patrolsb3 bench env|evaluate|train``: print one JSON object of speed figures (medians)."""
import importlib
import json

TARGETS = {"env": "patrolsb3.bench.env", "evaluate": "patrolsb3.bench.evaluate",
           "train": "patrolsb3.bench.train"}


def add_arguments(parser):
    parser.add_argument("target", choices=sorted(TARGETS), help="what to measure")
    parser.add_argument("--repeats", type=int, default=5, help="repeats; the median is printed")
    parser.add_argument("--quick", action="store_true", help="smaller sizes (smoke test)")


def run(args):
    module = importlib.import_module(TARGETS[args.target])
    print(json.dumps(module.run(repeats=args.repeats, quick=args.quick)))
    return 0
