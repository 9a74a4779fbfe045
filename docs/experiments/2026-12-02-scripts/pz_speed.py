# Usage: python pz_speed.py <repo root> <label>: simulator steps/s of that clone's PettingZoo env, one
# episode of 3 agents, learned messages, map A (the harness of patrolsb3 bench env, copied here so
# that old code runs the same loop); median of 5 seeds x 1,000 simulator steps.
import sys, time, statistics, itertools, numpy as np
sys.path.insert(0, sys.argv[1])
from patrolsb3.env import parallel_env
def speed(n_agents=3, n_steps=1000, seed=0):
    env = parallel_env("A", n_agents=n_agents, seed=seed)
    obs, infos = env.reset(seed=seed)
    draws = itertools.cycle(np.random.default_rng(seed).random(4099).tolist())
    sim = 0
    start = time.perf_counter()
    while sim < n_steps:
        actions = {}
        for a in env.agents:
            lm, lv = (np.flatnonzero(m) for m in infos[a]["action_mask"])
            actions[a] = (int(lm[int(next(draws) * len(lm))]), int(lv[int(next(draws) * len(lv))]))
        phase = infos[env.agents[0]]["phase"]
        obs, r, te, tr, infos = env.step(actions)
        sim += phase in (1, "move")   # the old env named the phase
        if not env.agents:
            obs, infos = env.reset()
    return n_steps / (time.perf_counter() - start)
if __name__ == "__main__":
    if len(sys.argv) > 3:   # pz_speed.py ROOT LABEL N_STEPS: one run of N_STEPS (under callgrind)
        speed(n_steps=int(sys.argv[3]))
    else:
        print(sys.argv[2], round(statistics.median(speed(seed=s) for s in range(5))))
