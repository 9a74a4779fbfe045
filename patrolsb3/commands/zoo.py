"""``patrolsb3 zoo list``: every zoo entry with its budget, date, env version and headline
figures; ``patrolsb3 zoo show MAP VARIANT``: one entry's config and evaluation; ``patrolsb3 zoo
export RUN``: a run into the zoo; ``patrolsb3 zoo validate RUN``: rank a run's checkpoints;
``patrolsb3 zoo listening MAP VARIANT``: what its messages carry (:mod:`patrolsb3.listening`);
``patrolsb3 zoo ablation MAP VARIANT``: what the team loses when it cannot trust them
(:mod:`patrolsb3.ablation`); ``patrolsb3 zoo choose MAP VARIANT``: the default seed, by
validation. MAP VARIANT means the main zoo; ``--shelf SHELF`` an entry on one of the zoo's
shelves (``--guarded``: the entries behind the return guard), ``--seed-of-entry K`` one training
seed."""
import json
import math
from pathlib import Path

from ..ablation import ablation_table, message_ablation
from ..listening import listening
from ..locks import hold
from ..names import SHELVES, shelf_option
from ..outputs import check_output_dir, check_output_file, write_json
from ..report import clean_figures
from ..runs import ZooEntry, recorded_path
from ..zoo import (
    ZooError,
    existing_entry_dir,
    export,
    export_destination,
    list_entries,
    load_entry,
    read_entry,
    replace_entry,
)
from ..zoo.cards import write_cards
from ..zoo.evaluation import write_zoo_eval
from ..zoo.validation import choose_default, rank, run_checkpoints, validate


def add_entry_arguments(parser, variant_help: str | None = None) -> None:
    """The arguments that pick one entry: MAP VARIANT, --zoo-dir, --shelf / --guarded, --seed-of-entry K."""
    parser.add_argument("map", help="the map the entry was trained on (A-D)")
    parser.add_argument("variant", help=variant_help or "rl-msg, rl-no-msg or rl-intention")
    parser.add_argument("--zoo-dir", default=None, help="another zoo folder (default: $PATROLSB3_ZOO, else the "
                                                        "checkout's zoo/)")
    add_shelf_arguments(parser)
    parser.add_argument("--seed-of-entry", type=int, default=None, dest="entry_seed", metavar="K",
                        help="the model of training seed K, zoo/MAP/VARIANT/seedK (zoo.load(..., seed=K) in "
                             "Python; --seed is the simulator's); default: the entry's default seed")


def add_shelf_arguments(parser, guarded: bool = True) -> None:
    """--shelf SHELF (and --guarded, short for --shelf guarded): an entry on a shelf of the zoo."""
    parser.add_argument("--shelf", default="", metavar="SHELF",
                        help=f"an entry on a shelf of the zoo, zoo/SHELF/ ({', '.join(SHELVES)}); default: the "
                             f"main zoo")
    if guarded:
        parser.add_argument("--guarded", action="store_true",
                            help="the entry behind the return guard (zoo/guarded/): --shelf guarded")


def add_action(sub, name: str, help: str):
    """A zoo action whose --help shows its own description (argparse shows ``help`` only in the
    list of actions)."""
    return sub.add_parser(name, help=help, description=help)


def add_arguments(parser):
    sub = parser.add_subparsers(dest="zoo_command", required=True, metavar="ACTION")
    p_list = add_action(sub, "list", help="list every zoo entry")
    p_list.add_argument("--zoo-dir", default=None, help="another zoo folder")
    p_show = add_action(sub, "show", help="print one entry's config and evaluation")
    add_entry_arguments(p_show)
    p_export = add_action(sub, "export", help="copy a training run into the zoo (policy only) and "
                                             "evaluate it for 1..max_agents agents into eval.json")
    p_export.add_argument("run_dir", help="run folder of 'patrolsb3 train'")
    p_export.add_argument("--zoo-dir", default=None)
    p_export.add_argument("--checkpoint", default=None,
                          help="checkpoint file to export (default: model.zip, else the newest checkpoint)")
    p_export.add_argument("--cpu-hours", type=float, default=None,
                          help="training CPU hours to record (default: what the run measured in its cpu_time.csv, warm-start stages included)")
    p_export.add_argument("--episodes", type=int, default=10, help="evaluation episodes per team size")
    p_export.add_argument("--steps", type=int, default=14400, help="steps per evaluation episode")
    p_export.add_argument("--seed", type=int, default=0)
    p_export.add_argument("--stochastic", action="store_true",
                          help="evaluate with sampled actions (default: the most likely legal action)")
    p_export.add_argument("--no-eval", action="store_true", help="copy only, no eval.json")
    p_export.add_argument("--overwrite", action="store_true",
                          help="replace an existing entry (its model and every figure of it: eval, listening, "
                               "ablation); without it an existing entry is refused")
    add_shelf_arguments(p_export, guarded=False)
    p_export.add_argument("--as-seed", action="store_true",
                          help="export into the entry's seed<k> subfolder (k: the run's seed), not its default")
    p_val = add_action(sub, "validate", help="evaluate every checkpoint of a run on a short greedy protocol "
                                            "(its own seed) and rank them: fewest battery failures, then AVG^h")
    p_val.add_argument("run_dir", help="run folder of 'patrolsb3 train'")
    p_val.add_argument("--agents", default="1,3,5", help="team sizes (default 1,3,5)")
    p_val.add_argument("--episodes", type=int, default=4, help="episodes per team size (default 4)")
    p_val.add_argument("--steps", type=int, default=3000, help="steps per episode (default 3000 = 5 h)")
    p_val.add_argument("--seed", type=int, default=7, help="simulator seed (default 7; the zoo's eval uses 0)")
    p_val.add_argument("--last", type=int, default=None, help="only the newest N checkpoints")
    p_eval = add_action(sub, "eval", help="evaluate an entry again and rewrite its eval.json (1..max_agents "
                                          "agents, with 95 %% intervals over episodes)")
    add_entry_arguments(p_eval)
    p_eval.add_argument("--episodes", type=int, default=10, help="episodes per team size (default 10)")
    p_eval.add_argument("--steps", type=int, default=14400, help="steps per episode (default 14400)")
    p_eval.add_argument("--seed", type=int, default=0)
    p_eval.add_argument("--stochastic", action="store_true", help="sampled actions instead of greedy")
    p_choose = add_action(sub, "choose", help="pick the paper-setting entry's default seed by the greedy "
                                             "validation of 'zoo validate' and write its default.yml")
    p_choose.add_argument("map")
    p_choose.add_argument("variant")
    p_choose.add_argument("--zoo-dir", default=None)
    add_shelf_arguments(p_choose, guarded=False)
    p_choose.add_argument("--agents", default="1,3,5", help="team sizes (default 1,3,5)")
    p_choose.add_argument("--episodes", type=int, default=4, help="episodes per team size (default 4)")
    p_choose.add_argument("--steps", type=int, default=3000, help="steps per episode (default 3000)")
    p_choose.add_argument("--seed", type=int, default=7, help="simulator seed (default 7; the zoo's eval uses 0)")
    p_cards = add_action(sub, "cards", help="write one model card (markdown) per entry and an index")
    p_cards.add_argument("--out", default="docs/zoo", help="folder of the cards (default docs/zoo)")
    p_cards.add_argument("--zoo-dir", default=None)
    p_lis = add_action(sub, "listening", help="how much an entry's moves depend on the symbols it receives "
                                             "(KL and greedy change when they are randomised) and how it "
                                             "uses its alphabet")
    add_entry_arguments(p_lis, variant_help="rl-msg or rl-intention")
    p_lis.add_argument("--agents", type=int, default=3, help="team size (default 3)")
    p_lis.add_argument("--episodes", type=int, default=8, help="parallel episodes (default 8)")
    p_lis.add_argument("--steps", type=int, default=500, help="simulator steps (default 500)")
    p_lis.add_argument("--seed", type=int, default=1000, help="seed (default 1000; the zoo's eval uses 0)")
    p_abl = add_action(sub, "ablation", help="the entry's AVG^h, MAX^h and collisions when the messages it "
                                            "receives are made constant or shuffled between agents")
    add_entry_arguments(p_abl, variant_help="rl-msg or rl-intention")
    p_abl.add_argument("--agents", type=int, default=3, help="team size (default 3)")
    p_abl.add_argument("--episodes", type=int, default=10, help="episodes (default 10)")
    p_abl.add_argument("--steps", type=int, default=2000, help="simulator steps per episode (default 2000)")
    p_abl.add_argument("--seed", type=int, default=1000, help="seed (default 1000; the zoo's eval uses 0)")
    p_abl.add_argument("--json", default=None, metavar="FILE", help="also write the figures as JSON")


def headline(entry: dict) -> str:
    """Short text of an entry's evaluation: MAX and AVG idleness, collisions, BF rate per n."""
    ev = entry.get("eval") or {}
    parts = []
    for row in ev.get("results", []):
        s = row["summary"]
        parts.append(f"n={row['n_agents']}: {clean_figures(s, precision=0)} "
                     f"BF {s['battery_failure_rate']['mean']:.2f}")
    if not parts:
        return "not evaluated"
    return (f"eval {ev['episodes']} episodes x {ev['steps']} steps: " + "; ".join(parts))


def team_sizes(text) -> tuple[int, ...]:
    """'1,3,5' -> (1, 3, 5); a one-line error naming --agents otherwise."""
    try:
        return tuple(int(n) for n in str(text).split(","))
    except ValueError:
        raise ValueError(f"--agents {text!r}: give team sizes like 1,3,5") from None


def chosen_entry(args):
    """The entry folder MAP VARIANT [--shelf SHELF | --guarded] [--seed-of-entry K] names; it must
    hold a model.

    Raises:
        ZooError: no such entry or seed (:func:`patrolsb3.zoo.existing_entry_dir`).
        ValueError: an unknown shelf, or --guarded with another shelf.
    """
    shelf = shelf_option(args.shelf, args.guarded)
    return existing_entry_dir(args.map, args.variant, args.zoo_dir, seed=args.entry_seed, shelf=shelf)


def run(args):
    if args.zoo_command == "export":
        return export_and_evaluate(args)
    if args.zoo_command == "validate":
        return validate_checkpoints(args)
    if args.zoo_command == "eval":
        path = write_zoo_eval(chosen_entry(args), episodes=args.episodes,
                              steps=args.steps, seed=args.seed, deterministic=not args.stochastic)
        print(f"evaluation written to {recorded_path(path)}")
        return 0
    if args.zoo_command == "cards":
        check_output_dir(args.out, "--out")
        paths = write_cards(args.out, zoo_dir=args.zoo_dir)
        print(f"wrote {len(paths)} files to {args.out}")
        return 0
    if args.zoo_command == "listening":
        figures = listening(load_entry(chosen_entry(args)), n_agents=args.agents,
                            episodes=args.episodes, steps=args.steps, seed=args.seed)
        print(json.dumps({"entry": f"{args.map.upper()}/{args.variant}", **figures}))
        return 0
    if args.zoo_command == "ablation":
        if args.json:
            check_output_file(args.json, "--json")
        for name in ("agents", "episodes", "steps"):
            if getattr(args, name) < 1:
                raise ValueError(f"--{name} must be >= 1, got {getattr(args, name)}")
        policy = load_entry(chosen_entry(args))
        figures = message_ablation(policy, n_agents=args.agents, episodes=args.episodes, steps=args.steps,
                                   seed=args.seed)
        print(ablation_table(f"{args.map.upper()}/{args.variant}", figures))
        if args.json:
            write_json(args.json, {"entry": f"{args.map.upper()}/{args.variant}", **figures}, indent=2)
        return 0
    if args.zoo_command == "show":
        entry = read_entry(chosen_entry(args))
        entry["path"] = recorded_path(entry["path"])      # no path of this machine in the output
        print(json.dumps(entry, indent=2, default=str))
        return 0
    if args.zoo_command == "choose":
        for name in ("episodes", "steps"):
            if getattr(args, name) < 1:
                raise ValueError(f"--{name} must be >= 1, got {getattr(args, name)}")
        chosen = choose_default(args.map, args.variant, zoo_dir=args.zoo_dir, team_sizes=team_sizes(args.agents),
                                episodes=args.episodes, steps=args.steps, seed=args.seed,
                                shelf=shelf_option(args.shelf, False))
        for row in chosen["validation"]:
            print(f"seed {row['seed']}: failures/episode {row['failures']:.2f}  BF rate {row['bf_rate']:.2f}  "
                  f"AVG^h {row['avg_idleness']:.1f}")
        print(f"default: seed {chosen['seed']} ({chosen['chosen_by']})")
        return 0
    entries = list_entries(args.zoo_dir)
    if not entries:
        print("the zoo is empty")
        return 0
    for e in entries:
        c = e["config"]
        budget = c.get("budget", {})
        where = f"/seed{e['seed']}" if e["seed"] is not None else ""
        shelf = f"{e['shelf']}/" if e["shelf"] else ""
        print(f"{shelf}{c.get('map', '?')}/{c.get('variant', '?')}{where}  algo {c.get('algo', '?')}  "
              f"env {c.get('env_version', '?')}  trained {c.get('date', '?')}  "
              f"{budget.get('timesteps', '?')} steps, {budget.get('cpu_hours', '?')} CPU h"
              + ("  behind the return guard (env.return_guard, ours)"
                 if (c.get("env") or {}).get("return_guard") else ""))
        print(f"    {headline(e)}")
    return 0


def export_and_evaluate(args) -> int:
    """``patrolsb3 zoo export``: every argument checked (the whole numbers by
    ``patrolsb3.cli.MINIMUMS``), then the run copied and evaluated
    (eval.json, paper metrics, n = 1..5) in a staging folder beside the entry, which replaces
    the entry only once complete: an interrupted or failed export leaves the old entry whole."""
    import os
    import shutil

    if args.cpu_hours is not None and not args.cpu_hours >= 0:
        raise ValueError(f"--cpu-hours must be a number >= 0, got {args.cpu_hours}")
    if args.checkpoint is not None and not os.path.isfile(args.checkpoint):
        raise ValueError(f"--checkpoint {args.checkpoint}: no such file")
    entry = export_destination(args.run_dir, zoo_dir=args.zoo_dir, as_seed=args.as_seed, shelf=args.shelf)
    entry.parent.mkdir(parents=True, exist_ok=True)
    lock = hold(entry.with_name(f".{entry.name}.lock"), f"{entry} is being exported by another process; wait for it to end")
    try:
        if ZooEntry(entry).model_file.exists() and not args.overwrite:
            raise ZooError(f"{entry} is an entry already; pass --overwrite to replace it (its model and every "
                           f"figure of it), or export with another --zoo-dir")
        staged = entry.with_name(f".{entry.name}.export-{os.getpid()}")
        budget = {"cpu_hours": args.cpu_hours} if args.cpu_hours is not None else {}
        try:
            export(args.run_dir, zoo_dir=args.zoo_dir, budget=budget, checkpoint=args.checkpoint,
                   as_seed=args.as_seed, into=staged, shelf=args.shelf)
            if not args.no_eval:
                write_zoo_eval(staged, episodes=args.episodes, steps=args.steps, seed=args.seed,
                               deterministic=not args.stochastic)
            replace_entry(staged, entry)
        finally:
            if staged.exists():
                shutil.rmtree(staged)
    finally:
        lock.release()
    print(f"exported to {entry}")
    if not args.no_eval:
        print(f"evaluation written to {ZooEntry(entry).evaluation_file}")
    return 0


def validate_checkpoints(args) -> int:
    """``patrolsb3 zoo validate``: one line per checkpoint, then the best by failures and AVG^h."""
    sizes = team_sizes(args.agents)
    paths = run_checkpoints(args.run_dir)
    if args.last:
        paths = paths[-args.last:]
    print(f"{len(paths)} checkpoints; greedy, {args.episodes} episodes x {args.steps} steps for n = "
          f"{','.join(map(str, sizes))}, seed {args.seed}")
    rows = []
    for path in paths:
        row = validate(path, team_sizes=sizes, episodes=args.episodes, steps=args.steps, seed=args.seed)
        rows.append(row)
        swap = "-" if math.isnan(row["swap_battery"]) else f"{100 * row['swap_battery']:.0f} %"
        print(f"{row['timesteps']:>10,} steps  failures/episode {row['failures']:.2f}  BF rate "
              f"{row['bf_rate']:.2f}  AVG^h {row['avg_idleness']:.1f}  battery at swap {swap}  {path}", flush=True)
    print(f"best: {rank(rows)[0]['checkpoint']}")
    return 0
