#!/usr/bin/env bash
# short zoo evaluations whose figures must not move under the refactor; $1 = output folder
set -e
mkdir -p "$1"
for s in zoo:rl-msg zoo:rl-no-msg zoo:rl-intention zoo:rl-msg:guarded CR SEBS; do
  patrolsb3 evaluate --strategy $s --map A --agents 3 --episodes 2 --steps 1500 --no-progress --json "$1/${s//:/_}.json" > /dev/null
done
patrolsb3 zoo validate zoo/A/rl-msg/seed0 > "$1/validate.txt" 2>&1 || true
patrolsb3 claims zoo/comparison --faults-result zoo/comparison/faults_A_rl-msg_n3.json > "$1/claims.txt"
