"""``patrolsb3 compare``: every strategy x maps x team sizes -> the paper's tables, a markdown
report and plots. The planning, the stored figures and the evaluation are
:mod:`patrolsb3.comparison`'s; this module parses the arguments and prints."""
from ..claims import read_faults_result
from ..comparison import Protocol, StoredResults, evaluate_cells, learning_curves, plan_cells
from ..distributed import require_ray
from ..outputs import check_output_dir
from ..report import clean_figures, write_compare
from ..zoo import use_zoo_dir


def parse_agents(text: str) -> list[int]:
    """'1-5' or '1,3,5' (or a mix) -> sorted team sizes."""
    sizes = set()
    try:
        for part in str(text).split(","):
            if "-" in part:
                low, high = (int(v) for v in part.split("-"))
                if low > high:
                    raise ValueError(f"bad --agents {text!r}: the range {part} is reversed (write {high}-{low})")
                sizes.update(range(low, high + 1))
            elif part.strip():
                sizes.add(int(part))
    except ValueError as exc:
        if "reversed" in str(exc):
            raise
        raise ValueError(f"bad --agents {text!r}: expected sizes like 1-5 or 1,3,5") from None
    if not sizes or min(sizes) < 1:
        raise ValueError(f"bad --agents {text!r}: team sizes must be >= 1")
    return sorted(sizes)


def say(line: str) -> None:
    """Print a progress line at once."""
    print(line, flush=True)


def report_cell(r: dict, cell, source: str) -> None:
    """The progress line of one cell: its figures and where they came from (or its time)."""
    _, name, n = cell
    s = r["summary"]
    print(f"map {r['map']} {name:>16} n={n}: {clean_figures(s)} "
          f"BF {s['battery_failure_rate']['mean']:.3f} BLv {s['swap_battery_pct']['mean']:.1f}{source}", flush=True)


def add_arguments(parser):
    parser.add_argument("--maps", default="A,B,C,D", help="comma-separated maps (default A,B,C,D)")
    parser.add_argument("--agents", default="1-5", help="team sizes, e.g. 1-5 or 1,3,5 (default 1-5)")
    parser.add_argument("--episodes", type=int, default=20, help="episodes per test (default 20)")
    parser.add_argument("--steps", type=int, default=14400, help="steps per episode (default 14400)")
    parser.add_argument("--tests", type=int, default=1, help="tests (default 1)")
    parser.add_argument("--strategies", default=None,
                        help="comma-separated strategies (default: CR,PART,SEBS,RANDOM,CYCLIC and the "
                             "zoo models available for each map)")
    parser.add_argument("--protocol", choices=["paper"], default=None,
                        help="'paper': 10 tests x 100 episodes x 14,400 steps")
    parser.add_argument("--seed", type=int, default=0,
                        help="simulator seed of the episodes (default 0, the seed of the zoo's eval.json)")
    parser.add_argument("--out", required=True, help="output folder")
    parser.add_argument("--zoo-dir", default=None,
                        help="the zoo to read (default: $PATROLSB3_ZOO, else the checkout's zoo/)")
    parser.add_argument("--no-progress", action="store_true", help="no progress bars, one line per cell")
    parser.add_argument("--stochastic", action="store_true",
                        help="zoo models sample their actions (default: the most likely legal action)")
    parser.add_argument("--rerun-heuristics", "--rerun", dest="rerun", action="store_true",
                        help="evaluate the heuristics again (only them; see --rerun-zoo) even when "
                             "OUT/results.json already holds a result of this exact protocol (a rerun or an "
                             "interrupted run reuses them); --rerun is its older name")
    parser.add_argument("--device", default="cpu", choices=["auto", "cpu", "cuda"],
                        help="where zoo models' networks run (default cpu; auto = cuda when torch sees one)")
    parser.add_argument("--ray", action="store_true",
                        help="evaluate the cells (map, strategy, team size) as Ray tasks, one CPU each "
                             "(needs the ray extra: pip install -e \".[ray]\"); same results.json, same figures")
    parser.add_argument("--address", default=None,
                        help="with --ray: the Ray cluster to join (HOST:6379, or auto); default: start Ray "
                             "on this machine with its cores")
    parser.add_argument("--faults-result", metavar="FILE", default=None,
                        help="an 'evaluate --faults STEP:K --json' result: the claims table at the head "
                             "of the report then tests the claim on failing agents too")
    parser.add_argument("--rerun-zoo", action="store_true",
                        help="evaluate zoo models again even when their eval.json already holds this "
                             "exact protocol (episodes, steps, seed, tests, action mode)")


def run(args):
    from ..sb3.algorithms import torch_device  # torch: loaded when the command runs
    torch_device(args.device)   # a device torch cannot use: one line, before any work
    if args.zoo_dir:
        use_zoo_dir(args.zoo_dir)
    check_output_dir(args.out, "--out")
    faults = read_faults_result(args.faults_result) if args.faults_result else None
    if args.protocol == "paper":
        args.tests, args.episodes, args.steps = 10, 100, 14400
    if args.address and not args.ray:
        raise ValueError("--address joins a Ray cluster: give it with --ray")
    if args.ray:
        require_ray()                # not installed: one line saying how, before any work
    maps = [m.strip() for m in args.maps.split(",") if m.strip()]
    strategies = args.strategies.split(",") if args.strategies else None
    cells = plan_cells(maps, parse_agents(args.agents), strategies, say=say)
    protocol = Protocol(args.episodes, args.tests, args.steps, args.seed, not args.stochastic, args.device)
    stored = StoredResults(args.out, protocol, rerun_heuristics=args.rerun, rerun_zoo=args.rerun_zoo)
    found = {}
    for cell in cells:
        result, source = stored.find(cell)
        if result is not None:
            found[cell] = result
            report_cell(result, cell, source)
    missing = [c for c in cells if c not in found]
    for cell, result, seconds in evaluate_cells(missing, protocol, progress=not args.no_progress, ray=args.ray,
                                                address=args.address, say=say):
        stored.add(cell, result)     # each stored as soon as it is done
        found[cell] = result
        report_cell(result, cell, f"  ({seconds:.1f} s)")
    paths = write_compare([found[c] for c in cells], args.out, learning_curves=learning_curves(cells),
                          zoo_notes=stored.zoo_notes(cells), faults_result=faults)
    paths += [stored.path] if stored.path.is_file() else []     # every result, written as each finished
    print(f"wrote {len(paths)} files to {args.out} (report: {args.out}/report.md)")
    return 0
