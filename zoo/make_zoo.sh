#!/usr/bin/env bash
# How the zoo was made (run from the repository root). Six training runs side by side on the
# 2-core development machine (each got about a third of a core), then export (policy only) and
# evaluation of every model, then the comparison with the heuristics.
set -euo pipefail
TIMESTEPS=${TIMESTEPS:-1200000}
for spec in "A rl-msg" "A rl-no-msg" "A rl-intention" "B rl-msg" "C rl-msg" "D rl-msg"; do
  set -- $spec
  nohup nice -n 5 patrolsb3 train --map "$1" --variant "$2" --timesteps "$TIMESTEPS" --out runs/zoo \
    --no-progress --set env.episode_steps=1000 --checkpoint-freq 200000 --eval-freq 400000 \
    > "runs/logs/$1_$2.log" 2>&1 &
done
wait
# export + eval.json: 10 episodes x 14,400 steps for each team size 1..5, seed 0
for run in runs/zoo/*/*/MaskableRecurrentPPO_seed0; do
  patrolsb3 zoo export "$run" --episodes 10 --steps 14400 --seed 0 --cpu-hours "${CPU_HOURS:-0.33}"
done
# the comparison (zoo columns read from eval.json: same protocol)
patrolsb3 compare --maps A,B,C,D --agents 1-5 --episodes 10 --steps 14400 --seed 0 --out zoo/comparison
