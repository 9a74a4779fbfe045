#!/usr/bin/env bash
# The paper-setting zoo runs: no return guard at training or at evaluation, legible messages
# (env.message_encoding=planes), every variant given the same number of SIMULATOR steps, several
# seeds. Run from the repository root; every run side by side, one torch thread each, each
# stopped cleanly (SIGINT: a checkpoint) after SECONDS; run again with --resume to continue.
#
#   zoo/train_paper_setting.sh 1 SECONDS [--resume]   # stage 1: patrol only (full batteries)
#   zoo/train_paper_setting.sh 2 SECONDS [--resume]   # stage 2: patrol + recharge, from stage 1
#
# RUNS: map:variant:seed triples (default "A:rl-msg:0 A:rl-no-msg:0"); OUT: root of the run
# folders (default runs/paper): OUT/stage<N>/<map>/<variant>/seed<seed>. SIM_STEPS: the stage's
# budget in vector-env simulator steps (each advances the 8 parallel episodes by one step;
# default 25,000 for stage 1, 200,000 for stage 2). A run's --timesteps (agent-steps, SB3's
# count: 40 rows x env steps) is SIM_STEPS x 40 x phases, phases = 2 with same-step messages
# (rl-msg, rl-intention), 1 without (rl-no-msg): equal simulator steps for every variant. Raise
# SIM_STEPS and pass --resume to train a stage further. SET: extra KEY=VALUE overrides passed
# to --set for every run of this call (e.g. SET="ent_coef_message=0.01"; pass the same on
# --resume, since a resumed run refuses settings other than its own).
#
# Stage 1 learns the patrol with the battery out of the way (300-step episodes, full batteries).
# Stage 2 learns when to swap, unshielded: 1,500-step episodes from 15-100 % batteries, half of
# every batch (parallel episodes 0, 2, 4, 6) a recharge drill (400 steps from 5-40 %), and the
# home shaping env.c_home=50 (a difference of potentials toward the station for low batteries;
# core/reward.py). These are training aids: none of them acts at evaluation (the paper's env),
# and every variant gets them alike. zoo/README.md and docs/experiments/ say why each is there.
set -euo pipefail
STAGE=${1:?usage: zoo/train_paper_setting.sh 1|2 SECONDS [--resume]}
SECONDS_PER_CALL=${2:?usage: zoo/train_paper_setting.sh 1|2 SECONDS [--resume]}
RESUME=${3:-}
RUNS=${RUNS:-"A:rl-msg:0 A:rl-no-msg:0"}
OUT=${OUT:-runs/paper}
read -r -a extra_set <<< "${SET:-}"
# the settings of each stage: the recipes zoo-stage1 and zoo-stage2 (patrolsb3/sb3/recipes.py)
case "$STAGE" in
  1) SIM=${SIM_STEPS:-25000} ;;
  2) SIM=${SIM_STEPS:-200000} ;;
  *) echo "stage must be 1 or 2" >&2; exit 2 ;;
esac
mkdir -p "$OUT/logs"
for run in $RUNS; do
  IFS=: read -r map variant seed <<< "$run"
  phases=2; [ "$variant" = rl-no-msg ] && phases=1
  timesteps=$((SIM * 40 * phases))
  init=()
  if [ "${#extra_set[@]}" -gt 0 ]; then init+=(--set "${extra_set[@]}"); fi
  if [ "$STAGE" = 2 ] && [ -z "$RESUME" ]; then init+=(--init-from "$OUT/stage1/$map/$variant/seed$seed"); fi
  nohup timeout -s INT "$SECONDS_PER_CALL" patrolsb3 train --map "$map" --variant "$variant" --seed "$seed" \
    --timesteps "$timesteps" --out "$OUT/stage$STAGE" --run-id "seed$seed" $RESUME "${init[@]}" \
    --device cpu --no-progress --checkpoint-freq 500000 --eval-freq 0 --recipe "zoo-stage$STAGE" \
    >> "$OUT/logs/stage${STAGE}_${map}_${variant}_seed${seed}.log" 2>&1 &
done
wait
tail -n 2 "$OUT"/logs/stage"${STAGE}"_*.log
