# Usage: python target_differences.py MAP [ZOO_SEED]: the AVG^h and MAX^h targets on one map,
# as bootstrap intervals of the difference of means (zoo:rl-msg minus a heuristic), from
# zoo/comparison/results.json (heuristics) and zoo/MAP/rl-msg/seed<ZOO_SEED>/eval.json, or without
# ZOO_SEED the episodes of every trained seed pooled (patrolsb3.zoo.pooled_result, as compare does).
# Where rl-msg has episodes with a battery failure, the differences over all episodes follow.
# Added 2026-12-07: without ZOO_SEED, the battery failure rate of rl-msg minus that of every other
# learned variant the zoo has on MAP (the B target: "no worse than the best other learned variant").
# scipy.stats.bootstrap, percentile method, 10,000 resamples, random_state 0; run from the repo root.
import json, sys
import numpy as np
from scipy.stats import bootstrap

MAP = sys.argv[1]
SEED = sys.argv[2] if len(sys.argv) > 2 else None
heuristics = json.load(open("zoo/comparison/results.json"))
if SEED is not None:
    learned = json.load(open(f"zoo/{MAP}/rl-msg/seed{SEED}/eval.json"))["results"]
else:   # the 24 h protocol of zoo/comparison: 10 episodes x 14,400 steps, seed 0, greedy
    from patrolsb3 import zoo
    learned = [zoo.pooled_result(MAP, "rl-msg", n, 10, 14400, 0) for n in range(1, 6)]
    print("pooled training seeds:", learned[0]["training_seeds"])


def episodes(results, n, metric, strategy=None):
    for r in results:
        if r["n_agents"] == n and (strategy is None or (r["map"], r["strategy"]) == (MAP, strategy)):
            return np.asarray(r["summary"][metric]["episodes"], float)
    raise SystemExit(f"no result for {strategy or 'zoo:rl-msg'} n={n} on map {MAP}")


def difference(a, b, digits=1):
    ci = bootstrap((a, b), lambda x, y, axis: x.mean(axis) - y.mean(axis), vectorized=True,
                   random_state=0, method="percentile", n_resamples=10_000).confidence_interval
    return f"{a.mean() - b.mean():+.{digits}f} [{ci.low:+.{digits}f}, {ci.high:+.{digits}f}]"


# AVG^h and MAX^h count the episodes without a battery failure (the paper's tables); where
# rl-msg has failed episodes, the same differences over every episode follow (suffix "_all").
failures = any(sum(r["summary"]["clean_episodes"]) < r["episodes"] * r["tests"] for r in learned)
for suffix in ("", "_all") if failures else ("",):
    label = " (all episodes, failed ones included)" if suffix else ""
    for n in range(2, 6):
        print(f"n={n} AVG^h{label} rl-msg - CR:",
              difference(episodes(learned, n, "avg_idleness" + suffix),
                         episodes(heuristics, n, "avg_idleness" + suffix, "CR")))
    for n in range(3, 6):
        for h in ("CR", "PART", "SEBS"):
            print(f"n={n} MAX^h{label} rl-msg - {h}:",
                  difference(episodes(learned, n, "max_idleness" + suffix),
                             episodes(heuristics, n, "max_idleness" + suffix, h)))

if SEED is None:
    from patrolsb3 import zoo
    for other in ("rl-no-msg", "rl-intention"):
        if not zoo.seeds(MAP, other):
            continue
        theirs = [zoo.pooled_result(MAP, other, n, 10, 14400, 0) for n in range(1, 6)]
        for n in range(1, 6):
            mine, their = (episodes(r, n, "battery_failure_rate") for r in (learned, theirs))
            print(f"n={n} BF rate rl-msg - {other} (seeds {theirs[0]['training_seeds']}): "
                  f"{mine.mean():.2f} - {their.mean():.2f} = " +
                  (difference(mine, their, 2) if np.ptp(np.concatenate([mine, their])) > 0 else "+0.00 (no failure)"))
