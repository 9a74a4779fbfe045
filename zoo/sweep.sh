#!/usr/bin/env bash
# The settings sweep that chose the zoo's shared training settings: A/rl-msg trained side by
# side (one process and one torch thread per setting, 16 processes on a 16-core machine), each
# stopped cleanly after SECONDS. Compare the runs with
#   python -c "import glob; from patrolsb3.report import curve_table; \
#     print(curve_table({p.split('/')[-2]: p for p in sorted(glob.glob('runs/sweep/A/rl-msg/*/curve.csv'))}))"
# Run from the repository root:  zoo/sweep.sh SECONDS
set -uo pipefail
SECONDS_PER_RUN=${1:?usage: zoo/sweep.sh SECONDS}
WIDE="env.episode_steps=500 env.init_battery=[0.15,1.0]"
BASE="$WIDE normalize_reward=true gamma=0.99 n_minibatches=10"
# name|overrides (each a full set)
SWEEP="paper|env.episode_steps=1000
paper-wide|$WIDE
base|$BASE
base-gamma0.95|$BASE gamma=0.95
base-no-norm|$WIDE gamma=0.99 n_minibatches=10
base-lr6e-4|$BASE learning_rate=drop_6e-4_3e-4
base-lr1e-3|$BASE learning_rate=drop_1e-3_5e-4
base-epochs6|$BASE n_epochs=6
base-ent0.01|$BASE ent_coef=0.01
base-envs16|$BASE n_envs=16
base-ep1000|$BASE env.episode_steps=1000
base-mb4|$BASE n_minibatches=4
base-no-curriculum|$BASE curriculum=false
base-maskableppo|$BASE algo=MaskablePPO
base-small-net|$BASE policy_kwargs.dense_sizes=[256,128] policy_kwargs.lstm_hidden_size=64
base-seed1|$BASE"
mkdir -p runs/logs
while IFS='|' read -r name settings; do
  seed=0; [ "${name##*-}" = seed1 ] && seed=1
  nohup timeout -s INT "$SECONDS_PER_RUN" patrolsb3 train --map A --variant rl-msg --timesteps 4000000 \
    --out runs/sweep --run-id "$name" --seed "$seed" --no-progress --checkpoint-freq 100000000 \
    --eval-freq 0 --set $settings > "runs/logs/sweep_$name.log" 2>&1 &
done <<< "$SWEEP"
wait
