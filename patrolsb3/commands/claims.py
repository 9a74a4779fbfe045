"""``patrolsb3 claims COMPARE_DIR``: the paper's claims, one row each, with our figure, its 95 %
interval and a verdict, from a comparison's results (``patrolsb3.claims``)."""
from .. import zoo
from ..claims import claims, claims_table, read_faults_result, read_figures, recipes_note
from ..names import display_name, is_learned
from ..outputs import check_output_file, write_json


def add_arguments(parser):
    parser.add_argument("compare_dir", metavar="COMPARE_DIR", help="a 'patrolsb3 compare' output folder")
    parser.add_argument("--zoo-dir", default=None, help="the zoo whose training curves to read (default: zoo/)")
    parser.add_argument("--guarded", action="store_true",
                        help="test the claims on the entries behind the return guard (columns "
                             "zoo:<variant>:guarded, curves from zoo/guarded/) instead of the paper's setting")
    parser.add_argument("--faults-result", default=None, metavar="FILE",
                        help="an 'evaluate --faults STEP:K --json' result, for the claim on failing agents")
    parser.add_argument("--json", default=None, metavar="FILE", help="also write the rows as JSON")


def run(args):
    if args.json:
        check_output_file(args.json, "--json", inputs=[args.compare_dir] + ([args.faults_result] if args.faults_result else []))
    figures = read_figures(args.compare_dir)
    if args.guarded:   # the guarded columns stand in for the learned variants; paper-setting ones are left out
        suffix = f":{zoo.GUARDED}"
        figures = {(m, n, name.removesuffix(suffix), metric): f for (m, n, name, metric), f in figures.items()
                   if name.endswith(suffix) or not is_learned(name)
                   or not any(k[2] == name + suffix for k in figures)}
    faults = read_faults_result(args.faults_result) if args.faults_result else None
    curves = {m: {v: found for v in zoo.VARIANT_NAMES
                  if zoo.available(m, v, args.zoo_dir, guard=args.guarded)
                  and (found := zoo.seed_curves(m, v, args.zoo_dir, guard=args.guarded))}
              for m in sorted({k[0] for k in figures})}
    rows = claims(figures, curves=curves, faults_result=faults)
    print(claims_table(rows))
    trained = {(m, display_name(name)): zoo.trained_with(m, zoo.parse_strategy(name)[0], args.zoo_dir,
                                                            guard=args.guarded)
               for m, name in sorted({(k[0], k[2]) for k in figures if is_learned(k[2])})
               if zoo.available(m, zoo.parse_strategy(name)[0], args.zoo_dir, guard=args.guarded)}
    if trained:
        print("\n" + recipes_note(trained))
    if args.json:
        write_json(args.json, rows, indent=2)
    return 0
