#!/usr/bin/env bash
# The zoo's two-stage training (run from the repository root), every run side by side on this
# 2-core machine, one torch thread each. Why two stages: zoo/README.md ("How they were trained").
#
#   zoo/train_two_stage.sh 1 SECONDS [--resume]   # stage 1: patrol only, runs/stage1
#   zoo/train_two_stage.sh 2 SECONDS [--resume]   # stage 2: patrol + recharge, runs/zoo,
#                                                 # each run started from its stage-1 weights
#
# Stage 1 learns to patrol with the battery out of the way (300-step episodes, every battery
# full, so no agent needs the station); stage 2 starts from those weights and learns when to
# swap in 1,500-step episodes with starting batteries of 15-100 %, long enough that each agent
# needs two or three swaps and swapping early costs patrol time. STAGE1_RUNS / ZOO_RUNS pick
# the runs (map:variant), STAGE1_OUT / STAGE2_OUT the run roots (default runs/stage1, runs/zoo);
# the shared settings below apply to every variant alike.
set -euo pipefail
STAGE=${1:?usage: zoo/train_two_stage.sh 1|2 SECONDS [--resume]}
SECONDS_PER_CALL=${2:?usage: zoo/train_two_stage.sh 1|2 SECONDS [--resume]}
RESUME=${3:-}
# env.local_idleness and env.c_d (the difference reward's weight, paper 50 / 5 = 10) are this
# zoo's changes to the observation and the reward scale; zoo/README.md says why
SHARED="normalize_reward=true gamma=0.99 n_minibatches=4 env.local_idleness=true env.c_d=200"
export ABLATIONS=""
case "$STAGE" in
  1) export ZOO_OUT=${STAGE1_OUT:-runs/stage1} TIMESTEPS=${TIMESTEPS:-2000000} \
       ZOO_RUNS=${STAGE1_RUNS:-"A:rl-msg A:rl-no-msg A:rl-intention B:rl-msg C:rl-msg D:rl-msg"} \
       ZOO_SET="env.episode_steps=300 env.init_battery=[1.0,1.0] $SHARED learning_rate=drop_6e-4_3e-4" ;;
  2) export ZOO_OUT=${STAGE2_OUT:-runs/zoo} TIMESTEPS=${TIMESTEPS:-3000000} \
       INIT_FROM="${STAGE1_OUT:-runs/stage1}/{map}/{variant}/MaskableRecurrentPPO_seed0" \
       ZOO_RUNS=${ZOO_RUNS:-"A:rl-msg A:rl-no-msg A:rl-intention B:rl-msg C:rl-msg D:rl-msg"} \
       ZOO_SET="env.episode_steps=1500 env.init_battery=[0.15,1.0] $SHARED learning_rate=3e-4 curriculum=false" ;;
  *) echo "stage must be 1 or 2" >&2; exit 2 ;;
esac
exec zoo/train_parallel.sh "$SECONDS_PER_CALL" $RESUME
