"""Apply issue 43's rule (docs/experiments/2026-12-07-afternoon.md, written before any result) to
candidate models of each recipe, on the validation seed only.

    python docs/experiments/2026-12-07-evening-scripts/recipe_rule.py \
        E0=zoo/A/rl-msg/seed0,zoo/A/rl-msg/seed1,zoo/A/rl-msg/seed2 \
        E1=PATH,PATH,PATH E2=PATH,PATH,PATH [--steps 14400] [--episodes 10] [--json FILE]

With ``--json FILE``, a model whose figures FILE already holds for the same episodes and steps is
not played again (E0's figures, computed once, serve when E1 and E2 come in), and FILE keeps the
figures of every model it held, named in this call or not: one recipe's figures can be added as
soon as its runs finish (``zoo/recipe_trial.sh validate E1``), the choice made when all are in.

Each PATH is a zoo entry folder or a checkpoint (``<run>/checkpoints/model_<k>_steps.zip``, the one
``zoo validate RUN --last 6`` picked). Every candidate plays ``--episodes`` greedy episodes per team
size 1-5 on simulator seed 7 (never the evaluation's 0), all team sizes in one batch with episode j
of every size paired. Per recipe, the mean over its seeds of:

- the battery failure rate with 3-5 agents (episodes with a failure / episodes) -- the gate, <= 0.05;
- collisions a day with 3-5 agents, over the episodes without a battery failure -- the primary;
- AVG^h over 1-5 agents -- the guard (no more than 5 % above the lowest qualified recipe's).

Ties: two recipes within 5 % of each other's collisions are tied, the cheaper wins (E0 = E1 < E2).
No qualifier: the zoo keeps E0. The figures decide nothing else; the 24-h evaluation on seed 0
comes after the choice.
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from patrolsb3 import zoo
from patrolsb3.evaluate import run_episodes, team_batch

COST = {"E0": 0, "E1": 0, "E2": 1}       # the rule's order of cost (E0 = E1 < E2)
VALIDATION_SEED = 7


def candidate_figures(path: Path, episodes: int, steps: int) -> dict:
    """The rule's three figures for one model, on the validation seed."""
    policy = zoo.load_checkpoint(path) if path.suffix == ".zip" else zoo.load_entry(path)
    cfg = zoo.evaluation_config(policy, steps)
    team, ids = team_batch(range(1, 6), episodes)                            # (5 * episodes,) each, paired
    out = run_episodes(policy, policy.spec, cfg, team, len(team), seed=VALIDATION_SEED, episode_ids=ids)
    big = team >= 3
    clean = big & ~out["failed"]
    day = 14400 / steps                                                      # collisions per 24 h
    return {"bf_rate_3_5": float(out["failed"][big].mean()),
            "collisions_3_5": float(out["collisions"][clean].mean() * day) if clean.any() else float("nan"),
            "avg_idleness_1_5": float(out["avg_idleness"].mean())}


def choose(recipes: dict) -> tuple[str, str]:
    """The rule: (chosen recipe, why)."""
    qualified = {r: f for r, f in recipes.items() if f["bf_rate_3_5"] <= 0.05}
    if not qualified:
        return "E0", "no recipe passes the gate (battery failure rate <= 0.05 with 3-5 agents): the zoo keeps E0"
    lowest_avg = min(f["avg_idleness_1_5"] for f in qualified.values())
    guarded = {r: f for r, f in qualified.items() if f["avg_idleness_1_5"] <= 1.05 * lowest_avg}
    best = min(guarded.values(), key=lambda f: f["collisions_3_5"])["collisions_3_5"]
    tied = [r for r, f in guarded.items() if f["collisions_3_5"] <= 1.05 * best]
    chosen = min(tied, key=lambda r: (COST.get(r, 9), r))
    return chosen, (f"qualified: {sorted(qualified)}; within 5 % of the lowest AVG^h: {sorted(guarded)}; "
                    f"fewest collisions (ties within 5 %): {sorted(tied)}; the cheapest of those: {chosen}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("recipes", nargs="+", metavar="NAME=PATH,PATH,...")
    parser.add_argument("--episodes", type=int, default=10)
    parser.add_argument("--steps", type=int, default=14400)
    parser.add_argument("--json", default=None)
    args = parser.parse_args()
    recipes, rows, seeds = {}, [], {}
    known = {}
    if args.json and Path(args.json).is_file():
        known = {(r["model"], r.get("episodes"), r.get("steps")): r for r in json.loads(Path(args.json).read_text())["seeds"]}
    kept_rows = dict(known)       # FILE keeps the figures of models not named in this call (E1's before E2's)
    figure_names = ("bf_rate_3_5", "collisions_3_5", "avg_idleness_1_5")
    for item in args.recipes:
        name, _, paths = item.partition("=")
        per_seed = []
        for path in paths.split(","):
            found = known.get((path, args.episodes, args.steps))
            figures = ({k: found[k] for k in figure_names} if found
                       else candidate_figures(Path(path), args.episodes, args.steps))
            per_seed.append(figures)
            rows.append({"recipe": name, "model": path, "episodes": args.episodes, "steps": args.steps, **figures})
            kept_rows[(path, args.episodes, args.steps)] = rows[-1]
            print(f"{name} {path}: " + ", ".join(f"{k} {v:.3f}" for k, v in figures.items()), flush=True)
        recipes[name] = {k: float(np.mean([f[k] for f in per_seed])) for k in per_seed[0]}
        seeds[name] = len(per_seed)
    if args.json:     # every model's figures kept at once, before the choice
        Path(args.json).write_text(json.dumps({"seeds": list(kept_rows.values())}, indent=2))
    for name, f in recipes.items():
        print(f"{name} (mean of {seeds[name]} seeds): " + ", ".join(f"{k} {v:.3f}" for k, v in f.items()))
    if len(recipes) < 2:      # figures of one recipe, kept for later: nothing to choose between yet
        print("one recipe given: its figures are kept; the rule chooses once E0, E1 and E2 are all in")
        return
    chosen, why = choose(recipes)
    print(f"chosen: {chosen} ({why})")
    if args.json:
        Path(args.json).write_text(json.dumps({"seeds": list(kept_rows.values()), "recipes": recipes,
                                               "chosen": chosen, "why": why},
                                              indent=2))


if __name__ == "__main__":
    main()
