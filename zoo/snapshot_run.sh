#!/usr/bin/env bash
# Keep a stopped paper-setting run resumable from a fresh clone: copies the run folder of
# zoo/train_paper_setting.sh (OUT/stage<N>/<MAP>/<VARIANT>/seed<K>) into
# zoo/in_progress/stage<N>/<MAP>/<VARIANT>/seed<K> with its newest valid checkpoint only (the model
# WITH its optimizer state, and the VecNormalize statistics beside it), config.yml, command.txt and
# the CSV files; TensorBoard logs and older checkpoints stay behind. Run from the repository root:
#
#   zoo/snapshot_run.sh STAGE MAP VARIANT SEED     # e.g. zoo/snapshot_run.sh 2 C rl-msg 2
#
# KEEP: how many of the newest checkpoints to keep (default 1). A run stopped within about six
# checkpoints (3 M agent-steps) of its end keeps more (KEEP=6), so that zoo/finish_paper_run.sh,
# which validates the last six, still sees those written before the stop.
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
KEEP=${KEEP:-1}
RUN="$OUT/stage$STAGE/$MAP/$VARIANT/seed$SEED"
DEST="zoo/in_progress/stage$STAGE/$MAP/$VARIANT/seed$SEED"
[ -d "$RUN" ] || { echo "snapshot_run.sh: $RUN: no such run folder" >&2; exit 2; }
python -c "
import sys
from patrolsb3.runs import RunFolder
if not sys.argv[3].isdigit() or int(sys.argv[3]) < 1:
    sys.exit(f'snapshot_run.sh: KEEP={sys.argv[3]!r}: not a whole number of checkpoints >= 1')
try:
    print(RunFolder(sys.argv[1]).snapshot(sys.argv[2], keep=int(sys.argv[3])))
except (FileNotFoundError, FileExistsError) as error:
    sys.exit(f'snapshot_run.sh: {error}')" "$RUN" "$DEST" "$KEEP"
du -sh "$DEST"
