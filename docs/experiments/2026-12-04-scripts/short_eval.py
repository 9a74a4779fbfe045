# Usage: python short_eval.py <repo root>: the figures of the three A zoo entries (3 agents, 2 x 400 steps)
# and of CR, PART and SEBS on B (4 agents, 4 x 4,000 steps: recharges, swaps, failures), one JSON line
# each; run with two clones and compare the files byte for byte.
import json, sys, warnings
sys.path.insert(0, sys.argv[1])
warnings.filterwarnings("ignore")
from patrolsb3.evaluate import evaluate
for s in ("zoo:rl-msg", "zoo:rl-no-msg", "zoo:rl-intention"):
    r = evaluate(s, "A", 3, episodes=2, steps=400, seed=0, progress=False)
    print(json.dumps({"s": s, "summary": r["summary"]}, sort_keys=True), flush=True)
for s in ("CR", "PART", "SEBS"):
    r = evaluate(s, "B", 4, episodes=4, steps=4000, seed=0, progress=False)
    print(json.dumps({"s": s, "summary": r["summary"]}, sort_keys=True), flush=True)
