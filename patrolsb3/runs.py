"""Run-folder files read the same way everywhere (config.yml, model zips).

A first piece of the run folder's one owner: ``sb3/train.py`` (resume), ``sb3/cpu_time.py``,
``zoo.py`` (entries, checkpoints) and ``checkpoints.py`` find checkpoints, read config files and
check model files through here, so none of them imports another for it.
"""
from __future__ import annotations

import json
import re
import zipfile
from pathlib import Path

import yaml

CHECKPOINT_RE = re.compile(r"model_(\d+)_steps\.zip$")
"""A checkpoint's file name: ``checkpoints/model_<agent-steps>_steps.zip`` (SB3's CheckpointCallback)."""


class ConfigError(ValueError):
    """A config.yml that cannot be read (not YAML, not a mapping)."""


CONFIG_SCHEMA = {"map": str, "map_source": str, "map_shape": list, "variant": str, "algo": str, "seed": int,
                 "timesteps": int, "env": dict, "hyperparams": dict, "versions": dict, "init_from": dict,
                 "env_version": str, "date": str, "source_model": str, "source_run": str, "budget": dict}
"""The keys a run's (or a zoo entry's) config.yml may hold, with their types: the train's own
(map .. versions, init_from for a warm start) and those ``zoo export`` adds."""


def read_config(path: Path) -> dict:
    """A config.yml as a dict, checked against :data:`CONFIG_SCHEMA`.

    Raises:
        ConfigError: not valid YAML, not a mapping, a key the schema does not know or a value of
            the wrong type (names the file and the problem).
    """
    try:
        config = yaml.safe_load(Path(path).read_text())
    except yaml.YAMLError as exc:
        raise ConfigError(f"{path}: not valid YAML ({str(exc).splitlines()[0]})") from None
    if config is None:
        return {}
    if not isinstance(config, dict):
        raise ConfigError(f"{path}: expected a mapping of settings, got {type(config).__name__}")
    unknown = sorted(set(config) - set(CONFIG_SCHEMA))
    if unknown:
        raise ConfigError(f"{path}: settings this code does not know: {unknown}")
    for key, kind in CONFIG_SCHEMA.items():
        if key in config and config[key] is not None and not isinstance(config[key], kind):
            raise ConfigError(f"{path}: {key} must be of type {kind.__name__}, got {config[key]!r}")
    return config


def zip_is_intact(path) -> bool:
    """True for a non-empty zip whose every member passes its CRC check (a model file)."""
    import zipfile
    path = Path(path)
    try:
        if path.stat().st_size == 0:
            return False
        with zipfile.ZipFile(path) as archive:
            return archive.testzip() is None
    except (OSError, zipfile.BadZipFile, EOFError):
        return False


def is_valid_model_file(path) -> bool:
    """True for a readable SB3 algorithm zip: intact (:func:`zip_is_intact`) with a ``data``
    record (a run killed while writing leaves an empty or cut file; flipped bytes fail the CRC)."""
    import zipfile
    if not zip_is_intact(path):
        return False
    with zipfile.ZipFile(path) as archive:
        return "data" in archive.namelist()


def trim_rows(path, timesteps: int) -> int:
    """Cut a run's CSV (curve.csv, eval.csv) back to the rows at or before ``timesteps`` (the
    checkpoint a resume starts from), dropping a cut last line; rewritten atomically. Returns the
    rows kept (0 when the file does not exist)."""
    import csv
    path = Path(path)
    if not path.is_file():
        return 0
    with path.open(newline="") as f:
        reader = csv.reader(f)
        header = next(reader, None)
        if header is None or "timesteps" not in header:
            return 0
        column = header.index("timesteps")
        kept = []
        for row in reader:
            try:
                if len(row) == len(header) and int(row[column]) <= timesteps:
                    kept.append(row)
            except ValueError:          # a line cut by a kill
                continue
    def write(partial: Path) -> None:
        with partial.open("w", newline="") as f:
            writer = csv.writer(f)
            writer.writerow(header)
            writer.writerows(kept)
    write_atomically(path, write)
    return len(kept)


def write_atomically(path, write) -> Path:
    """``write(partial_path)`` into a hidden ``.partial/`` folder beside ``path`` under the same
    file name (so writers that derive content from the name, like torch's zip archives, write
    the same bytes), then a rename over ``path``: a kill during the write leaves the old file
    (or none), never a cut one.

    Args:
        path: the file to (re)write.
        write: a function that writes the whole file at the path it is given.
    """
    import os
    path = Path(path)
    folder = path.parent / ".partial"
    folder.mkdir(parents=True, exist_ok=True)
    partial = folder / path.name
    write(partial)
    os.replace(partial, path)
    try:
        folder.rmdir()                  # left only while a write is under way (or was killed)
    except OSError:
        pass
    return path


def checkpoints_by_steps(run_dir) -> list[Path]:
    """The checkpoints ``run_dir/checkpoints/model_<steps>_steps.zip``, fewest steps first."""
    found = sorted((int(m.group(1)), p) for p in (Path(run_dir) / "checkpoints").glob("model_*_steps.zip")
                   if (m := CHECKPOINT_RE.search(p.name)))
    return [p for _, p in found]


def model_steps(model_path) -> int | None:
    """Agent-steps a model file was saved at: from a checkpoint's name
    (``model_<steps>_steps.zip``), else from the SB3 zip's own ``data`` record (a run's
    ``model.zip``); None when neither tells."""
    model_path = Path(model_path)
    if m := CHECKPOINT_RE.search(model_path.name):
        return int(m.group(1))
    try:
        with zipfile.ZipFile(model_path) as archive:
            return int(json.loads(archive.read("data"))["num_timesteps"])
    except (OSError, KeyError, ValueError, zipfile.BadZipFile):
        return None


def newest_checkpoint(run_dir: Path, skipped: list | None = None) -> Path | None:
    """The valid checkpoint of ``run_dir/checkpoints`` with the most timesteps, or None.

    Args:
        skipped: a list that receives the newer checkpoints passed over as invalid.
    """
    for path in reversed(checkpoints_by_steps(run_dir)):
        if is_valid_model_file(path):
            return path
        if skipped is not None:
            skipped.append(path)
    return None


def run_folder_of(model_path: Path) -> Path:
    """The run folder of a model file: ``<run>/checkpoints/model_<steps>_steps.zip`` or ``<run>/model.zip``."""
    model_path = Path(model_path)
    return model_path.parent.parent if model_path.parent.name == "checkpoints" else model_path.parent
