"""PART on D: blocked steps heading home, in its own part, outside it (lent parts, the way back)."""
import numpy as np, sys
from patrolsb3.core.maps import load_map
from patrolsb3.evaluate import load_policy, run_episodes, evaluation_setup
from patrolsb3.summary import summarize
spec = load_map("D")
for strat in ["PART", "CYCLIC"]:
    for k in (2, 3, 5):
        spec_, cfg = evaluation_setup("D", k, 4, 1, 3000, ())
        pol = load_policy(strat, spec_, k, cfg)
        orig = pol.predict
        c = np.zeros(5)
        def predict(sim, state=None, episode_start=None, deterministic=True):
            prev = None if state is None else state["returning"].copy()
            a, m = orig(sim, state, episode_start, deterministic)
            act = sim.status == 0; st = m["blocked"] > 0; ret = m["returning"]
            own = np.zeros_like(act)
            if strat == "PART":
                K = sim.n_agents[:, None]; slot = np.arange(act.shape[1])[None]
                own = pol.part_cell[K, slot, sim.pos]
            c[0] += (st & ret).sum(); c[1] += (st & ~ret & own).sum(); c[2] += (st & ~ret & ~own).sum(); c[3] += act.sum(); c[4] += (act & ~ret & ~own).sum()
            return a, m
        pol.predict = predict
        s = summarize(run_episodes(pol, spec_, cfg, k, 4, seed=0), 1)
        print(strat, k, "AVG %.1f coll %.1f" % (s["avg_idleness"]["mean"], s["collisions"]["mean"]),
              "blocked: heading home %.3f, patrolling in own part %.3f, patrolling outside own part %.3f; share of steps patrolling outside own part %.3f" % tuple(c[[0,1,2,4]] / c[3]))
