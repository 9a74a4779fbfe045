"""Evaluating a zoo entry into its ``eval.json`` (``patrolsb3 zoo eval``, ``zoo export``): every
team size 1..max_agents on the zoo's protocol, the figures ``compare`` then reuses."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..core.metrics import idleness_lower_bounds
from ..core.streams import STREAMS_VERSION
from ..evaluate import run_episodes, team_batch
from ..names import strategy_name
from ..outputs import write_json
from ..runs import ZooEntry
from ..summary import summarize
from .folders import shelf_of
from .policy import evaluation_config, load_entry


def write_zoo_eval(folder, episodes: int = 10, steps: int = 14400, seed: int = 0, tests: int = 1,
               progress: bool = True, deterministic: bool = True) -> Path:
    """Evaluate a zoo entry for 1..max_agents agents and write ``eval.json`` beside it.

    All team sizes run in one batch (episodes x tests per size) so the policy's forward passes
    are shared; each size's figures are summarised like ``patrolsb3.evaluate.evaluate`` does,
    so ``patrolsb3 compare`` can reuse them (:func:`cached_result`).

    Args:
        folder: the entry folder (``zoo/<map>/<variant>``).
        episodes: episodes per test and team size.
        steps: steps per episode (14,400 = the paper's 24 h).
        seed: simulator seed.
        tests: tests per team size.
        progress: progress bar.
        deterministic: most likely legal actions (True) or sampled ones (False).

    Returns:
        Path of eval.json: {"map", "strategy", "episodes", "tests", "steps", "seed", "deterministic",
        "results": [evaluate()-style dict per team size]}.
    """
    folder = Path(folder)
    policy = load_entry(folder)
    config = policy.info["config"]
    max_agents = policy.cfg.max_agents
    cfg = evaluation_config(policy, steps)
    per_size = episodes * tests
    team, ids = team_batch(range(1, max_agents + 1), per_size)              # (max_agents * per_size,) each
    per_episode = run_episodes(policy, policy.spec, cfg, team, len(team), seed=seed, progress=progress,
                               episode_ids=ids,
                               desc=f"zoo {config['map']}/{config['variant']} n=1..{max_agents}",
                               deterministic=deterministic)
    strategy = strategy_name(config["variant"], shelf_of(folder))
    results = []
    for n in range(1, max_agents + 1):
        rows = team == n
        part = {k: v[rows] for k, v in per_episode.items() if isinstance(v, np.ndarray)}
        results.append({"strategy": strategy, "map": config["map"], "n_agents": n, "episodes": episodes,
                        "tests": tests, "steps": steps, "seed": seed, "faults": [],
                        "deterministic": bool(deterministic), "env": cfg.to_dict(), "draws": STREAMS_VERSION,
                        "policy_settings": policy.env_settings(),
                        "summary": summarize(part, tests),
                        "bounds": idleness_lower_bounds(policy.spec.n_vertices, n, steps)})
    out = {"map": config["map"], "strategy": strategy, "episodes": episodes, "tests": tests,
           "steps": steps, "seed": seed, "deterministic": bool(deterministic), "draws": STREAMS_VERSION,
           "note": "all team sizes stepped in one batch; episode j of every size has id j (paired draws)",
           "results": results}
    return write_json(ZooEntry(folder).evaluation_file, out, indent=2)
