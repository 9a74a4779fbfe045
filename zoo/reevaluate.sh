#!/usr/bin/env bash
# Evaluate again every zoo entry whose eval.json was written under other draws than this code's
# (patrolsb3.core.streams.STREAMS_VERSION; before paired episodes: none), one after the other, on
# the zoo's protocol (10 episodes x 14,400 steps per team size 1-5, greedy, seed 0). An entry
# already evaluated under these draws is skipped, so the same command continues after a stop.
# About 10 minutes per entry on one core. Run from the repository root:
#
#   zoo/reevaluate.sh            # every stale entry, the paper's setting and behind the guard
#   zoo/reevaluate.sh A          # only map A's
#
# Then the comparisons (their heuristics are evaluated again too, about 25 s a cell):
#   patrolsb3 compare --maps A,B,C,D --agents 1-5 --episodes 10 --steps 14400 --out zoo/comparison \
#     --faults-result zoo/comparison/faults_A_rl-msg_n3.json
set -euo pipefail
MAPS=${1:-}
python - "$MAPS" <<'EOF' | while read -r map variant seed guarded; do
import sys
from patrolsb3 import zoo
from patrolsb3.core.streams import STREAMS_VERSION
maps = set(sys.argv[1].upper().split(",")) if sys.argv[1] else None
for entry in zoo.list_entries():
    config = entry["config"]
    if maps and str(config["map"]).upper() not in maps:
        continue
    if (entry["eval"] or {}).get("draws") != STREAMS_VERSION:
        seed = entry["seed"] if entry["seed"] is not None else "-"
        print(config["map"], config["variant"], seed, "guarded" if entry["guard"] else "paper")
EOF
  args=(zoo eval "$map" "$variant" --episodes 10 --steps 14400)
  [ "$seed" != "-" ] && args+=(--seed-of-entry "$seed")
  [ "$guarded" = guarded ] && args+=(--guarded)
  echo "$(date +%T) ${args[*]}"
  patrolsb3 "${args[@]}" 2>&1 | tr '\r' '\n' | grep -v "step/s" | tail -1
done
