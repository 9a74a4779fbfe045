#!/usr/bin/env bash
# Issue 43's recipe trial on map A (rl-msg, three training seeds a recipe), once its runs have
# finished, in the order the rule (docs/experiments/2026-12-07-afternoon.md, written before any
# result) demands. Run from the repository root, one step at a time:
#
#   zoo/recipe_trial.sh validate E1|E2   # as soon as one recipe's three runs have finished: validate
#                                 #   them (seed 7), keep their rule figures in RULE_JSON and a
#                                 #   snapshot of each finished run (model.zip, the checkpoint chosen,
#                                 #   E2's milestones) in zoo/in_progress/, so that the others can take
#                                 #   sessions more; nothing is chosen, exported or evaluated on seed 0
#   zoo/recipe_trial.sh choose    # validate E1's and E2's runs (seed 7), apply the rule: RULE_JSON
#   zoo/recipe_trial.sh shelve    # only after 'choose': E1 onto zoo/cd10/, E2 onto zoo/paper-recipe/,
#                                 #   each with its 24 h eval.json (seed 0), listening and ablation
#   zoo/recipe_trial.sh budget    # after 'shelve': E2's checkpoints at 16 M and 32 M agent-steps (1.6 M
#                                 #   and 3.2 M episode steps) evaluated like an entry (scratch zoo),
#                                 #   beside the full budget: zoo/comparison-recipes/budget.md
#   zoo/recipe_trial.sh compare   # E0, E1, E2 beside CR, PART, SEBS on A, and the claims of each
#
# E1: runs/e1/stage2/A/rl-msg/seed<k> (zoo/train_paper_setting.sh with env.c_d=10); E2:
# runs/e2/A/rl-msg/seed<k> (patrolsb3 sweep zoo/sweeps/paper-recipe-a.yml); E0: the zoo's
# A/rl-msg seeds. RULE_JSON (default zoo/comparison-recipes/recipe_rule.json) keeps every
# model's rule figures; it starts from E0's (2026-12-07-night-logs/recipe_rule_E0.json), so E0 is
# not played again. Each run's validation (`zoo validate --last 6`) is kept beside RULE_JSON
# (validate_<e1|e2>_seed<k>.txt, committed), so a run restored from its snapshot is not validated
# twice. Other logs go to runs/recipe_trial/.
set -euo pipefail
USAGE="usage: zoo/recipe_trial.sh validate E1|E2 | choose | shelve | budget | compare"
STEP=${1:?$USAGE}
SEEDS=(0 1 2)
E1_RUNS=runs/e1/stage2/A/rl-msg
E2_RUNS=runs/e2/A/rl-msg
E2_MILESTONES="16000000,32000000"      # E2's checkpoints at the zoo's budget and 3.2 M episode steps
LOG=runs/recipe_trial
RULE_JSON=${RULE_JSON:-zoo/comparison-recipes/recipe_rule.json}
VALIDATIONS=$(dirname "$RULE_JSON")
RULE=docs/experiments/2026-12-07-evening-scripts/recipe_rule.py

start_rule_json() {   # RULE_JSON begins with E0's figures (validation seed 7), computed once
  mkdir -p "$LOG" "$VALIDATIONS"
  [ -f "$RULE_JSON" ] || cp docs/experiments/2026-12-07-night-logs/recipe_rule_E0.json "$RULE_JSON"
}

finished() {   # every seed of a recipe has its model.zip
  local runs=$1 k
  for k in "${SEEDS[@]}"; do
    if [ ! -f "$runs/seed$k/model.zip" ]; then
      echo "recipe_trial.sh: $runs/seed$k has not finished (no model.zip); continue it first (zoo/in_progress/README.md)" >&2
      exit 2
    fi
  done
}

best_of() {    # the checkpoint 'zoo validate --last 6' chose for one run (validated once)
  local run=$1 tag=$2 record="$VALIDATIONS/validate_$2.txt"
  if ! grep -q '^best: ' "$record" 2>/dev/null; then
    patrolsb3 zoo validate "$run" --last 6 > "$record.partial" 2>&1
    mv "$record.partial" "$record"
  fi
  sed -n 's/^best: //p' "$record"
}

chosen() {     # the recipe the rule chose, from RULE_JSON; empty before 'choose'
  [ -f "$RULE_JSON" ] && python -c "import json, sys; print(json.load(open(sys.argv[1])).get('chosen', ''))" "$RULE_JSON"
}

case "$STEP" in
  validate)
    case "${2:-}" in
      E1) runs=$E1_RUNS; tag=e1; milestones="" ;;
      E2) runs=$E2_RUNS; tag=e2; milestones=$E2_MILESTONES ;;
      *) echo "recipe_trial.sh: validate takes E1 or E2, not '${2:-}' ($USAGE)" >&2; exit 2 ;;
    esac
    finished "$runs"
    start_rule_json
    models=()
    for k in "${SEEDS[@]}"; do
      models+=("$(best_of "$runs/seed$k" "${tag}_seed$k")")
    done
    python "$RULE" "$2=$(IFS=,; echo "${models[*]}")" --json "$RULE_JSON" | tee "$LOG/rule_$tag.txt"
    for k in "${SEEDS[@]}"; do    # the finished run, kept for 'shelve' and 'budget' on any machine
      python -c "
import sys
from patrolsb3.runs import RunFolder
milestones = [int(m) for m in sys.argv[4].split(',') if m]
print(RunFolder(sys.argv[1]).snapshot(sys.argv[2], chosen=sys.argv[3], milestones=milestones))" \
        "$runs/seed$k" "zoo/in_progress/${runs#runs/}/seed$k" "${models[$k]}" "$milestones"
    done
    echo "kept: zoo/in_progress/${runs#runs/}/seed{0,1,2} (restore with cp -r into $runs/), $RULE_JSON, $VALIDATIONS/validate_${tag}_seed*.txt"
    ;;
  choose)
    finished "$E1_RUNS"; finished "$E2_RUNS"
    start_rule_json
    e0=$(IFS=,; echo "${SEEDS[*]/#/zoo/A/rl-msg/seed}")
    e1=(); e2=()
    for k in "${SEEDS[@]}"; do
      e1+=("$(best_of "$E1_RUNS/seed$k" "e1_seed$k")")
      e2+=("$(best_of "$E2_RUNS/seed$k" "e2_seed$k")")
    done
    python "$RULE" "E0=$e0" \
      "E1=$(IFS=,; echo "${e1[*]}")" "E2=$(IFS=,; echo "${e2[*]}")" --json "$RULE_JSON" | tee "$LOG/rule.txt"
    ;;
  shelve)
    if [ -z "$(chosen)" ]; then
      echo "recipe_trial.sh: no choice in $RULE_JSON yet; run 'zoo/recipe_trial.sh choose' first (no seed-0 evaluation before the rule)" >&2
      exit 2
    fi
    for k in "${SEEDS[@]}"; do
      OUT=$LOG RUN="$E1_RUNS/seed$k" SHELF=cd10 CHECKPOINT="$(best_of "$E1_RUNS/seed$k" "e1_seed$k")" \
        zoo/finish_paper_run.sh A rl-msg "$k"
      OUT=$LOG RUN="$E2_RUNS/seed$k" SHELF=paper-recipe CHECKPOINT="$(best_of "$E2_RUNS/seed$k" "e2_seed$k")" \
        zoo/finish_paper_run.sh A rl-msg "$k"
    done
    patrolsb3 zoo choose A rl-msg --shelf cd10
    patrolsb3 zoo choose A rl-msg --shelf paper-recipe
    ;;
  budget)
    finished "$E2_RUNS"
    if [ -z "$(chosen)" ]; then
      echo "recipe_trial.sh: no choice in $RULE_JSON yet; run 'zoo/recipe_trial.sh choose' first (no seed-0 evaluation before the rule)" >&2
      exit 2
    fi
    for k in "${SEEDS[@]}"; do
      if [ ! -f "zoo/paper-recipe/A/rl-msg/seed$k/eval.json" ]; then
        echo "recipe_trial.sh: zoo/paper-recipe/A/rl-msg/seed$k/eval.json is missing (E2 at its full budget); run 'zoo/recipe_trial.sh shelve' first" >&2
        exit 2
      fi
      for steps in ${E2_MILESTONES//,/ }; do
        if [ ! -f "$E2_RUNS/seed$k/checkpoints/model_${steps}_steps.zip" ]; then
          echo "recipe_trial.sh: $E2_RUNS/seed$k/checkpoints/model_${steps}_steps.zip is missing (snapshots keep it as a milestone)" >&2
          exit 2
        fi
      done
    done
    mkdir -p "$LOG"
    rows=()
    for steps in ${E2_MILESTONES//,/ }; do
      for k in "${SEEDS[@]}"; do     # exported into a scratch zoo; its 24-h eval.json is kept
        patrolsb3 zoo export "$E2_RUNS/seed$k" --checkpoint "$E2_RUNS/seed$k/checkpoints/model_${steps}_steps.zip" \
          --shelf paper-recipe --zoo-dir "$LOG/budget-$steps" > "$LOG/budget_${steps}_seed$k.txt" 2>&1
        mkdir -p "$VALIDATIONS/budget/$steps/seed$k"
        cp "$LOG/budget-$steps/paper-recipe/A/rl-msg/seed$k/eval.json" "$VALIDATIONS/budget/$steps/seed$k/eval.json"
      done
      rows+=("$steps=$VALIDATIONS/budget/$steps")
    done
    python docs/experiments/2026-12-08-scripts/budget_table.py "${rows[@]}" 75000000=zoo/paper-recipe/A/rl-msg \
      --out "$VALIDATIONS/budget.md"
    echo "E2 at each budget: $VALIDATIONS/budget.md (the evaluations in $VALIDATIONS/budget/<steps>/seed<k>/eval.json)"
    ;;
  compare)
    if [ -z "$(chosen)" ]; then
      echo "recipe_trial.sh: no choice in $RULE_JSON yet; run 'zoo/recipe_trial.sh choose' first" >&2
      exit 2
    fi
    mkdir -p "$LOG"
    patrolsb3 compare --maps A --agents 1-5 --episodes 10 --steps 14400 --out zoo/comparison-recipes \
      --strategies CR,PART,SEBS,zoo:rl-msg,zoo:rl-msg:cd10,zoo:rl-msg:paper-recipe --no-progress \
      > "$LOG/compare.txt" 2>&1
    patrolsb3 claims zoo/comparison-recipes --json zoo/comparison-recipes/claims.json > zoo/comparison-recipes/claims.md
    for shelf in cd10 paper-recipe; do
      patrolsb3 claims zoo/comparison-recipes --shelf "$shelf" --json "zoo/comparison-recipes/claims-$shelf.json" \
        > "zoo/comparison-recipes/claims-$shelf.md"
    done
    echo "zoo/comparison-recipes: report.md, claims.md (E0), claims-cd10.md (E1), claims-paper-recipe.md (E2)"
    ;;
  *)
    echo "recipe_trial.sh: no step '$STEP' ($USAGE)" >&2
    exit 2
    ;;
esac
