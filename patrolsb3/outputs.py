"""Outputs: paths checked before any long work starts (a one-line error naming the argument and
the cause, instead of a traceback after the work is done), and result files written as
standard JSON.

JSON results (``results.json`` of a comparison, a zoo entry's ``eval.json``, ``evaluate
--json``) are strict JSON: a figure that does not exist (the swap battery level of a run with
no swap, a mean over no clean episode) is NaN in memory and ``null`` on disk, written by
:func:`write_json` and read back as NaN by :func:`read_results`.
"""
from __future__ import annotations

import os
from pathlib import Path

from .runs import ComparisonFolder, RunFolder, ZooEntry, write_atomically
from .stats import RATE_METRICS, rate_interval


def _writable_ancestor(path: Path, argument: str) -> None:
    """The nearest existing ancestor of ``path`` must be a writable folder (the rest is created)."""
    for parent in path.parents:
        if parent.exists():
            if not parent.is_dir():
                raise ValueError(f"{argument} {path}: {parent} is a file, not a folder")
            if not os.access(parent, os.W_OK):
                raise ValueError(f"{argument} {path}: {parent} is not writable")
            return


def check_output_file(path, argument: str, inputs=()) -> Path:
    """A file the command will write: not a folder, writable, under a folder that is or can be
    made, and none of the command's ``inputs`` (files, or folders whose files it reads).

    Raises:
        ValueError: names ``argument`` (e.g. "--json") and the cause.
    """
    path = Path(path)
    for given in inputs:
        given = Path(given)
        if path.resolve() == given.resolve() or (given.is_dir() and path.resolve().parent == given.resolve()
                                                 and path.name in INPUT_NAMES):
            raise ValueError(f"{argument} {path}: is an input of this command; give another file name")
    if path.is_dir():
        raise ValueError(f"{argument} {path}: is a folder; give a file name")
    if path.exists() and not os.access(path, os.W_OK):
        raise ValueError(f"{argument} {path}: the file is not writable")
    _writable_ancestor(path, argument)
    return path


INPUT_NAMES = (ComparisonFolder.RESULTS_CSV, ComparisonFolder.EPISODES_CSV, ComparisonFolder.RESULTS_JSON,
               ZooEntry.EVALUATION, RunFolder.CONFIG, RunFolder.CURVE)
"""Files a command reads out of the folder it is given (a comparison folder, a run or an entry)."""


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


def write_json(path, value, indent: int | None = None) -> Path:
    """``value`` as strict JSON (non-finite floats as null, :func:`strict_json`), written
    atomically (:func:`patrolsb3.runs.write_atomically`)."""
    import json

    text = json.dumps(strict_json(value), indent=indent, allow_nan=False)
    return write_atomically(path, lambda partial: partial.write_text(text))


def _nan_for_null(value):
    if value is None:
        return float("nan")
    if isinstance(value, dict):
        return {k: _nan_for_null(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_nan_for_null(v) for v in value]
    return value


def read_json(path, what: str = "JSON file"):
    """The value of a JSON file, or one line naming the file and what is wrong with it.

    Args:
        path: the file.
        what: what the file should be, for the message (e.g. "eval.json of a zoo entry").

    Raises:
        ValueError: the file is not valid JSON (cut, damaged, or another kind of file).
    """
    import json
    path = Path(path)
    try:
        return json.loads(path.read_text())
    except UnicodeDecodeError:
        raise ValueError(f"{path}: not a text file; expected a {what}") from None
    except json.JSONDecodeError as exc:
        raise ValueError(f"{path}: not valid JSON, cut or damaged at line {exc.lineno} column {exc.colno} "
                         f"({exc.msg}); expected a {what}") from None


def read_eval_file(path) -> dict:
    """A zoo entry's eval.json (``write_zoo_eval``'s), its figures' nulls back to NaN.

    Raises:
        ValueError: not valid JSON, or not such a file (one line naming it).
    """
    data = read_json(path, "zoo entry's eval.json (patrolsb3 zoo eval)")
    if not isinstance(data, dict) or not isinstance(data.get("results"), list) \
            or not all(isinstance(r, dict) and "n_agents" in r and "summary" in r for r in data["results"]):
        raise ValueError(f"{path}: not an eval.json written by 'patrolsb3 zoo eval' (no results per team size); "
                         f"rewrite it with 'patrolsb3 zoo eval'")
    data["results"] = read_results(data["results"])
    return data


def read_results(results: list) -> list:
    """Results read from JSON with their figures as written: a null inside a result's
    ``summary`` (a figure that did not exist) back to NaN, and each rate's interval the exact one
    of its per-episode values (:mod:`patrolsb3.stats`), whatever interval was stored with it."""
    return [{**r, "summary": _exact_rates(_nan_for_null(r["summary"]))} if isinstance(r, dict) and "summary" in r
            else r for r in results]


def _exact_rates(summary: dict) -> dict:
    for metric in RATE_METRICS:
        figure = summary.get(metric) if isinstance(summary, dict) else None
        if isinstance(figure, dict) and figure.get("episodes"):
            figure["ci95"] = rate_interval(figure["episodes"])
    return summary
