"""``patrolsb3 sweep SWEEP.yml``: a grid of training runs (maps x variants x seeds x any --set
key) as Ray Tune trials, each a normal run folder; run it again to resume what is unfinished
(``patrolsb3.sweeps``, ``patrolsb3.distributed``)."""

from ..sweeps import run_sweep, summary_table


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
    parser.add_argument("--precision", default=None, choices=["auto", "fp32", "bf16"],
                        help="training precision of every trial (default: the sweep's or the hyperparameters')")
    parser.add_argument("--dry-run", action="store_true", help="list the trials and their state, start nothing")


def run(args):
    from functools import partial

    outcomes = run_sweep(args.sweep_file, out=args.out, precision=args.precision, address=args.address, cpus=args.cpus,
                         cpus_per_trial=args.cpus_per_trial, dry_run=args.dry_run, say=partial(print, flush=True))
    print(summary_table(outcomes))
    if any(o.status == "error" for o in outcomes):
        return 1
    return 130 if any(o.status == "stopped" for o in outcomes) else 0     # 130: stopped by a signal
