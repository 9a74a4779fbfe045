#!/usr/bin/env bash
# How the zoo was made (run from the repository root): six training runs side by side on the
# 2-core development machine (about a third of a core each), 3,600 s then 2,100 s more with
# --resume; export (policy only) with eval.json (10 episodes x 14,400 steps for n = 1..5,
# seed 0); then the comparison with the heuristics. Settings and why: zoo/README.md.
set -euo pipefail
export ZOO_RUNS="A:rl-msg A:rl-no-msg A:rl-intention B:rl-msg C:rl-msg D:rl-msg" ABLATIONS=""
zoo/train_parallel.sh 3600
zoo/train_parallel.sh 2100 --resume
rm -rf zoo/A zoo/B zoo/C zoo/D
EVAL_ARGS="--episodes 10 --steps 14400 --seed 0" zoo/export_runs.sh 0.53
patrolsb3 compare --maps A,B,C,D --agents 1-5 --episodes 10 --steps 14400 --seed 0 --out zoo/comparison
