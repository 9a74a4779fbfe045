# Usage: python interleaved_pz_speed.py ROUNDS LABEL=ROOT [LABEL=ROOT ...]: pz_speed.py of each clone
# (2026-12-02-scripts), one subprocess per run, the clones interleaved round by round; medians.
import statistics, subprocess, sys
from pathlib import Path
SCRIPT = Path(__file__).resolve().parent.parent / "2026-12-02-scripts" / "pz_speed.py"
rounds, clones = int(sys.argv[1]), dict(a.split("=", 1) for a in sys.argv[2:])
runs = {label: [] for label in clones}
for _ in range(rounds):
    for label, root in clones.items():
        out = subprocess.run([sys.executable, str(SCRIPT), root, label], capture_output=True, text=True, check=True)
        runs[label].append(int(out.stdout.split()[1]))
for label, values in runs.items():
    print(label, statistics.median(values), values)
print("load average", open("/proc/loadavg").read().split()[:3])
