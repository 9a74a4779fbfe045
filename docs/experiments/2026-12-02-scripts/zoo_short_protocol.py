"""Evaluate every zoo entry on a short protocol and print one JSON line per entry (figures)."""
import json, sys, warnings
warnings.filterwarnings("ignore")
from patrolsb3.evaluate import evaluate
for m in "ABCD":
    for v in ("rl-msg", "rl-no-msg", "rl-intention"):
        r = evaluate(f"zoo:{v}", m, 3, episodes=2, steps=400, seed=0, progress=False)
        print(json.dumps({"entry": f"{m}/{v}", "summary": r["summary"]}, sort_keys=True), flush=True)
