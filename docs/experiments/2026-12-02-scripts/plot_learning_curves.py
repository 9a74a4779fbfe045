"""Learning curves of the same seeded short run, old code vs new (mean over 5 rounds of 8 episodes)."""
import sys
import numpy as np
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

runs = {"old code (f7d08a1), 50 minibatches of ~205 rows": "/tmp/lc/old",
        "new code, batch_size 2048 (new default)": "/tmp/lc/new",
        "new code, n_minibatches=50": "/tmp/lc/new_nmb50"}
fig, axes = plt.subplots(1, 3, figsize=(15, 4))
rows = []
for label, root in runs.items():
    try:
        d = np.genfromtxt(f"{root}/A/rl-msg/MaskableRecurrentPPO_seed0/curve.csv", delimiter=",", names=True)
    except (FileNotFoundError, OSError):
        continue
    bins = np.arange(0, 1.2e6 + 1, 80_000)                     # 2 rounds of 8 episodes per bin
    which = np.digitize(d["timesteps"], bins)
    centres = [(bins[i - 1] + bins[i]) / 2 for i in range(1, len(bins)) if (which == i).any()]
    for ax, col in zip(axes, ("reward", "mean_idleness", "battery_failures")):
        per_bin = [d[col][which == i].mean() for i in range(1, len(bins)) if (which == i).any()]
        ax.plot(np.array(centres) / 1e6, per_bin, marker="o", ms=3, label=label)
        ax.set_xlabel("agent-steps (M)")
        ax.set_title(f"{col}: mean of the episodes ending in each 80k-step bin", fontsize=8)
    for lo, hi in ((0, 4e5), (4e5, 8e5), (8e5, 1.3e6)):
        sel = (d["timesteps"] > lo) & (d["timesteps"] <= hi)
        rows.append((label, f"{lo/1e6:.1f}-{hi/1e6:.1f} M", round(d["reward"][sel].mean(), 1),
                     round(d["mean_idleness"][sel].mean(), 1), round(d["battery_failures"][sel].mean(), 2),
                     int(sel.sum())))
axes[0].legend(fontsize=7)
fig.tight_layout()
fig.savefig(sys.argv[1], dpi=90)
for r in rows:
    print(" | ".join(str(x) for x in r))
