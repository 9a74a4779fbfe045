"""Print the table of zoo/in_progress/README.md: one row per kept run, with how far it got and the
command that continues it from a fresh clone. Run from the repository root after
``zoo/snapshot_run.sh``:

    python zoo/in_progress_table.py > /tmp/table.md     # then paste it into the README

A stage-2 snapshot (a ``checkpoints/`` folder) is continued with ``--resume``; a finished
stage-1 run (a ``model.zip``) starts its stage 2. CPU hours come from the run's cpu_time.csv;
the hours left of a stage-2 run are estimated at its own pace so far (hosts differ), those of
a stage 2 not yet started at CPU_PER_AGENT_STEP.
"""
from __future__ import annotations

import csv
import shlex
import sys
from pathlib import Path

from patrolsb3.runs import RunFolder, model_steps

ROOT = Path("zoo/in_progress")
CPU_PER_AGENT_STEP = 1 / 1780   # CPU s per agent-step of one run beside another (zoo/README.md)


def _last_record(run: Path) -> tuple[int, float]:
    """(agent-steps, CPU hours) of the last row of the run's cpu_time.csv."""
    with open(run / "cpu_time.csv", newline="") as f:
        rows = list(csv.DictReader(f))                       # timesteps, cpu_seconds
    return (int(rows[-1]["timesteps"]), float(rows[-1]["cpu_seconds"]) / 3600) if rows else (0, 0.0)


def _asked(run: Path) -> tuple[int, str]:
    """The run's --timesteps and its SET= prefix (the --set overrides, as train_paper_setting.sh
    takes them), from command.txt."""
    words = shlex.split((run / "command.txt").read_text())
    timesteps = int(words[words.index("--timesteps") + 1])
    sets = []
    if "--set" in words:
        for word in words[words.index("--set") + 1:]:
            if word.startswith("--"):
                break
            sets.append(word)
    return timesteps, (f'SET="{" ".join(sets)}" ' if sets else "")


def row(run: Path) -> str:
    """One markdown row for the run folder ``run`` (zoo/in_progress/stage<N>/<map>/<variant>/seed<k>)."""
    stage, map_name, variant, seed = run.relative_to(ROOT).parts
    k = seed.removeprefix("seed")
    timesteps, set_prefix = _asked(run)
    name = f"{stage}/{map_name}/{variant}/{seed}"
    copy = (f"mkdir -p runs/paper/{stage}/{map_name}/{variant} && "
            f"cp -r zoo/in_progress/{name} runs/paper/{stage}/{map_name}/{variant}/")
    train = f'RUNS="{map_name}:{variant}:{k}" {set_prefix}zoo/train_paper_setting.sh'
    finish = f"`zoo/finish_paper_run.sh {map_name} {variant} {k}`"
    if (run / "checkpoints").is_dir():
        done = model_steps(RunFolder(run).newest_checkpoint())
        recorded_steps, hours = _last_record(run)
        # the run's own pace where it has one (hosts differ by 1.6x), else the zoo's typical one
        per_step = hours * 3600 / recorded_steps if recorded_steps else CPU_PER_AGENT_STEP
        left = (timesteps - done) * per_step / 3600
        where = (f"{stage[:5]} {stage[5:]} stopped at **{done:,} of {timesteps:,}** agent-steps "
                 f"({hours:.2f} CPU h so far), with its optimizer state")
        how = f"`{copy} && {train} 2 SECONDS --resume` (~{left:.1f} CPU h left), then {finish}"
    else:
        stage2 = 16_000_000 if variant != "rl-no-msg" else 8_000_000
        steps, hours = _last_record(run)
        where = (f"stage 1 finished ({steps:,} agent-steps, {hours:.2f} CPU h; policy only, "
                 f"which is all the start of stage 2 reads)")
        how = (f"`{copy} && {train} 2 SECONDS` (~{stage2 * CPU_PER_AGENT_STEP / 3600:.1f} CPU h), "
               f"then {finish}")
    return f"| `{name}` | {where} | {how} |"


def main() -> int:
    runs = sorted(p.parent for p in ROOT.glob("stage*/*/*/seed*/command.txt"))
    if not runs:
        print(f"{ROOT}: no kept runs", file=sys.stderr)
        return 1
    print("| run | where it stopped | continue with |")
    print("|---|---|---|")
    for run in sorted(runs, key=lambda p: (p.parts[-4] != "stage2", str(p))):
        print(row(run))
    return 0


if __name__ == "__main__":
    sys.exit(main())
