# Usage: python battery_failures.py MAP SEED_OF_ENTRY [N_AGENTS] [EPISODES] [STEPS] [SIM_SEED]
# Why does a zoo rl-msg entry run out of battery? Runs the entry greedily (the 24 h protocol's
# env, simulator seed SIM_SEED, default 1: not the evaluation's seed 0) and, for every agent whose
# battery runs out, looks back over its last 300 steps: how far from the station it died, the
# last step at which it still had the battery to fly home (battery >= steps home x the highest
# drain 1.1), whether it was heading home after that (steps home falling), and how often its move
# was lost to a collision or to the wind in its last 100 steps, and how long it had flown below
# b_l (20 % of b_max: where the low-battery penalty starts). Added 2026-12-05 (evening): in its
# last 100 steps, how often it chose Stay, how often its move took it farther from the station,
# how often every move toward the station was masked (another agent on the cell: the mask, not a
# collision, stops it), and how many distinct cells it stood on. Run from the repository root.
import sys
import numpy as np
from patrolsb3 import zoo
from patrolsb3.core.masks import action_mask
from patrolsb3.core.state import reset_state
from patrolsb3.core.step import step

MAP, ENTRY_SEED = sys.argv[1], int(sys.argv[2])
N = int(sys.argv[3]) if len(sys.argv) > 3 else 5
EPISODES = int(sys.argv[4]) if len(sys.argv) > 4 else 4
STEPS = int(sys.argv[5]) if len(sys.argv) > 5 else 14400
SIM_SEED = int(sys.argv[6]) if len(sys.argv) > 6 else 1
LOOK = 300

policy = zoo.load(MAP, "rl-msg", seed=ENTRY_SEED)
spec, cfg = policy.spec, zoo.evaluation_config(policy, STEPS)
home = spec.steps_home                                        # (H*W,) steps to the station
sim = reset_state(spec, cfg, np.full(EPISODES, N), n_envs=EPISODES, seed=SIM_SEED)
E, A = sim.pos.shape
hist_home = np.zeros((LOOK, E, A), np.int64)                  # ring buffers over the last LOOK steps
hist_batt = np.zeros((LOOK, E, A))
hist_lost = np.zeros((LOOK, E, A), bool)                      # move lost: collided or pushed
hist_stay = np.zeros((LOOK, E, A), bool)                      # chose Stay
hist_cell = np.zeros((LOOK, E, A), np.int64)                  # cell after the step
hist_home_masked = np.zeros((LOOK, E, A), bool)               # every move toward home masked
toward = home[spec.neighbour] < home[:, None]                 # (H*W, 5) the move shortens the way home
memory, start = None, np.ones(E, bool)
deaths, swaps = [], 0
for t in range(STEPS):
    actions, memory = policy.predict(sim, state=memory, episode_start=start, deterministic=True)
    start[:] = False
    k = t % LOOK
    closer = toward[sim.pos]                                  # (E, A, 5)
    hist_home_masked[k] = closer.any(axis=2) & ~(closer & action_mask(spec, sim)).any(axis=2)
    hist_stay[k] = actions[..., 1] == 4
    info = step(spec, cfg, sim, actions[..., 1], messages=actions[..., 0], compute_reward=False)
    hist_home[k], hist_batt[k], hist_cell[k] = home[sim.pos], sim.battery, sim.pos
    hist_lost[k] = info.collided | info.pushed
    swaps += int(info.swap_started.sum())
    for e, a in zip(*np.nonzero(info.battery_failed)):
        order = [(t - j) % LOOK for j in range(min(LOOK, t + 1))][::-1]    # oldest .. newest
        h, b, lost = hist_home[order, e, a], hist_batt[order, e, a], hist_lost[order, e, a]
        safe = np.nonzero(b >= 1.1 * h)[0]
        last_safe = int(safe[-1]) if safe.size else -1
        after = h[last_safe:] if last_safe >= 0 else h
        deaths.append({"t": t, "episode": int(e), "steps_home_at_death": int(h[-1]),
                       "steps_since_last_safe": len(h) - 1 - last_safe if last_safe >= 0 else None,
                       "steps_home_at_last_safe": int(h[last_safe]) if last_safe >= 0 else None,
                       "closer_after_last_safe": int(after[0] - after.min()),
                       "moves_lost_last_100": int(lost[-100:].sum()),
                       "stay_last_100": int(hist_stay[order, e, a][-100:].sum()),
                       "away_last_100": int((np.diff(h[-101:]) > 0).sum()),
                       "home_masked_last_100": int(hist_home_masked[order, e, a][-100:].sum()),
                       "cells_last_100": len(set(hist_cell[order, e, a][-100:].tolist())),
                       "steps_below_b_l": int((b < cfg.b_low_frac * cfg.b_max).sum()),
                       "battery_pct_100_before": round(100 * float(b[-100]) / cfg.b_max, 1)
                       if len(b) >= 100 else None})
print(f"{MAP}/rl-msg seed {ENTRY_SEED}, {N} agents, {EPISODES} episodes x {STEPS} steps, "
      f"simulator seed {SIM_SEED}: {len(deaths)} battery failures, {swaps} swaps")
for d in deaths:
    print(d)
