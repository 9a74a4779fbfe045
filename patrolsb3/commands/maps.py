"""``patrolsb3 maps [NAME ...] [--png DIR]``: list the shipped maps with their figures, draw
each one in the terminal (the file legend), and optionally write a PNG picture of each."""

from ..core.maps import available_maps, load_map
from ..outputs import check_output_dir


def add_arguments(parser):
    parser.add_argument("names", nargs="*", metavar="MAP",
                        help="maps to show: shipped names or .txt paths (default: every shipped map)")
    parser.add_argument("--png", metavar="DIR", help="also write DIR/map_<name>.png for each map")
    parser.add_argument("--no-draw", action="store_true", help="print the table only")


def map_summary(spec) -> dict:
    """The figures ``patrolsb3 maps`` prints for one map."""
    H, W = spec.shape
    return {"name": spec.name, "size": f"{H}x{W}", "vertices": spec.n_vertices,
            "stations": len(spec.stations), "priority_vertices": int((spec.priority > 0).sum())}


def run(args):
    from pathlib import Path

    if args.png:
        check_output_dir(args.png, "--png")

    specs = [load_map(name) for name in (args.names or available_maps())]
    columns = ("name", "size", "vertices", "stations", "priority_vertices")
    rows = [map_summary(spec) for spec in specs]
    widths = {c: max(len(c), *(len(str(r[c])) for r in rows)) for c in columns}
    print("  ".join(c.ljust(widths[c]) for c in columns))
    for r in rows:
        print("  ".join(str(r[c]).ljust(widths[c]) for c in columns))
    if not args.no_draw:
        for spec in specs:
            print(f"\nmap {spec.name} ({spec.source})")        # the file that exists here, shipped or not
            print(spec.to_text())
        print("\nlegend: # obstacle, . vertex, 1-9 priority vertex (idleness rate 1+p), S station")
    if args.png:
        from ..render import draw_map_png
        out = Path(args.png)
        for spec in specs:
            path = draw_map_png(spec, out / f"map_{spec.name.lower()}.png")
            print(f"wrote {path}")
    return 0
