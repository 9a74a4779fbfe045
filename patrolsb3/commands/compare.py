"""``patrolsb3 compare``: every strategy x maps x team sizes -> the paper's tables, a markdown
report and plots (see ``patrolsb3.report``). Zoo columns (INTENTION, NOMSG, MSG) are the entries
in the paper's setting (no return guard), filled when ``patrolsb3.zoo`` has one for the map and
said to be missing otherwise; the entries behind the guard are columns only when asked for
(``--strategies ...,zoo:rl-msg:guarded``). Heuristic results are kept in
``OUT/results.json`` as they finish (``patrolsb3.result_store``): the same command again
resumes an interrupted comparison or redraws a finished one without running it again."""
from ..names import is_learned


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


def zoo_note(zoo, map_name: str, strategy: str, reused: bool, pooled=None) -> str:
    """The report's line about a zoo column: its setting (behind the return guard or the paper's),
    which training seeds its figures are (pooled: ``(seeds pooled, seeds left out)``) and whether
    they were reused from the entries' eval.json or computed now."""
    variant, guard = zoo.parse_strategy(strategy)
    folder = zoo.entry_dir(map_name, variant, guard=guard)
    config = zoo.read_entry(folder)["config"]
    guarded = bool((config.get("env") or {}).get("return_guard"))
    setting = ("behind the return guard (env.return_guard, ours: the heuristics' recharge rule as a "
               "shield)" if guarded else "the paper's setting (no return guard)")
    if guard:
        which = ""
    elif pooled and len(pooled[0]) > 1:
        which = (f"training seeds {', '.join(map(str, pooled[0]))} pooled (+- is the std of the seeds' "
                 f"means, the interval is over all their episodes together); ")
    else:
        shown = pooled[0][0] if pooled else config.get("seed", "?")
        which = f"training seed {shown} ({default_reason(zoo, map_name, variant)}); "
    if pooled and pooled[1]:
        which += (f"seed{'s' if len(pooled[1]) > 1 else ''} {', '.join(map(str, pooled[1]))} left out (no "
                  f"eval.json with per-episode figures for this protocol: 'patrolsb3 zoo eval'); ")
    return f"{setting}; {which}figures {'reused from the eval.json' if reused else 'computed now'}"


def default_reason(zoo, map_name: str, variant: str) -> str:
    """Why the paper-setting entry's default seed is the default, for the report."""
    chosen = zoo.default_seed(map_name, variant) or {}
    have = zoo.seeds(map_name, variant)
    return f"{chosen.get('chosen_by', '?')}; the entry has {len(have)} seed{'s' if len(have) != 1 else ''}"


def timed(function, **kwargs):
    """``(function(**kwargs), seconds it took)``."""
    import time
    begun = time.time()
    return function(**kwargs), time.time() - begun


def report_cell(r: dict, name: str, n: int, source: str) -> None:
    """The progress line of one cell: its figures and where they came from (or its time)."""
    from ..report import clean_figures
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
    parser.add_argument("--rerun", action="store_true",
                        help="evaluate the heuristics (only them; see --rerun-zoo) again even when OUT/results.json already holds "
                             "a result of this exact protocol (a rerun or an interrupted run reuses them)")
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
    import importlib

    from ..evaluate import evaluate, evaluation_setup, request_of
    from ..report import EXTRA_COLUMNS, ZOO_COLUMNS, write_compare
    from ..result_store import ResultStore
    from ..sb3.algorithms import torch_device
    torch_device(args.device)   # a device torch cannot use: one line, before any work
    if args.zoo_dir:
        from ..zoo import use_zoo_dir
        use_zoo_dir(args.zoo_dir)
    from ..outputs import check_output_dir
    check_output_dir(args.out, "--out")
    from ..claims import read_faults_result
    faults = read_faults_result(args.faults_result) if args.faults_result else None
    if args.protocol == "paper":
        args.tests, args.episodes, args.steps = 10, 100, 14400
    maps = [m.strip() for m in args.maps.split(",") if m.strip()]
    if duplicates := sorted({m for m in maps if maps.count(m) > 1}):
        raise ValueError(f"--maps {args.maps}: {', '.join(duplicates)} given more than once")
    sizes = parse_agents(args.agents)
    try:
        zoo = importlib.import_module("patrolsb3.zoo")
    except ImportError:
        zoo = None
    from ..core.maps import load_map
    from ..evaluate import canonical_name
    from ..strategies import REGISTRY
    for m in maps:                                            # fail now, not after an hour
        load_map(m)
    if max(sizes) > 5:
        raise ValueError(f"--agents {args.agents}: at most 5 agents (max_agents) per team")
    for name in (args.strategies or "").split(","):
        name = canonical_name(name) if name.strip() else ""
        if name and not is_learned(name) and name not in REGISTRY:
            raise ValueError(f"unknown strategy {name!r}; known: {', '.join(REGISTRY)}, zoo:<variant> "
                             f"or zoo:<variant>:guarded")
        if is_learned(name):
            if zoo is None:
                raise ValueError(f"{name}: patrolsb3.zoo cannot be imported")
            variant, guard = zoo.parse_strategy(name)
            missing = [m for m in maps if not zoo.available(m, variant, guard=guard)]
            if missing:
                raise ValueError(f"{name}: no zoo model for map(s) {', '.join(missing)}"
                                 + ("" if guard else " in the paper's setting"))
    if args.address and not args.ray:
        raise ValueError("--address joins a Ray cluster: give it with --ray")
    if args.ray:
        from ..distributed import require_ray
        require_ray()                # not installed: one line saying how, before any work
    store = ResultStore(args.out)
    cells = []                       # (map, strategy, team size) in report order
    for m in maps:
        if args.strategies:
            names = [canonical_name(s) for s in args.strategies.split(",") if s.strip()]
        else:
            names = ["CR", "PART", "SEBS", *EXTRA_COLUMNS]
            if zoo is not None:
                names += [s for s in ZOO_COLUMNS.values() if zoo.available(m, zoo.parse_strategy(s)[0])]
                absent = [s for s in ZOO_COLUMNS.values() if s not in names]
                if absent:
                    print(f"map {m.upper()}: no entry in the paper's setting for {', '.join(absent)}; those "
                          f"columns stay empty (the entries behind the return guard: --strategies "
                          f"...,{absent[0]}:guarded)", flush=True)
        cells += [(m, name, n) for name in names for n in sizes]
    for m, name in dict.fromkeys((m, name) for m, name, _ in cells if is_learned(name)):
        variant, guard = zoo.parse_strategy(name)
        if not guard:    # several seeds and no default.yml: one line saying how to choose, before any work
            zoo.default_seed(m, variant)
    found, sources = {}, {}
    pooled = {}                      # {(MAP, zoo strategy): (seeds pooled, seeds left out)}
    for m, name, n in cells:         # what a zoo entry's eval.json or results.json already holds
        r = None
        if zoo is not None and is_learned(name) and not args.rerun_zoo:
            variant, guard = zoo.parse_strategy(name)
            if guard:
                r = zoo.cached_result(m, variant, n, args.episodes, args.steps, args.seed, args.tests,
                                      deterministic=not args.stochastic, guard=True)
            else:                    # the paper's setting: every seed with this protocol, pooled
                r = zoo.pooled_result(m, variant, n, args.episodes, args.steps, args.seed, args.tests,
                                      deterministic=not args.stochastic)
                if r is not None:
                    pooled[(m.upper(), name)] = (r["training_seeds"], r["unpooled_seeds"])
            sources[(m, name, n)] = "  (from the zoo's eval.json; --rerun-zoo to run it)" if r else ""
        if r is None and not args.rerun and not is_learned(name):
            spec, cfg = evaluation_setup(m, n, args.episodes, args.tests, args.steps)
            r = store.find(request_of(name, spec, n, args.episodes, args.tests, args.steps,
                                      args.seed, cfg, deterministic=not args.stochastic))
            sources[(m, name, n)] = f"  (from {store.path}; --rerun to run it)" if r else ""
        if r is not None:
            found[(m, name, n)] = r
            report_cell(r, name, n, sources[(m, name, n)])
    missing = [c for c in cells if c not in found]
    jobs = [dict(strategy=name, map_name=m, n_agents=n, episodes=args.episodes, tests=args.tests,
                 steps=args.steps, seed=args.seed, deterministic=not args.stochastic, device=args.device)
            for m, name, n in missing]
    if args.ray:
        from ..distributed import connect, evaluate_on_ray
        cpus = connect(args.address).get("CPU", 0)
        print(f"ray: {len(jobs)} cells on {cpus:.0f} CPUs", flush=True)
        finished = ((missing[i], r, seconds) for i, r, seconds in evaluate_on_ray(jobs))
    else:
        finished = ((cell, *timed(evaluate, progress=not args.no_progress, **job)) for cell, job in zip(missing, jobs))
    for (m, name, n), r, seconds in finished:   # each stored as soon as it is done
        if not is_learned(name):
            store.add(r)
        found[(m, name, n)] = r
        report_cell(r, name, n, f"  ({seconds:.1f} s)")
    results = [found[c] for c in cells]
    zoo_notes = {(m.upper(), name): zoo_note(zoo, m, name, reused=bool(sources.get((m, name, n))),
                                             pooled=pooled.get((m.upper(), name)))
                 for m, name, n in cells if is_learned(name)}
    curves = {}              # {MAP: {variant (or variant:guarded): [curve.csv of every seed]}} of the zoo columns
    for m, name, n in cells:
        if is_learned(name):
            variant, guard = zoo.parse_strategy(name)
            if found := zoo.seed_curves(m, variant, guard=guard):
                curves.setdefault(m.upper(), {})[name[4:]] = found
    paths = write_compare(results, args.out, learning_curves=curves, zoo_notes=zoo_notes,
                          faults_result=faults)
    paths += [store.path] if store.path.is_file() else []     # every result, written as each finished
    print(f"wrote {len(paths)} files to {args.out} (report: {args.out}/report.md)")
    return 0
