"""``patrolsb3 claims COMPARE_DIR``: the paper's claims, one row each, with our figure, its 95 %
interval and a verdict, from a comparison's results (``patrolsb3.claims``)."""
from .. import zoo
from ..claims import claims, claims_table, read_faults_result, read_figures, recipes_note
from ..names import SHELVES, display_name, is_learned, shelf_option
from ..outputs import check_output_file, write_json


def add_arguments(parser):
    parser.add_argument("compare_dir", metavar="COMPARE_DIR", help="a 'patrolsb3 compare' output folder")
    parser.add_argument("--zoo-dir", default=None, help="the zoo whose training curves to read (default: zoo/)")
    parser.add_argument("--shelf", default="", metavar="SHELF",
                        help=f"test the claims on the entries of a shelf of the zoo (columns zoo:<variant>:SHELF, "
                             f"curves from zoo/SHELF/; shelves: {', '.join(SHELVES)}) instead of the main zoo's")
    parser.add_argument("--guarded", action="store_true",
                        help="the entries behind the return guard: --shelf guarded")
    parser.add_argument("--faults-result", default=None, metavar="FILE",
                        help="an 'evaluate --faults STEP:K --json' result, for the claim on failing agents")
    parser.add_argument("--json", default=None, metavar="FILE", help="also write the rows as JSON")


def on_shelf(figures: dict, shelf: str) -> dict:
    """The figures the claims test: with a ``shelf``, its columns (``zoo:<variant>:<shelf>``) stand
    in for the learned variants, and a main-zoo column is kept only for a variant the shelf lacks;
    columns of other shelves are left out either way."""
    names = {name for _, _, name, _ in figures}
    shelf_of = {name: zoo.parse_strategy(name)[1] for name in names if is_learned(name)}     # parsed once
    suffix = f":{shelf}"
    kept = {}
    for (m, n, name, metric), figure in figures.items():
        if name not in shelf_of:
            kept[(m, n, name, metric)] = figure
        elif shelf and shelf_of[name] == shelf:
            kept[(m, n, name.removesuffix(suffix), metric)] = figure
        elif shelf_of[name] == "" and not (shelf and name + suffix in names):
            kept.setdefault((m, n, name, metric), figure)
    return kept


def run(args):
    if args.json:
        check_output_file(args.json, "--json", inputs=[args.compare_dir] + ([args.faults_result] if args.faults_result else []))
    shelf = shelf_option(args.shelf, args.guarded)
    figures = on_shelf(read_figures(args.compare_dir), shelf)
    faults = read_faults_result(args.faults_result) if args.faults_result else None
    curves = {m: {v: found for v in zoo.VARIANT_NAMES
                  if zoo.available(m, v, args.zoo_dir, shelf=shelf)
                  and (found := zoo.seed_curves(m, v, args.zoo_dir, shelf=shelf))}
              for m in sorted({k[0] for k in figures})}
    rows = claims(figures, curves=curves, faults_result=faults)
    print(claims_table(rows))
    trained = {(m, display_name(name)): zoo.trained_with(m, zoo.parse_strategy(name)[0], args.zoo_dir, shelf=shelf)
               for m, name in sorted({(k[0], k[2]) for k in figures if is_learned(k[2])})
               if zoo.available(m, zoo.parse_strategy(name)[0], args.zoo_dir, shelf=shelf)}
    if trained:
        print("\n" + recipes_note(trained))
    if args.json:
        write_json(args.json, rows, indent=2)
    return 0
