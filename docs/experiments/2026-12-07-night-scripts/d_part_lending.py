"""PART with and without the paper's lending of a swapping agent's part, maps D and A."""
import numpy as np
from patrolsb3.evaluate import load_policy, run_episodes, evaluation_setup
from patrolsb3.summary import summarize
for m in "DA":
  for lend in (True, False):
    for k in (1, 2, 3, 4, 5):
        spec_, cfg = evaluation_setup(m, k, 4, 1, 3000, ())
        pol = load_policy("PART", spec_, k, cfg)
        if not lend:
            pol.allowed_vertices = lambda sim, e, a, pol=pol: pol.parts[sim.n_agents[e], a]
        s = summarize(run_episodes(pol, spec_, cfg, k, 4, seed=0), 1)
        print(m, "lend" if lend else "no-lend", k, "AVG %.1f MAX %.1f coll %.1f BF %.2f" % (s["avg_idleness"]["mean"], s["max_idleness"]["mean"], s["collisions"]["mean"], s["battery_failure_rate"]["mean"] if "battery_failure_rate" in s else -1))
