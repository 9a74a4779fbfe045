"""Putting a training run into the zoo: ``patrolsb3 zoo export`` copies a run's policy (no
optimizer), config and records into an entry folder, built aside and swapped in whole."""
from __future__ import annotations

import datetime
import os
import shutil
from pathlib import Path

import yaml

from ..core.config import ENV_VERSION
from ..runs import RunFolder, ZooEntry, recorded_path, write_atomically
from ..names import GUARDED
from .folders import ZooError, checked_shelf, entry_dir


def export_destination(run_dir, zoo_dir=None, as_seed: bool = False, shelf: str = "") -> Path:
    """The entry folder :func:`export` writes a run into (its docstring says which).

    Raises:
        ZooError: the run folder has no config.yml, an unknown shelf, or a shelf that does not
            fit the run: a run behind the return guard goes to the shelf "guarded" and only
            there.
    """
    run = RunFolder(run_dir)
    if not run.config_file.is_file():
        raise ZooError(f"{run.path}: no config.yml; not a run folder of 'patrolsb3 train'")
    config = run.read_config()
    guard = bool((config.get("env") or {}).get("return_guard"))
    shelf = checked_shelf(shelf)
    if shelf and (shelf == GUARDED) != guard:
        raise ZooError(f"--shelf {shelf}: {run.path} was trained {'behind' if guard else 'without'} the return "
                       f"guard; {'its shelf is ' + repr(GUARDED) if guard else 'the shelf ' + repr(GUARDED) + ' holds only runs behind it'}")
    shelf = GUARDED if guard else shelf
    return entry_dir(config["map"], config["variant"], zoo_dir, shelf=shelf,
                     seed=config.get("seed", 0) if as_seed or not guard else None)


def export(run_dir, zoo_dir=None, budget: dict | None = None, checkpoint=None, as_seed: bool = False,
           into=None, shelf: str = "") -> Path:
    """Copy a training run into the zoo, keeping the policy only (no optimizer).

    Args:
        run_dir: a run folder of ``patrolsb3 train`` (model.zip, config.yml, command.txt,
            curve.csv, eval.csv). A run stopped before its end has no model.zip: its newest
            checkpoint is taken (and named in config.yml as ``source_model``).
        checkpoint: a specific checkpoint file of the run to export instead.
        zoo_dir: the zoo root (default: the repository's ``zoo/``).
        budget: extra facts about the training budget, stored in config.yml. Without
            ``cpu_hours`` in it, the CPU hours the run measured (``cpu_time.csv``, its
            warm-start stages included) are recorded, when every stage measured them.
        as_seed: for a run behind the return guard, write into the guarded entry's ``seed<k>``
            subfolder (k: the run's training seed) instead of its default folder. A run in the
            paper's setting always goes to ``zoo/<MAP>/<variant>/seed<k>/``.
        shelf: a recipe shelf (:data:`patrolsb3.names.SHELVES`, e.g. ``"paper-recipe"``) to write
            into, ``zoo/<shelf>/<MAP>/<variant>/seed<k>/``, instead of the main zoo.
        into: write into this folder instead (a staging folder: ``patrolsb3 zoo export`` builds
            the whole entry there, then swaps it in; :func:`replace_entry`).

    Returns:
        The entry folder: ``zoo/[<shelf>/]<MAP>/<variant>/seed<k>`` for a run in the paper's setting
        (no return guard), ``zoo/guarded/<MAP>/<variant>`` (or its ``seed<k>``) for a guarded one.

    Raises:
        ZooError: the run folder lacks a model or a config.
    """
    run = RunFolder(run_dir)
    run_dir = run.path
    if not run.config_file.is_file():
        raise ZooError(f"{run_dir}: no config.yml; not a run folder of 'patrolsb3 train'")
    source = Path(checkpoint) if checkpoint else run.newest_model()
    if source is None or not source.is_file():
        raise ZooError(f"{run_dir}: no model.zip and no checkpoint to export")
    config = run.read_config()
    from ..sb3.algorithms import get_algorithm  # torch and SB3: loaded when a model is
    from ..sb3.cpu_time import cpu_hours_of
    algo_class, _ = get_algorithm(config["algo"]).classes()
    model = algo_class.load(str(source), device="cpu")
    folder = Path(into) if into is not None else export_destination(run_dir, zoo_dir, as_seed, shelf)
    folder.mkdir(parents=True, exist_ok=True)
    write_atomically(ZooEntry(folder).model_file, lambda partial: model.policy.save(str(partial)))
    for name in (run.COMMAND, *run.RECORDS):
        if (run_dir / name).is_file():
            shutil.copyfile(run_dir / name, folder / name)
    config["env_version"] = config.get("versions", {}).get("env_version", ENV_VERSION)
    config["date"] = datetime.date.fromtimestamp(source.stat().st_mtime).isoformat()
    config["source_model"] = recorded_path(source)
    config["budget"] = {"timesteps": int(model.num_timesteps), **(budget or {})}
    if "cpu_hours" in config["budget"]:
        config["budget"]["cpu_hours_source"] = "given (--cpu-hours)"
    elif (measured := cpu_hours_of(source)) is not None:
        config["budget"]["cpu_hours"] = round(measured, 3)
        config["budget"]["cpu_hours_source"] = ("measured (this run's cpu_time.csv) + the cpu_hours "
                                                "its warm-start source recorded, if any")
    warm = (config.get("init_from") or {}).get("timesteps")
    if warm:  # a warm-started run: its budget includes the run it started from
        config["budget"]["timesteps_this_run"] = int(model.num_timesteps)
        config["budget"]["timesteps"] = int(model.num_timesteps) + int(warm)
    config["source_run"] = recorded_path(run_dir)
    text = yaml.safe_dump(config, sort_keys=False)
    write_atomically(ZooEntry(folder).config_file, lambda partial: partial.write_text(text))
    return folder


def replace_entry(staged: Path, entry: Path) -> None:
    """Put a complete staged entry in place of ``entry`` in one step: the old entry (its model and
    every figure of it: eval.json, listening.json, ablation files) is moved aside, the staged one
    renamed in, then the old one deleted; a new model never stands beside old figures."""
    staged, entry = Path(staged), Path(entry)
    old = entry.with_name(f".{entry.name}.old-{os.getpid()}")
    if entry.exists():
        entry.rename(old)
    staged.rename(entry)
    if old.exists():
        shutil.rmtree(old)
