"""fp32 against bf16, the same seeded runs side by side (issue 45): learning curves and
per-update statistics of runs/precision/<precision>/A/rl-msg/seed<k>.

    python docs/experiments/2026-12-07-afternoon-scripts/precision_compare.py [ROOT]

Prints, per run: the curve's reward, mean and max idleness over its last quarter of episodes
and in four quarters of training, and the mean of each SB3 update statistic (TensorBoard) over
the run and its second half; then each precision's mean and the seeds' spread.
"""
import csv
import statistics
import sys
from pathlib import Path

from tensorboard.backend.event_processing.event_accumulator import EventAccumulator

ROOT = Path(sys.argv[1] if len(sys.argv) > 1 else "runs/precision")
STATS = ("train/approx_kl", "train/clip_fraction", "train/entropy_loss", "train/explained_variance",
         "train/value_loss", "train/message_entropy_loss")


def curve(run: Path):
    with (run / "curve.csv").open() as f:
        rows = list(csv.DictReader(f))
    total = int(rows[-1]["timesteps"])
    quarters = []
    for q in range(4):
        part = [r for r in rows if q * total / 4 < int(r["timesteps"]) <= (q + 1) * total / 4]
        quarters.append(statistics.fmean(float(r["reward"]) for r in part) if part else float("nan"))
    last = rows[-len(rows) // 4:]
    return {"reward": statistics.fmean(float(r["reward"]) for r in last),
            "mean_idleness": statistics.fmean(float(r["mean_idleness"]) for r in last),
            "max_idleness": statistics.fmean(float(r["max_idleness"]) for r in last),
            "reward_quarters": quarters, "episodes": len(rows), "timesteps": total}


def update_stats(run: Path):
    events = EventAccumulator(str(run / "tb"), size_guidance={"scalars": 0})
    out = {}
    for folder in sorted((run / "tb").iterdir()):
        acc = EventAccumulator(str(folder), size_guidance={"scalars": 0}).Reload()
        for tag in STATS:
            if tag in acc.Tags()["scalars"]:
                values = [e.value for e in acc.Scalars(tag)]
                out[tag] = (statistics.fmean(values), statistics.fmean(values[len(values) // 2:]))
    del events
    return out


table = {}
for precision in ("fp32", "bf16"):
    for run in sorted((ROOT / precision / "A" / "rl-msg").glob("seed*")):
        table[(precision, run.name)] = {**curve(run), **update_stats(run)}

print("| precision | seed | episodes | reward Q1..Q4 | reward (last quarter) | AVG idleness | MAX idleness |"
      + "".join(f" {t.split('/')[1]} (all / 2nd half) |" for t in STATS))
print("|---" * (7 + len(STATS)) + "|")
for (precision, seed), r in table.items():
    quarters = " / ".join(f"{q:.1f}" for q in r["reward_quarters"])
    stats = "".join(f" {r[t][0]:.4g} / {r[t][1]:.4g} |" if t in r else " - |" for t in STATS)
    print(f"| {precision} | {seed} | {r['episodes']} | {quarters} | {r['reward']:.1f} | {r['mean_idleness']:.1f} "
          f"| {r['max_idleness']:.1f} |{stats}")
for precision in ("fp32", "bf16"):
    rows = [r for (p, _), r in table.items() if p == precision]
    if len(rows) < 2:
        continue
    parts = []
    for key in ("reward", "mean_idleness", "max_idleness"):
        values = [r[key] for r in rows]
        parts.append(f"{key} {statistics.fmean(values):.1f} (seeds {min(values):.1f}..{max(values):.1f})")
    for tag in STATS:
        values = [r[tag][1] for r in rows if tag in r]
        if values:
            parts.append(f"{tag.split('/')[1]} {statistics.fmean(values):.4g} ({min(values):.4g}..{max(values):.4g})")
    print(f"{precision}: " + "; ".join(parts))
