"""Where CYCLIC and PART agents are blocked on map D: inside dead-end branches or elsewhere.

Usage: python d_blocked_where.py D CYCLIC,PART
"""
import sys
import numpy as np
from patrolsb3.core.maps import load_map, STAY
from patrolsb3.evaluate import load_policy, run_episodes, evaluation_setup
from patrolsb3.summary import summarize

def branches(spec):
    n = spec.kinds.size
    free = np.zeros(n, bool); free[spec.free_cells] = True
    nb = [set(int(c) for c, ok in zip(spec.neighbour[i, :4], spec.move_ok[i, :4]) if ok and c != i) for i in range(n)]
    alive = free.copy()
    deg = np.array([len(s) for s in nb])
    peeled = np.zeros(n, bool)
    changed = True
    while changed:
        changed = False
        for i in np.flatnonzero(alive):
            if sum(alive[j] for j in nb[i]) <= 1:
                alive[i] = False; peeled[i] = True; changed = True
    return peeled

spec = load_map(sys.argv[1] if len(sys.argv) > 1 else "D")
peeled = branches(spec)
H, W = spec.kinds.shape
print("\n".join("".join("#" if spec.kinds.flat[r*W+c] == 0 and spec.free_index[r*W+c] < 0 else ("b" if peeled[r*W+c] else ".") for c in range(W)) for r in range(H)))
for strat in sys.argv[2].split(","):
    for k in range(1, 6):
        spec_, cfg = evaluation_setup(spec.name, k, 4, 1, 3000, ())
        pol = load_policy(strat, spec_, k, cfg)
        orig = pol.predict
        counts = np.zeros(3)
        def predict(sim, state=None, episode_start=None, deterministic=True):
            a, m = orig(sim, state, episode_start, deterministic)
            act = sim.status == 0
            st = m["blocked"] > 0
            counts[0] += (st & peeled[sim.pos]).sum(); counts[1] += (st & ~peeled[sim.pos]).sum(); counts[2] += act.sum()
            return a, m
        pol.predict = predict
        res = run_episodes(pol, spec_, cfg, k, 4, seed=0)
        s = summarize(res, 1)
        print(strat, k, "AVG", round(s["avg_idleness"]["mean"], 1), "coll", round(s["collisions"]["mean"], 1),
              "blocked in branch %.3f elsewhere %.3f" % (counts[0] / counts[2], counts[1] / counts[2]))
