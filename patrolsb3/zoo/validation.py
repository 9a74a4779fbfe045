"""Choosing by validation: a run's checkpoint (``patrolsb3 zoo validate``) and an entry's default
seed (``patrolsb3 zoo choose``), each by a short greedy evaluation on the validation seed.

PPO's last checkpoint is not always its best: in our staged training the recharge learned in
one stage can be lost again in the next while the training curve (sampled actions) still looks
fine. Every checkpoint of a run is therefore evaluated greedily on a short protocol with its own
seed (not the zoo's evaluation seed 0, so the choice does not peek at the reported figures) and
ranked: fewest battery failures first, then the lowest AVG^h.
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import yaml

from ..evaluate import run_episodes, team_batch
from ..names import GUARDED
from ..runs import RunFolder, is_valid_model_file, model_steps, write_atomically
from .folders import DEFAULT_FILE, ZooError, seeds, variant_folder
from .policy import evaluation_config, load_checkpoint, load_entry


def run_checkpoints(run_dir) -> list[Path]:
    """Every valid ``checkpoints/model_<steps>_steps.zip`` of a run, by steps, then ``model.zip``
    unless a checkpoint already holds its steps (a finished run saves both); empty, cut or
    corrupt checkpoints are named on stderr and left out.

    Raises:
        FileNotFoundError: a folder with no checkpoint and no model.zip.
    """
    run = RunFolder(run_dir)
    paths = []
    for path in run.checkpoints():
        if is_valid_model_file(path):
            paths.append(path)
        else:
            print(f"skipped {path} (empty, cut or corrupt)", file=sys.stderr)
    if run.model_file.is_file() and model_steps(run.model_file) not in map(model_steps, paths):
        paths.append(run.model_file)
    if not paths:
        raise FileNotFoundError(f"{run_dir}: no checkpoints/model_<steps>_steps.zip and no model.zip; "
                                f"not a run folder of 'patrolsb3 train'")
    return paths


def validate(path, team_sizes=(1, 3, 5), episodes: int = 4, steps: int = 3000, seed: int = 7) -> dict:
    """Greedy episodes of one checkpoint in the evaluation's env (batteries start at 90-100 %).

    Args:
        path: a checkpoint of ``patrolsb3 train`` (see :func:`patrolsb3.zoo.load_checkpoint`).
        team_sizes: team sizes to run, ``episodes`` episodes each, all in one batch.
        episodes: episodes per team size.
        steps: steps per episode (3,000 = 5 h: about five batteries per agent).
        seed: simulator seed.

    Returns:
        {"checkpoint", "timesteps", "failures" (battery failures per episode, mean over every
        episode), "bf_rate" (share of episodes with one), "avg_idleness" (AVG^h over every
        episode, failed ones included), "swap_battery" (mean battery fraction at a swap)}.
    """
    policy = load_checkpoint(path)
    return {"checkpoint": str(path), "timesteps": policy.info["timesteps"],
            **validate_policy(policy, team_sizes, episodes, steps, seed)}


def validate_policy(policy, team_sizes=(1, 3, 5), episodes: int = 4, steps: int = 3000, seed: int = 7) -> dict:
    """The figures of :func:`validate` for a loaded :class:`~patrolsb3.zoo.ZooPolicy` (a
    checkpoint or a zoo entry): {"failures", "bf_rate", "avg_idleness", "swap_battery"}."""
    cfg = evaluation_config(policy, steps)
    team, ids = team_batch(team_sizes, episodes)                                # (E,) each, paired across sizes
    result = run_episodes(policy, policy.spec, cfg, team, len(team), seed=seed, deterministic=True,
                          episode_ids=ids)
    swap = result["swap_battery"]
    return {"failures": float(result["battery_failures"].mean()), "bf_rate": float(result["failed"].mean()),
            "avg_idleness": float(result["avg_idleness"].mean()),
            "swap_battery": float(np.nanmean(swap)) if np.isfinite(swap).any() else float("nan")}


def rank(rows: list[dict]) -> list[dict]:
    """Best first: fewest battery failures per episode, then the lowest AVG^h."""
    return sorted(rows, key=lambda r: (round(r["failures"], 6), r["avg_idleness"]))


def choose_default(map_name: str, variant: str, zoo_dir=None, team_sizes=(1, 3, 5), episodes: int = 4,
                   steps: int = 3000, seed: int = 7, shelf: str = "") -> dict:
    """Pick the entry's default seed (the main zoo's, or a recipe ``shelf``'s) by validation and
    write its ``default.yml``.

    Each seed's model plays the greedy validation protocol of ``zoo validate`` (its own
    simulator seed, not the evaluation's 0, so the choice does not peek at the reported
    figures); the best by :func:`patrolsb3.zoo.validation.rank` (fewest battery failures, then
    the lowest AVG^h) becomes the default.

    Returns:
        What was written: {"seed", "chosen_by", "validation": [one row per seed]}.

    Raises:
        ZooError: the entry has no seed, or the shelf is "guarded" (one entry folder, no default
            to choose).
    """
    if shelf == GUARDED:
        raise ZooError(f"--shelf {GUARDED}: the entries behind the return guard have one default folder each; "
                       f"there is no seed to choose")
    folder = variant_folder(map_name, variant, zoo_dir, shelf)
    have = seeds(map_name, variant, zoo_dir, shelf)
    if not have:
        raise ZooError(f"{folder}: no seed<k>/model.zip to choose from")
    rows = [{"seed": k, **validate_policy(load_entry(folder / f"seed{k}"), team_sizes, episodes, steps, seed)}
            for k in have]
    best = rank(rows)[0]
    chosen = {"seed": best["seed"],
              "chosen_by": (f"zoo choose: greedy validation (simulator seed {seed}, {episodes} episodes x "
                            f"{steps} steps for n = {','.join(map(str, team_sizes))}): fewest battery "
                            f"failures, then the lowest AVG^h"),
              "validation": [{k: (round(v, 4) if isinstance(v, float) else v) for k, v in r.items()} for r in rows]}
    text = yaml.safe_dump(chosen, sort_keys=False)
    write_atomically(folder / DEFAULT_FILE, lambda partial: partial.write_text(text))
    return chosen
