#!/usr/bin/env bash
# Turn a finished stage-2 run of zoo/train_paper_setting.sh into a zoo entry: validate its last
# six checkpoints (seed 7, never the evaluation's seed 0), export the best one (writes
# zoo/<MAP>/<variant>/seed<k> with its 24 h eval.json), and for rl-msg measure what the
# messages carry (listening.json; ablation.md / ablation.json). Run from the repository root:
#
#   zoo/finish_paper_run.sh MAP VARIANT SEED      # e.g. zoo/finish_paper_run.sh A rl-msg 2
#
# OUT: root of the run folders (default runs/paper). What validate, export, listening and
# ablation print besides their results goes to OUT/logs/. Afterwards: `patrolsb3 zoo choose MAP VARIANT` when the variant has several seeds,
# then compare / claims and the cards (zoo/README.md, "How the entries are made").
# RUN: the run folder, when it is not OUT/stage2/MAP/VARIANT/seedSEED (a sweep's trial);
# CHECKPOINT: the checkpoint to export, already chosen by validation (skips it);
# SHELF: a shelf of the zoo to export onto (zoo/SHELF/MAP/VARIANT/seedSEED; docs/zoo.md).
set -euo pipefail
MAP=${1:?usage: zoo/finish_paper_run.sh MAP VARIANT SEED}
VARIANT=${2:?usage: zoo/finish_paper_run.sh MAP VARIANT SEED}
SEED=${3:?usage: zoo/finish_paper_run.sh MAP VARIANT SEED}
OUT=${OUT:-runs/paper}
RUN=${RUN:-"$OUT/stage2/$MAP/$VARIANT/seed$SEED"}
SHELF=${SHELF:-}
LOG="$OUT/logs"
shelf=(); [ -n "$SHELF" ] && shelf=(--shelf "$SHELF")
if [ ! -f "$RUN/model.zip" ]; then
  echo "finish_paper_run.sh: $RUN has no model.zip: the run has not finished (continue it with zoo/train_paper_setting.sh 2 SECONDS --resume)" >&2
  exit 2
fi
mkdir -p "$LOG"
tag="${SHELF:+${SHELF}_}${MAP}_${VARIANT}_seed${SEED}"
if [ -n "${CHECKPOINT:-}" ]; then
  best=$CHECKPOINT
else
  patrolsb3 zoo validate "$RUN" --last 6 > "$LOG/validate_$tag.txt" 2>&1
  best=$(sed -n 's/^best: //p' "$LOG/validate_$tag.txt")
fi
if [ -z "$best" ]; then
  echo "finish_paper_run.sh: zoo validate chose no checkpoint; see $LOG/validate_$tag.txt" >&2
  exit 1
fi
echo "validation chose $best"
patrolsb3 zoo export "$RUN" --checkpoint "$best" "${shelf[@]}" > "$LOG/export_$tag.txt" 2>&1
entry="zoo/${SHELF:+$SHELF/}$MAP/$VARIANT/seed$SEED"
echo "exported $entry"
if [ "$VARIANT" = rl-msg ]; then
  patrolsb3 zoo listening "$MAP" rl-msg --seed-of-entry "$SEED" "${shelf[@]}" > "$entry/listening.json" 2> "$LOG/listening_$tag.txt"
  patrolsb3 zoo ablation "$MAP" rl-msg --seed-of-entry "$SEED" "${shelf[@]}" --episodes 8 --steps 1000 \
    --json "$entry/ablation.json" > "$entry/ablation.md" 2> "$LOG/ablation_$tag.txt"
  echo "wrote $entry/listening.json and $entry/ablation.md"
fi
