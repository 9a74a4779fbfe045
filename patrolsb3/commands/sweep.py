"""``patrolsb3 sweep SWEEP.yml``: a grid of training runs (maps x variants x seeds x any --set
key) as Ray Tune trials, each a normal run folder; run it again to resume what is unfinished
(``patrolsb3.sweeps``, ``patrolsb3.distributed``)."""


def add_arguments(parser):
    parser.add_argument("sweep_file", metavar="SWEEP.yml", help="the sweep: grid, timesteps, out (docs/cluster.md)")
    parser.add_argument("--out", default=None, help="root of the run folders (default: the file's out)")
    parser.add_argument("--address", default=None,
                        help="the Ray cluster to join (HOST:6379, or auto); default: start Ray on this "
                             "machine with its cores")
    parser.add_argument("--cpus", type=int, default=None,
                        help="CPUs a local Ray may use (default: all); not with --address")
    parser.add_argument("--cpus-per-trial", type=int, default=1,
                        help="CPUs reserved for each trial, also its torch threads (default 1)")
    parser.add_argument("--dry-run", action="store_true", help="list the trials and their state, start nothing")


def run(args):
    from ..distributed import connect, require_ray, sweep_on_ray
    from ..outputs import check_output_dir
    from ..sweeps import TrialOutcome, check_trial, read_sweep, summary_table, trial_state
    if args.cpus_per_trial < 1:
        raise ValueError(f"--cpus-per-trial must be >= 1, got {args.cpus_per_trial}")
    if args.cpus is not None and (args.cpus < 1 or args.address):
        raise ValueError("--cpus must be >= 1 and is for a local Ray (not with --address)")
    trials = read_sweep(args.sweep_file, out=args.out)
    check_output_dir(trials[0].run_dir.parents[2], "--out")
    outcomes = {t.name: TrialOutcome(t, "pending") for t in trials}
    to_run = []
    for t in trials:
        problem = check_trial(t)
        if problem:
            outcomes[t.name] = TrialOutcome(t, "error", error=problem)
            print(f"trial {t.name}: refused before it started: {problem}", flush=True)
        elif trial_state(t) == "finished":
            outcomes[t.name] = TrialOutcome(t, "skipped")
        else:
            to_run.append(t)
    skipped = sum(o.status == "skipped" for o in outcomes.values())
    print(f"sweep {args.sweep_file}: {len(trials)} trials, {skipped} finished before, {len(to_run)} to run"
          + ("" if not to_run else f" ({sum(trial_state(t) == 'resumable' for t in to_run)} resume from a checkpoint)"),
          flush=True)
    if to_run and not args.dry_run:
        require_ray()
        cpus = connect(args.address, args.cpus).get("CPU", 0)
        print(f"ray: {cpus:.0f} CPUs, {args.cpus_per_trial} per trial", flush=True)
        for name, result in sweep_on_ray(to_run, args.cpus_per_trial).items():
            outcomes[name] = TrialOutcome(outcomes[name].trial, result["status"], result["seconds"], result["error"])
    print(summary_table(list(outcomes.values())))
    return 1 if any(o.status == "error" for o in outcomes.values()) else 0
