#!/usr/bin/env bash
# Keep a stopped paper-setting run resumable from a fresh clone: copies the run folder of
# zoo/train_paper_setting.sh (OUT/stage<N>/<MAP>/<VARIANT>/seed<K>) into
# zoo/in_progress/stage<N>/<MAP>/<VARIANT>/seed<K> with its newest valid checkpoint only (the model
# WITH its optimizer state, and the VecNormalize statistics beside it), config.yml, command.txt and
# the CSV files; TensorBoard logs and older checkpoints stay behind. Run from the repository root:
#
#   zoo/snapshot_run.sh STAGE MAP VARIANT SEED     # e.g. zoo/snapshot_run.sh 2 C rl-msg 2
#
# Continue it on any machine with (then --resume cuts the CSV files back to the checkpoint):
#   mkdir -p runs/paper/stage2/C/rl-msg && cp -r zoo/in_progress/stage2/C/rl-msg/seed2 runs/paper/stage2/C/rl-msg/
#   RUNS="C:rl-msg:2" SET="ent_coef_message=0.01" zoo/train_paper_setting.sh 2 SECONDS --resume
set -euo pipefail
STAGE=${1:?usage: zoo/snapshot_run.sh STAGE MAP VARIANT SEED}
MAP=${2:?usage: zoo/snapshot_run.sh STAGE MAP VARIANT SEED}
VARIANT=${3:?usage: zoo/snapshot_run.sh STAGE MAP VARIANT SEED}
SEED=${4:?usage: zoo/snapshot_run.sh STAGE MAP VARIANT SEED}
OUT=${OUT:-runs/paper}
RUN="$OUT/stage$STAGE/$MAP/$VARIANT/seed$SEED"
DEST="zoo/in_progress/stage$STAGE/$MAP/$VARIANT/seed$SEED"
[ -d "$RUN" ] || { echo "snapshot_run.sh: $RUN: no such run folder" >&2; exit 2; }
python -c "
import sys
from patrolsb3.runs import RunFolder
try:
    print(RunFolder(sys.argv[1]).snapshot(sys.argv[2]))
except (FileNotFoundError, FileExistsError) as error:
    sys.exit(f'snapshot_run.sh: {error}')" "$RUN" "$DEST"
du -sh "$DEST"
