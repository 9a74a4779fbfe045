"""Named training recipes: hyperparameter overrides applied on top of the YAML's (``patrolsb3
train --recipe NAME``; ``--set`` applies on top of the recipe).

* ``default``: the YAML's values (the paper's, with a 256-step rollout of 2,048-row
  minibatches so that short runs update often).
* ``paper``: the paper's training as written (docs/training.md, "The paper's recipe"): every
  value of its tables, and its rollout: each update collects one whole training episode of the
  8 parallel episodes (``n_steps: episode``, 5,000 simulator steps) and splits it into 50
  minibatches. Its budget, 1,500 training episodes, is the run's ``timesteps``: 7.5 M episode
  steps = 937,500 steps of the 8 episodes = 937,500 x 40 rows x phases agent-steps (75 M for
  rl-msg and rl-intention, 37.5 M for rl-no-msg); the curriculum and the learning-rate drop
  fall at the paper's episodes when the run has that budget.

The paper-setting zoo trains in two stages (``zoo/train_paper_setting.sh`` runs them):

* ``zoo-stage1``: the patrol with the battery out of the way: 300-step episodes, full batteries.
* ``zoo-stage2``: the recharge, unshielded, from the stage-1 weights (``--init-from``):
  1,500-step episodes from 15-100 % batteries, half of every batch (parallel episodes 0, 2, 4,
  6) a 400-step drill from 5-40 %, and the home shaping ``c_home=50``. These are training aids:
  none acts at evaluation (the paper's env), and every variant gets them alike.

Both share the zoo's settings (OURS, each a documented switch): reward normalisation, gamma
0.99 per simulator step, 2,048-row minibatches, the local idleness in the actor's vector, the
difference reward weighted 200, and legible messages (``message_encoding=planes``).
"""
from __future__ import annotations

import copy
from pathlib import Path
from typing import Any

from ..core.maps import load_map
from ..runs import RunFolder, model_steps
from .hyperparams import merge
from .train import resolve_settings, train

SHARED = {"normalize_reward": True, "gamma": 0.99, "batch_size": 2048,
          "env": {"local_idleness": True, "c_d": 200.0, "message_encoding": "planes"}}

PAPER = {"n_steps": "episode", "n_minibatches": 50}
"""The paper's rollout over the YAML's values (which are the paper's for everything else)."""

PAPER_EPISODES = 1500
"""Training episodes of the paper's budget (its section "Model Training")."""

RECIPES = {
    "default": {},
    "paper": PAPER,
    "zoo-stage1": {**SHARED, "learning_rate": "drop_6e-4_3e-4",
                   "env": {**SHARED["env"], "episode_steps": 300, "init_battery": [1.0, 1.0]}},
    "zoo-stage2": {**SHARED, "learning_rate": 3e-4, "curriculum": False,
                   "env": {**SHARED["env"], "episode_steps": 1500, "init_battery": [0.15, 1.0], "c_home": 50.0},
                   "mix": {"episodes": [0, 2, 4, 6], "env": {"episode_steps": 400, "init_battery": [0.05, 0.4]}}},
}
"""Recipe name -> hyperparameter overrides ("default": the YAML's values)."""


def paper_budget(phases_per_step: int, max_agents: int = 5, episode_steps: int = 5000,
                 episodes: int = PAPER_EPISODES) -> int:
    """Agent-steps (``--timesteps``) of the paper's budget: ``episodes`` training episodes of
    ``episode_steps``, counted one per parallel episode (our reading; docs/training.md), each
    step of which is ``max_agents`` rows (slots) x ``phases_per_step`` env steps.

    >>> paper_budget(2)      # rl-msg, rl-intention: 937,500 steps of the 8 episodes
    75000000
    """
    return episodes * episode_steps * max_agents * phases_per_step


def recipe(name: str) -> dict:
    """The overrides of a recipe (a fresh copy).

    Raises:
        ValueError: an unknown name (the message lists the known ones).
    """
    if name not in RECIPES:
        raise ValueError(f"unknown recipe {name!r}; known: {', '.join(RECIPES)}")
    return copy.deepcopy(RECIPES[name])


STAGE1_SHARE = 0.2
"""Share of a two-stage run's agent-steps spent in stage 1 (the zoo's runs: 2 M of 10 M)."""


def train_in_stages(map="A", variant: str = "rl-msg", timesteps: int = 10_000_000, seed: int = 0,
                    out="runs/", run_id: str | None = None, resume: bool = False,
                    overrides: dict | None = None, say=None, **train_kwargs: Any) -> Path:
    """The zoo's recipe in one call: ``zoo-stage1`` for a fifth of ``timesteps``, then
    ``zoo-stage2`` from its weights for the rest.

    Run folders: ``<out>/stage1/<map>/<variant>/<run_id>`` and ``.../stage2/...`` (run_id
    default ``seed<seed>``). With ``resume``, a finished stage 1 is skipped and whichever stage is
    unfinished continues from its newest checkpoint.

    Args:
        timesteps: agent-steps of both stages together.
        overrides: hyperparameters applied on top of each stage's recipe (``--set``).
        say (Callable[[str], None] | None): receives a line naming each stage before it starts (default: stderr).
        **train_kwargs (Any): passed to :func:`patrolsb3.sb3.train.train` (progress_bar, device ...).

    Returns:
        Path: the stage-2 run folder.
    """
    import sys

    say = say or (lambda line: print(line, file=sys.stderr, flush=True))
    run_id = run_id or f"seed{seed}"
    first = max(1, round(int(timesteps) * STAGE1_SHARE))
    stages = []
    for stage in (1, 2):
        folder = Path(out) / f"stage{stage}"
        hp = merge(recipe(f"zoo-stage{stage}"), overrides or {})
        stages.append((folder, hp))
    (out1, hp1), (out2, hp2) = stages
    for hp, steps in ((hp1, first), (hp2, int(timesteps))):     # both stages' settings, before any work
        resolve_settings(map, variant, merge(hp, {"timesteps": steps}))
    name = load_map(map).name
    run1, run2 = out1 / name / variant / run_id, out2 / name / variant / run_id
    model1 = RunFolder(run1).model_file
    stage1_done = model1.is_file() and (model_steps(model1) or 0) >= first
    if not stage1_done:
        say(f"stage 1 of 2 (zoo-stage1: the patrol, full batteries): {first:,} agent-steps into {run1}")
        train(map=map, variant=variant, timesteps=first, seed=seed, out=out1, run_id=run_id,
              resume=resume and run1.exists(), hyperparams=hp1, **train_kwargs)
    resume2 = resume and run2.exists()
    say(f"stage 2 of 2 (zoo-stage2: the recharge, from stage 1's weights): up to {int(timesteps):,} agent-steps "
        f"into {run2}")
    return train(map=map, variant=variant, timesteps=int(timesteps), seed=seed, out=out2, run_id=run_id,
                 resume=resume2, init_from=None if resume2 else run1, hyperparams=hp2, **train_kwargs)
