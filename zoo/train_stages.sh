#!/usr/bin/env bash
# The zoo's staged training (run from the repository root), every run side by side on this
# 2-core machine, one torch thread each. Why stages: zoo/README.md ("How they were trained").
#
#   zoo/train_stages.sh 1 SECONDS [--resume]   # stage 1: patrol only, STAGE1_OUT (runs/stage1)
#   zoo/train_stages.sh 2 SECONDS [--resume]   # stage 2: patrol + recharge, STAGE2_OUT (runs/zoo)
#   zoo/train_stages.sh 3 SECONDS [--resume]   # stage 3: recharge drill, STAGE3_OUT (runs/stage3)
#   zoo/train_stages.sh 4 SECONDS [--resume]   # stage 4: drill + long episodes mixed, STAGE4_OUT (runs/stage4)
#   zoo/train_stages.sh 2h SECONDS [--resume]  # stages 2-4 in one: mixed + home shaping, STAGE2H_OUT (runs/stage2h)
#   zoo/train_stages.sh g SECONDS [--resume]   # stages 2-4 in one: long episodes behind the return guard, STAGEG_OUT (runs/stageg)
#
# Each stage after the first starts from the weights of the stage before it (its run folder:
# model.zip, or the newest checkpoint of a run stopped by time).
# Stage 1 learns to patrol with the battery out of the way (300-step episodes, every battery
# full, so no agent needs the station); stage 2 learns when to swap in 1,500-step episodes with
# starting batteries of 15-100 %, long enough that each agent needs two or three swaps and
# swapping early costs patrol time. Stage 3 is a drill of the recharge itself: 400-step episodes
# whose batteries start at 5-40 %, so that most of what an agent lives through is the trip to
# the station (stage 2 alone left agents patrolling until their battery ran out); choose its
# checkpoint with `patrolsb3 zoo validate` (a later stage back on long episodes erased the
# recharge again: zoo/README.md). Stage 4 starts from the chosen drill checkpoint (exported to
# the zoo: STAGE4_FROM, default zoo/{map}/{variant}) and mixes both in every batch: four of the
# eight parallel episodes (teams 1, 1, 2, 4) are drill episodes, the other four (teams 1, 1, 3,
# 5) last 1,500 steps from 15-100 %, so the patrol improves on long episodes while the
# recharge keeps being practised; choose its checkpoint with `patrolsb3 zoo validate` too.
# Stage 2h (B and D's v6) replaces stages 2-4: from the stage-1 weights, stage 4's mix of drill
# and long episodes with the home shaping env.c_home=50 (core/reward.py), which pays a
# low-battery agent for each step toward the station; without it B never found the station.
# Stage g (v7) replaces stages 2-4 too: long episodes (1,500 steps, batteries 15-100 %) with the
# return guard env.return_guard=true (core/masks.py), the heuristics' recharge rule as a shield
# on the policy's moves, so that the policy learns the patrol only; from the stage-1 weights
# (STAGEG_FROM, default STAGE1_OUT's runs; zoo/{map}/{variant} to start from a zoo entry).
# STAGE1_RUNS / ZOO_RUNS pick the runs (map:variant); the shared settings below apply to every
# variant alike.
set -euo pipefail
STAGE=${1:?usage: zoo/train_stages.sh 1|2|3|4|2h|g SECONDS [--resume]}
SECONDS_PER_CALL=${2:?usage: zoo/train_stages.sh 1|2|3|4|2h|g SECONDS [--resume]}
RESUME=${3:-}
# env.local_idleness and env.c_d (the difference reward's weight, paper 50 / 5 = 10) are this
# zoo's changes to the observation and the reward scale; zoo/README.md says why
SHARED="normalize_reward=true gamma=0.99 n_minibatches=4 env.local_idleness=true env.c_d=200"
export ABLATIONS=""
# run folder patterns ({map} and {variant} are filled in by train_parallel.sh; kept out of
# ${VAR:-default} because bash ends such a default at the first "}")
MAP_VARIANT="{map}/{variant}"
STAGE1_RUN="${STAGE1_OUT:-runs/stage1}/$MAP_VARIANT/MaskableRecurrentPPO_seed0"
case "$STAGE" in
  1) export ZOO_OUT=${STAGE1_OUT:-runs/stage1} TIMESTEPS=${TIMESTEPS:-2000000} \
       ZOO_RUNS=${STAGE1_RUNS:-"A:rl-msg A:rl-no-msg A:rl-intention B:rl-msg C:rl-msg D:rl-msg"} \
       ZOO_SET="env.episode_steps=300 env.init_battery=[1.0,1.0] $SHARED learning_rate=drop_6e-4_3e-4" ;;
  2) export ZOO_OUT=${STAGE2_OUT:-runs/zoo} TIMESTEPS=${TIMESTEPS:-3000000} \
       INIT_FROM="${STAGE1_OUT:-runs/stage1}/{map}/{variant}/MaskableRecurrentPPO_seed0" \
       ZOO_RUNS=${ZOO_RUNS:-"A:rl-msg A:rl-no-msg A:rl-intention B:rl-msg C:rl-msg D:rl-msg"} \
       ZOO_SET="env.episode_steps=1500 env.init_battery=[0.15,1.0] $SHARED learning_rate=3e-4 curriculum=false" ;;
  3) export ZOO_OUT=${STAGE3_OUT:-runs/stage3} TIMESTEPS=${TIMESTEPS:-1228800} CHECKPOINT_FREQ=100000 \
       INIT_FROM="${STAGE2_OUT:-runs/zoo}/{map}/{variant}/MaskableRecurrentPPO_seed0" \
       ZOO_RUNS=${ZOO_RUNS:-"A:rl-msg A:rl-no-msg A:rl-intention"} \
       ZOO_SET="env.episode_steps=400 env.init_battery=[0.05,0.4] $SHARED learning_rate=3e-4 curriculum=false" ;;
  4) export ZOO_OUT=${STAGE4_OUT:-runs/stage4} TIMESTEPS=${TIMESTEPS:-700000} CHECKPOINT_FREQ=100000 \
       INIT_FROM="${STAGE4_FROM:-zoo/$MAP_VARIANT}" \
       ZOO_RUNS=${ZOO_RUNS:-"A:rl-msg A:rl-no-msg A:rl-intention"} \
       ZOO_SET="env.episode_steps=1500 env.init_battery=[0.15,1.0] mix.episodes=[0,2,4,6] mix.env.episode_steps=400 mix.env.init_battery=[0.05,0.4] $SHARED learning_rate=3e-4 curriculum=false" ;;
  2h) export ZOO_OUT=${STAGE2H_OUT:-runs/stage2h} TIMESTEPS=${TIMESTEPS:-2700000} CHECKPOINT_FREQ=100000 \
       INIT_FROM="${STAGE1_OUT:-runs/stage1}/{map}/{variant}/MaskableRecurrentPPO_seed0" \
       ZOO_RUNS=${ZOO_RUNS:-"B:rl-msg D:rl-msg"} \
       ZOO_SET="env.episode_steps=1500 env.init_battery=[0.15,1.0] mix.episodes=[0,2,4,6] mix.env.episode_steps=400 mix.env.init_battery=[0.05,0.4] env.c_home=50 $SHARED learning_rate=3e-4 curriculum=false" ;;
  g) export ZOO_OUT=${STAGEG_OUT:-runs/stageg} TIMESTEPS=${TIMESTEPS:-4000000} CHECKPOINT_FREQ=250000 \
       INIT_FROM="${STAGEG_FROM:-$STAGE1_RUN}" \
       ZOO_RUNS=${ZOO_RUNS:-"A:rl-msg B:rl-msg C:rl-msg D:rl-msg"} \
       ZOO_SET="env.episode_steps=1500 env.init_battery=[0.15,1.0] env.return_guard=true $SHARED learning_rate=3e-4 curriculum=false" ;;
  *) echo "stage must be 1, 2, 3, 4, 2h or g" >&2; exit 2 ;;
esac
exec zoo/train_parallel.sh "$SECONDS_PER_CALL" $RESUME
