#!/usr/bin/env bash
# Evaluate again every zoo entry whose eval.json was written under other draws than this code's
# (patrolsb3.core.streams.STREAMS_VERSION; before paired episodes: none), one after the other, on
# the zoo's protocol (10 episodes x 14,400 steps per team size 1-5, greedy, seed 0). An entry
# already evaluated under these draws is skipped, so the same command continues after a stop.
# About 10 minutes per entry on one core. Run from the repository root:
#
#   zoo/reevaluate.sh                  # every stale entry, the main zoo's and every shelf's
#   zoo/reevaluate.sh A                # only map A's
#   zoo/reevaluate.sh A,B,C,D guarded  # only one shelf's entries (guarded, paper-recipe, cd10),
#                                      # or: paper (the main zoo's)
#
# Each entry is checked again just before it is evaluated, so two calls on two cores (say one
# for paper, one for guarded) never evaluate again an entry that the other has finished.
#
# Then the comparisons (their heuristics are evaluated again too, about 10 s a cell):
#   patrolsb3 compare --maps A,B,C,D --agents 1-5 --episodes 10 --steps 14400 --out zoo/comparison \
#     --faults-result zoo/comparison/faults_A_rl-msg_n3.json
set -euo pipefail
MAPS=${1:-}
KIND=${2:-}
shelves=$(python -c "from patrolsb3.names import SHELVES; print(' '.join(SHELVES))")
case " paper $shelves " in
  *" ${KIND:-paper} "*) ;;
  *) echo "reevaluate.sh: the second argument must be paper or a shelf ($shelves), not '$KIND'" >&2; exit 2 ;;
esac

stale() {  # one line per stale entry: map variant seed|- paper|<shelf>
  python - "$MAPS" "$KIND" <<'EOF'
import sys
from patrolsb3 import zoo
from patrolsb3.core.streams import STREAMS_VERSION
maps = set(sys.argv[1].upper().split(",")) if sys.argv[1] else None
for entry in zoo.list_entries():
    config = entry["config"]
    kind = entry["shelf"] or "paper"
    if (maps and str(config["map"]).upper() not in maps) or sys.argv[2] not in ("", kind):
        continue
    if (entry["eval"] or {}).get("draws") != STREAMS_VERSION:
        seed = entry["seed"] if entry["seed"] is not None else "-"
        print(config["map"], config["variant"], seed, kind)
EOF
}

stale | while read -r map variant seed kind; do
  still=$(stale)          # read whole: grep -q on a pipe would cut the list short (a broken pipe)
  grep -qx "$map $variant $seed $kind" <<< "$still" || continue   # finished meanwhile by another call
  args=(zoo eval "$map" "$variant" --episodes 10 --steps 14400)
  [ "$seed" != "-" ] && args+=(--seed-of-entry "$seed")
  [ "$kind" != paper ] && args+=(--shelf "$kind")
  echo "$(date +%T) ${args[*]}"
  patrolsb3 "${args[@]}" 2>&1 | tr '\r' '\n' | grep -v "step/s" | tail -1
done
