"""``patrolsb3 evaluate``: one strategy on one map with the paper's metrics (mean +- std over tests)."""

from ..evaluate import evaluate
from ..outputs import check_output_file, write_json
from ..report import evaluation_text
from ..zoo import use_zoo_dir


def parse_faults(texts) -> tuple:
    """Parse ``STEP:K`` strings into ((step, k), ...).

    Raises:
        ValueError: a string not of the form STEP:K with integers STEP >= 0 and K >= 1.
    """
    faults = []
    for text in texts or ():
        parts = str(text).split(":")
        try:
            if len(parts) != 2:
                raise ValueError
            fault_step, k = int(parts[0]), int(parts[1])
        except ValueError:
            raise ValueError(f"bad --faults {text!r}: expected STEP:K with integers, e.g. 7200:1 "
                             f"(K agents fail for good at step STEP)") from None
        if fault_step < 0 or k < 1:
            raise ValueError(f"bad --faults {text!r}: STEP must be >= 0 and K >= 1")
        faults.append((fault_step, k))
    return tuple(sorted(faults))


def add_arguments(parser):
    parser.add_argument("--strategy", required=True,
                        help="RANDOM, CR, PART, SEBS, CYCLIC (case-insensitive), zoo:<variant> (the paper's setting) "
                             "or zoo:<variant>:<shelf> (an entry on a shelf of the zoo: guarded, paper-recipe, cd10)")
    parser.add_argument("--map", default="A", help="map name A-D or a map file (default A)")
    parser.add_argument("--agents", type=int, default=3, help="team size (default 3)")
    parser.add_argument("--episodes", type=int, default=100, help="episodes per test (default 100)")
    parser.add_argument("--steps", type=int, default=14400, help="steps per episode (default 14400 = 24 h)")
    parser.add_argument("--tests", type=int, default=1, help="tests; mean +- std over them (default 1)")
    parser.add_argument("--seed", type=int, default=0, help="simulator seed of the episodes (default 0)")
    parser.add_argument("--zoo-dir", default=None,
                        help="the zoo of a zoo: strategy (default: $PATROLSB3_ZOO, else the checkout's zoo/)")
    parser.add_argument("--faults", action="append", default=[], metavar="STEP:K",
                        help="K agents fail for good at STEP (repeatable); AVG/MAX are split at each")
    parser.add_argument("--stochastic", action="store_true",
                        help="a zoo model samples its actions instead of taking the most likely one")
    parser.add_argument("--device", default="cpu", choices=["auto", "cpu", "cuda"],
                        help="where a zoo model's network runs (default cpu; auto = cuda when torch sees one)")
    parser.add_argument("--json", default=None, metavar="FILE", help="also write the result as JSON")
    parser.add_argument("--no-progress", action="store_true", help="hide the progress bar")


def run(args):
    from pathlib import Path

    from ..sb3.algorithms import torch_device
    torch_device(args.device)   # a device torch cannot use: one line, before any work
    if args.zoo_dir:
        use_zoo_dir(args.zoo_dir)
    if args.json:
        check_output_file(args.json, "--json", inputs=[args.map] if Path(args.map).is_file() else [])
    faults = parse_faults(args.faults)
    if sum(k for _, k in faults) > args.agents:
        raise ValueError(f"--faults {' '.join(args.faults)}: {sum(k for _, k in faults)} agents fail in a team of "
                         f"{args.agents} (--agents)")
    result = evaluate(args.strategy, args.map, args.agents, episodes=args.episodes, tests=args.tests,
                      steps=args.steps, seed=args.seed, faults=faults,
                      progress=not args.no_progress, deterministic=not args.stochastic, device=args.device)
    print(evaluation_text(result))
    if args.json:
        write_json(args.json, result, indent=2)    # strict JSON: NaN (no swap) -> null
    return 0
