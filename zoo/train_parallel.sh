#!/usr/bin/env bash
# Train the zoo runs side by side on a many-core machine, one process (one torch thread) per run,
# each stopped cleanly (SIGINT: it writes a checkpoint) after SECONDS; run it again with
# --resume to continue every run from its newest checkpoint. Run from the repository root.
#
#   zoo/train_parallel.sh SECONDS [--resume]
#
# ZOO_SET holds the hyperparameters every zoo run shares (applied to every variant alike, see
# zoo/README.md); ABLATIONS adds runs of A/rl-msg that change one thing of it, for the README's
# ablation table (ABLATIONS="" runs none). Logs go to runs/logs/, run folders to ZOO_OUT
# (default runs/zoo) and runs/ablation. INIT_FROM (optional, e.g.
# "runs/stage1/{map}/{variant}/MaskableRecurrentPPO_seed0") starts each new zoo run from the
# weights of that run ({map} and {variant} filled in; see zoo/train_stages.sh).
set -uo pipefail
SECONDS_PER_CALL=${1:?usage: zoo/train_parallel.sh SECONDS [--resume]}
RESUME=${2:-}
TIMESTEPS=${TIMESTEPS:-4000000}
ZOO_SET=${ZOO_SET:-"env.episode_steps=500 env.init_battery=[0.15,1.0] normalize_reward=true gamma=0.99 n_minibatches=4 learning_rate=drop_6e-4_3e-4"}
ZOO_RUNS=${ZOO_RUNS-"A:rl-msg A:rl-no-msg A:rl-intention B:rl-msg C:rl-msg D:rl-msg B:rl-no-msg C:rl-no-msg D:rl-no-msg B:rl-intention C:rl-intention D:rl-intention"}
# name|seed|settings replacing ZOO_SET (each a full set of overrides): a second seed of each
# variant on A, and the paper's settings with the same budget as a control
ABLATIONS=${ABLATIONS-"rl-msg-seed1|1|$ZOO_SET
rl-no-msg-seed1|1|$ZOO_SET
rl-intention-seed1|1|$ZOO_SET
rl-msg-paper-settings|0|env.episode_steps=1000"}
ZOO_OUT=${ZOO_OUT:-runs/zoo}
INIT_FROM=${INIT_FROM:-}
mkdir -p runs/logs

init_from() {  # out map variant -> "--init-from PATH" for a new zoo run when INIT_FROM is set
  if [ -n "$INIT_FROM" ] && [ -z "$RESUME" ] && [ "$1" = "$ZOO_OUT" ]; then
    local path=${INIT_FROM//\{map\}/$2}
    echo "--init-from ${path//\{variant\}/$3}"
  fi
}

launch() {  # out map variant run_id seed settings...
  local out=$1 map=$2 variant=$3 run_id=$4 seed=$5; shift 5
  nohup timeout -s INT "$SECONDS_PER_CALL" patrolsb3 train --map "$map" --variant "$variant" \
    --timesteps "$TIMESTEPS" --out "$out" --run-id "$run_id" --seed "$seed" $RESUME $(init_from "$out" "$map" "$variant") --no-progress \
    --checkpoint-freq "${CHECKPOINT_FREQ:-250000}" --eval-freq 0 --set $* \
    >> "runs/logs/${out##*/}_${map}_${variant}_${run_id}.log" 2>&1 &
}

for run in $ZOO_RUNS; do
  launch "$ZOO_OUT" "${run%%:*}" "${run#*:}" MaskableRecurrentPPO_seed0 0 $ZOO_SET
done
while IFS='|' read -r name seed settings; do
  variant=${name%%-seed1}; variant=${variant%%-paper-settings}
  [ -n "$name" ] && launch runs/ablation A "$variant" "$name" "$seed" $settings
done <<< "$ABLATIONS"
wait
tail -n 2 runs/logs/*.log
