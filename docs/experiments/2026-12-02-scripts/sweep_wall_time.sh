#!/usr/bin/env bash
# Wall time of a sweep of 4 short trials on a local Ray with 2 CPUs, against the same 4 runs
# trained one after another with `patrolsb3 train` (docs/cluster.md). Needs the ray extra.
#   docs/experiments/2026-12-02-scripts/sweep_wall_time.sh [OUT]
set -euo pipefail
OUT=${1:-/tmp/sweep_wall_time}
STEPS=${STEPS:-40000}
rm -rf "$OUT"; mkdir -p "$OUT"
cat > "$OUT/sweep.yml" <<YML
out: $OUT/ray
timesteps: $STEPS
set: {checkpoint_freq: 20000, eval_freq: 0}
grid: {map: [A], variant: [rl-msg], seed: [0, 1, 2, 3]}
YML
uptime
start=$(date +%s.%N)
for seed in 0 1 2 3; do
  patrolsb3 train --map A --variant rl-msg --seed "$seed" --timesteps "$STEPS" --out "$OUT/serial" \
    --run-id "seed$seed" --checkpoint-freq 20000 --eval-freq 0 --no-progress --device cpu > /dev/null
done
serial=$(echo "$(date +%s.%N) - $start" | bc)
start=$(date +%s.%N)
patrolsb3 sweep "$OUT/sweep.yml" --cpus 2 > "$OUT/sweep.log" 2>&1
ray=$(echo "$(date +%s.%N) - $start" | bc)
uptime
grep "finished in" "$OUT/sweep.log"
printf 'one after another: %.1f s\nsweep on Ray, 2 CPUs: %.1f s (ratio %.2f)\n' "$serial" "$ray" "$(echo "$serial / $ray" | bc -l)"
