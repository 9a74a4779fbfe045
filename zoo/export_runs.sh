#!/usr/bin/env bash
# Export every zoo run of runs/zoo (policy only, no optimizer state) into ZOO_DIR (default zoo),
# side by side, with the CPU hours each run trained; EVAL_ARGS are passed to 'patrolsb3 zoo
# export' (default --no-eval: copy only; pass the evaluation options to write eval.json).
#   zoo/export_runs.sh CPU_HOURS
set -uo pipefail
CPU_HOURS=${1:?usage: zoo/export_runs.sh CPU_HOURS}
ZOO_DIR=${ZOO_DIR:-zoo}
for run in runs/zoo/*/*/MaskableRecurrentPPO_seed0; do
  patrolsb3 zoo export "$run" --zoo-dir "$ZOO_DIR" --cpu-hours "$CPU_HOURS" ${EVAL_ARGS:---no-eval} &
done
wait
