"""Output paths checked before any long work starts: a one-line error naming the argument and
the cause, instead of a traceback after the work is done."""
from __future__ import annotations

import os
from pathlib import Path


def _writable_ancestor(path: Path, argument: str) -> None:
    """The nearest existing ancestor of ``path`` must be a writable folder (the rest is created)."""
    for parent in path.parents:
        if parent.exists():
            if not parent.is_dir():
                raise ValueError(f"{argument} {path}: {parent} is a file, not a folder")
            if not os.access(parent, os.W_OK):
                raise ValueError(f"{argument} {path}: {parent} is not writable")
            return


def check_output_file(path, argument: str) -> Path:
    """A file the command will write: not a folder, writable, under a folder that is or can be made.

    Raises:
        ValueError: names ``argument`` (e.g. "--json") and the cause.
    """
    path = Path(path)
    if path.is_dir():
        raise ValueError(f"{argument} {path}: is a folder; give a file name")
    if path.exists() and not os.access(path, os.W_OK):
        raise ValueError(f"{argument} {path}: the file is not writable")
    _writable_ancestor(path, argument)
    return path


def check_output_dir(path, argument: str) -> Path:
    """A folder the command will write into: not a file, writable or creatable.

    Raises:
        ValueError: names ``argument`` (e.g. "--out") and the cause.
    """
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise ValueError(f"{argument} {path}: is a file, not a folder")
    if path.is_dir() and not os.access(path, os.W_OK):
        raise ValueError(f"{argument} {path}: the folder is not writable")
    _writable_ancestor(path, argument)
    return path


def strict_json(value):
    """``value`` with every non-finite float replaced by None, so that ``json.dumps(...,
    allow_nan=False)`` writes standard JSON (no literal NaN, which strict parsers reject)."""
    import math
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {k: strict_json(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [strict_json(v) for v in value]
    return value
