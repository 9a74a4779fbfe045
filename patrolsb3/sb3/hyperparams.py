"""Training hyperparameters: the YAML files of ``patrolsb3/hyperparams/`` (keyed by map, with
a ``default:`` entry), ``key=value`` overrides, and schedules written as strings.

Schedules: a number (constant), ``lin_<v>`` (linear from v to 0, as in rl-baselines3-zoo)
or ``drop_<v>_<w>`` (v, then w after two thirds of training: the paper's learning rate).
"""
from __future__ import annotations

import copy
from pathlib import Path
from typing import Any, Callable

import yaml

from .curriculum import lr_schedule

DEFAULT_FILE = Path(__file__).resolve().parent.parent / "hyperparams" / "default.yml"
"""The hyperparameters shipped with the package (paper values)."""

NESTED = ("policy_kwargs", "env")
"""Keys whose dict values are merged key by key rather than replaced."""


def load_hyperparams(map_name: str, path: str | Path | None = None) -> dict:
    """The hyperparameters of a map: ``default`` merged with the map's own entry.

    Args:
        map_name: map name ("A" ..); a map without an entry gets ``default``.
        path: a YAML file (default: the package's ``hyperparams/default.yml``).

    Raises:
        FileNotFoundError: the file does not exist.
        ValueError: the file is not YAML, has no ``default:`` entry or is not a mapping.
    """
    path = Path(path) if path is not None else DEFAULT_FILE
    if not path.is_file():
        raise FileNotFoundError(f"hyperparameter file {path} not found")
    try:
        table = yaml.safe_load(path.read_text()) or {}
    except (yaml.YAMLError, UnicodeDecodeError) as exc:
        raise ValueError(f"{path}: not valid YAML, cut or damaged ({str(exc).splitlines()[0]})") from None
    if not isinstance(table, dict) or not isinstance(table.get("default"), dict):
        raise ValueError(f"{path}: expected a mapping with a 'default:' entry (keyed by map name)")
    return merge(table["default"], table.get(str(map_name)) or {})


def merge(base: dict, overrides: dict) -> dict:
    """``base`` updated by ``overrides``; the NESTED dicts are merged one level deeper."""
    out = copy.deepcopy(base)
    for key, value in overrides.items():
        if key in NESTED and isinstance(value, dict):
            out[key] = {**(out.get(key) or {}), **value}
        else:
            out[key] = copy.deepcopy(value)
    return out


def parse_set(pairs: list[str]) -> dict:
    """``["n_steps=128", "policy_kwargs.lstm_hidden_size=64"]`` -> nested dict (values read
    as YAML, so numbers, booleans and lists work).

    Raises:
        ValueError: an item without ``=``.
    """
    out: dict = {}
    for pair in pairs or []:
        if "=" not in pair:
            raise ValueError(f"--set expects key=value, got {pair!r}")
        key, text = pair.split("=", 1)
        try:
            value = yaml.safe_load(text)
        except yaml.YAMLError as exc:
            problem = str(exc).splitlines()[0]
            raise ValueError(f"--set {pair!r}: the value is not valid YAML ({problem})") from None
        parts = key.strip().split(".")
        node = out
        for part in parts[:-1]:
            node = node.setdefault(part, {})
        node[parts[-1]] = value
    return out


def schedule(value: Any, name: str = "learning_rate") -> float | Callable[[float], float]:
    """A number or schedule string -> what SB3 accepts (a float or f(progress_remaining)).

    Raises:
        ValueError: a string that is not ``lin_<v>`` or ``drop_<v>_<w>``.
    """
    if isinstance(value, (int, float)):
        return float(value)
    text = str(value)
    try:
        if text.startswith("lin_"):
            start = float(text[4:])
            return lambda progress_remaining: progress_remaining * start
        if text.startswith("drop_"):
            first, late = (float(v) for v in text[5:].split("_"))
            return lr_schedule(first, late, drop_at=2 / 3)
        return float(text)
    except ValueError:
        raise ValueError(f"{name}: {value!r} is not a number, 'lin_<v>' or 'drop_<v>_<w>'") from None


def per_phase(value: float, phases_per_step: int) -> float:
    """A per-simulator-step factor (gamma, GAE lambda) as a per-env-step one:
    ``value ** (1 / phases_per_step)``, so that two phases (message, move) discount one
    simulator step exactly by ``value``."""
    return float(value) ** (1.0 / phases_per_step)
