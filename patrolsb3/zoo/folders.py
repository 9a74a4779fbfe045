"""The zoo's folders: where the zoo is, which folder holds which entry and seed, and reading an
entry's files. No torch here: listing and reading entries is cheap.

The main zoo and its shelves (:data:`patrolsb3.names.SHELVES`), each its own folder (the rule
lives here, in :func:`variant_folder` and :func:`entry_dir`):

- the **main zoo** (no shelf): ``zoo/<MAP>/<variant>/seed<k>/``, one folder per training seed,
  trained and evaluated in the paper's setting (no return guard) with the zoo's chosen recipe;
  ``zoo/<MAP>/<variant>/default.yml`` names the seed chosen by validation (``patrolsb3 zoo
  choose``, on the validation seed, never the evaluation's). With a single seed and no
  ``default.yml``, that seed is the default.
- a **recipe shelf** (``shelf="paper-recipe"``, strategy ``zoo:<variant>:paper-recipe``):
  ``zoo/<shelf>/<MAP>/<variant>/seed<k>/``, the same layout as the main zoo's, for entries
  trained with another recipe and compared beside the main ones.
- **behind the return guard** (``shelf="guarded"``, strategy ``zoo:<variant>:guarded``):
  ``zoo/guarded/<MAP>/<variant>/``, the earlier entries that act with the heuristics' recharge
  rule as a shield (``env.return_guard``, ours; not the paper's setting); this shelf keeps its
  earlier layout: the variant folder is the entry (its default), with optional ``seed<k>``
  subfolders.

Each entry folder holds ``model.zip`` (policy only, no optimizer state), ``config.yml`` (env
config, algorithm, hyperparameters, versions, training budget), ``command.txt``,
``curve.csv`` (learning curve) and ``eval.json`` (paper metrics for 1-5 agents); their names
are :class:`patrolsb3.runs.RunFolder`'s.
"""
from __future__ import annotations

import os
from pathlib import Path

import yaml

from .. import names
from ..core.maps import parse_map
from ..names import GUARDED, SHELVES, VARIANT_NAMES, check_shelf
from ..outputs import read_eval_file
from ..runs import ZooEntry, read_config


class ZooError(ValueError):
    """A zoo entry that is missing, incomplete or incompatible with this code."""


ZOO_DIR = Path(__file__).resolve().parents[2] / "zoo"
"""The checkout's zoo (the zoo ships with the git repository, not with the wheel)."""


ZOO_ENV = "PATROLSB3_ZOO"
"""Environment variable naming a zoo folder (e.g. a clone's ``zoo/``) for an installed package."""


def training_map(config: dict):
    """The map a run or entry was trained on, from its config.yml: the map file if it is still
    there, else the map text it recorded (a map not shipped), else the shipped map by name."""
    source = config.get("map_source")
    if source and Path(source).is_file():
        return source
    if config.get("map_text"):
        return parse_map(config["map_text"], name=config["map"], source=str(source or "<config.yml>"))
    return config["map"]


def use_zoo_dir(zoo_dir) -> None:
    """Make ``zoo_dir`` the zoo of this process and the processes it starts (Ray's included):
    what a command's ``--zoo-dir`` does, through ``$PATROLSB3_ZOO``.

    Raises:
        ZooError: not a folder.
    """
    root = Path(zoo_dir)
    if not root.is_dir():
        raise ZooError(f"--zoo-dir {root}: not a folder; give the zoo/ folder of a patrolsb3 clone")
    os.environ[ZOO_ENV] = str(root.resolve())


def zoo_root(zoo_dir=None) -> Path:
    """Where the zoo is: ``zoo_dir`` if given, else ``$PATROLSB3_ZOO``, else the checkout's ``zoo/``.

    Raises:
        ZooError: none of them is a folder; the message says where it looked and how to get it.
    """
    if zoo_dir is not None:
        return Path(zoo_dir)
    if os.environ.get(ZOO_ENV):
        root = Path(os.environ[ZOO_ENV])
        if not root.is_dir():
            raise ZooError(f"${ZOO_ENV}={root} is not a folder; point it at the zoo/ folder of a "
                           f"patrolsb3 clone")
        return root
    if ZOO_DIR.is_dir():
        return ZOO_DIR
    raise ZooError(f"no zoo found (looked for ${ZOO_ENV} and {ZOO_DIR.name}/ beside the package): the zoo "
                   f"ships with the git repository, not the wheel; clone it and set {ZOO_ENV} to its zoo/ "
                   f"folder, or give the zoo folder with --zoo-dir (commands) or zoo_dir= (Python)")


DEFAULT_FILE = ZooEntry.DEFAULT
"""In a paper-setting entry folder: ``{seed: k, chosen_by: ...}``, the seed ``load`` uses by default."""


def parse_strategy(name: str) -> tuple[str, str]:
    """:func:`patrolsb3.names.parse_strategy`, its error a :class:`ZooError`."""
    try:
        return names.parse_strategy(name)
    except names.StrategyNameError as exc:
        raise ZooError(str(exc)) from None


def variant_folder(map_name: str, variant: str, zoo_dir=None, shelf: str = "") -> Path:
    """``<zoo>/<MAP>/<variant>`` (the main zoo) or ``<zoo>/<shelf>/<MAP>/<variant>``; it need not exist.

    Raises:
        ZooError: an unknown shelf.
    """
    root = zoo_root(zoo_dir)
    return (root / checked_shelf(shelf) if shelf else root) / str(map_name).upper() / variant


def checked_shelf(shelf: str) -> str:
    """:func:`patrolsb3.names.check_shelf`, its error a :class:`ZooError`."""
    try:
        return check_shelf(shelf)
    except names.StrategyNameError as exc:
        raise ZooError(str(exc)) from None


def shelf_of(folder) -> str:
    """The shelf an entry folder sits on ("" for the main zoo), from its place in the layout:
    ``.../<shelf>/<MAP>/<variant>[/seed<k>]``."""
    parts = Path(folder).resolve().parts
    found = [i for i, part in enumerate(parts) if part in VARIANT_NAMES]
    if not found or found[-1] < 2:
        return ""
    above_map = parts[found[-1] - 2]
    return above_map if above_map in SHELVES else ""


def seeds(map_name: str, variant: str, zoo_dir=None, shelf: str = "") -> list[int]:
    """The training seeds an entry holds (its ``seed<k>`` subfolders with a model)."""
    folder = variant_folder(map_name, variant, zoo_dir, shelf)
    return sorted(int(p.parent.name[4:]) for p in folder.glob(f"seed*/{ZooEntry.MODEL}") if p.parent.name[4:].isdigit())


def seed_curves(map_name: str, variant: str, zoo_dir=None, shelf: str = "") -> list[Path]:
    """The curve.csv of every training seed of an entry (a guarded entry's one), in seed order;
    [] when there is none."""
    if shelf == GUARDED:
        path = ZooEntry(entry_dir(map_name, variant, zoo_dir, shelf=GUARDED)).curve_file
        return [path] if path.is_file() else []
    found = [ZooEntry(entry_dir(map_name, variant, zoo_dir, seed=k, shelf=shelf)).curve_file
             for k in seeds(map_name, variant, zoo_dir, shelf)]
    return [p for p in found if p.is_file()]


def default_seed(map_name: str, variant: str, zoo_dir=None, shelf: str = "") -> dict | None:
    """The entry's default seed (the main zoo or a recipe shelf): ``{"seed": k, "chosen_by":
    text}`` from its ``default.yml``, else its only seed; None when it has no seed.

    Raises:
        ZooError: several seeds and no ``default.yml`` (say how to choose), or a default.yml
            naming a seed the entry lacks.
    """
    folder = variant_folder(map_name, variant, zoo_dir, shelf)
    have = seeds(map_name, variant, zoo_dir, shelf)
    choose = f"patrolsb3 zoo choose {str(map_name).upper()} {variant}" + (f" --shelf {shelf}" if shelf else "")
    if (folder / DEFAULT_FILE).is_file():
        try:
            chosen = yaml.safe_load((folder / DEFAULT_FILE).read_text()) or {}
        except (yaml.YAMLError, UnicodeDecodeError) as exc:
            raise ZooError(f"{folder / DEFAULT_FILE}: not valid YAML, cut or damaged ({str(exc).splitlines()[0]}); "
                           f"write it again with '{choose}'") from None
        if not isinstance(chosen, dict):
            raise ZooError(f"{folder / DEFAULT_FILE}: expected a mapping with 'seed', got {type(chosen).__name__}; "
                           f"write it again with '{choose}'")
        if chosen.get("seed") not in have:
            raise ZooError(f"{folder / DEFAULT_FILE}: names seed {chosen.get('seed')!r}, the entry has {have}")
        return chosen
    if len(have) > 1:
        raise ZooError(f"{folder}: seeds {have} and no {DEFAULT_FILE}; run '{choose}' to pick one by validation")
    return {"seed": have[0], "chosen_by": "the only seed"} if have else None


def entry_dir(map_name: str, variant: str, zoo_dir=None, seed: int | None = None, shelf: str = "") -> Path:
    """Folder of one zoo entry (it need not exist).

    The main zoo or a recipe shelf: ``<zoo>[/<shelf>]/<MAP>/<variant>/seed<k>``, ``seed`` or else
    the default seed (:func:`default_seed`; the bare variant folder when there is none). Behind
    the guard: ``<zoo>/guarded/<MAP>/<variant>``, or its ``seed<k>`` subfolder.
    """
    folder = variant_folder(map_name, variant, zoo_dir, shelf)
    if seed is None and shelf != GUARDED:
        chosen = default_seed(map_name, variant, zoo_dir, shelf)
        seed = chosen["seed"] if chosen else None
    return folder if seed is None else folder / f"seed{int(seed)}"


def read_entry(path: Path, damaged_eval_ok: bool = False) -> dict:
    """config.yml and eval.json of one entry folder, as one dict with its ``path``.

    Args:
        path: the entry folder.
        damaged_eval_ok: a damaged eval.json reads as none (``zoo eval`` rewrites it) instead of
            an error.

    Raises:
        ZooError: no config.yml. ValueError: a damaged config.yml or eval.json (names it).
    """
    path = Path(path)
    config_file = ZooEntry(path).config_file
    if not config_file.is_file():
        raise ZooError(f"{path}: no config.yml; not a zoo entry")
    config = read_config(config_file)
    eval_file = ZooEntry(path).evaluation_file
    evaluation = None
    if eval_file.is_file():
        try:
            evaluation = read_eval_file(eval_file)
        except ValueError:
            if not damaged_eval_ok:
                raise
    return {"path": str(path), "config": config, "eval": evaluation}


def list_entries(zoo_dir=None) -> list[dict]:
    """Every entry folder of the zoo, the main zoo's (every seed) first, then each shelf's in the
    order of :data:`~patrolsb3.names.SHELVES`; sorted by map, variant and seed. Each dict also has
    ``shelf`` ("" for the main zoo) and ``seed`` (the folder's training seed, None for a guarded
    entry's default folder)."""
    root = zoo_root(zoo_dir)
    found = []
    config = ZooEntry.CONFIG
    patterns = [("", f"[A-Z]*/*/seed*/{config}")]
    for shelf in SHELVES:
        patterns += ([(shelf, f"{shelf}/*/*/{config}")] if shelf == GUARDED else []) + \
            [(shelf, f"{shelf}/[A-Z]*/*/seed*/{config}")]
    for shelf, pattern in patterns:
        for path in sorted(root.glob(pattern)):
            entry = read_entry(path.parent)
            name = path.parent.name
            entry["shelf"] = shelf
            entry["seed"] = int(name[4:]) if name.startswith("seed") and name[4:].isdigit() else None
            found.append(entry)
    return found


def available(map_name: str, variant: str, zoo_dir=None, shelf: str = "") -> bool:
    """True when the zoo has a model for (map, variant) on that shelf (the main zoo or a recipe
    shelf: at least one trained seed, whether or not a default has been chosen among several; ask
    :func:`default_seed` for that); False also when there is no zoo."""
    try:
        if shelf != GUARDED:
            return bool(seeds(map_name, variant, zoo_dir, shelf))
        return ZooEntry(entry_dir(map_name, variant, zoo_dir, shelf=shelf)).model_file.is_file()
    except ZooError:
        return False


def existing_entry_dir(map_name: str, variant: str, zoo_dir=None, seed: int | None = None,
                       shelf: str = "") -> Path:
    """:func:`entry_dir`, checked: the folder holds a model.

    Raises:
        ZooError: an unknown variant, or no such entry or seed (the message lists what the zoo has).
    """
    if variant not in VARIANT_NAMES:
        raise ZooError(f"unknown variant {variant!r}; known: {', '.join(VARIANT_NAMES)}")
    setting = f"on the shelf {shelf!r}" if shelf else "in the main zoo"
    folder = entry_dir(map_name, variant, zoo_dir, seed, shelf)
    model = ZooEntry(folder).model_file
    if seed is not None and not model.is_file():
        raise ZooError(f"no seed {seed} of {str(map_name).upper()}/{variant} {setting} (looked for "
                       f"{model}); its seeds: {seeds(map_name, variant, zoo_dir, shelf) or 'none'}")
    if not model.is_file():
        have = sorted({f"{str(e['config'].get('map', '?')).upper()}/{e['config'].get('variant', '?')}"
                       + (f":{e['shelf']}" if e["shelf"] else "") for e in list_entries(zoo_dir)})
        raise ZooError(f"no zoo model for map {str(map_name).upper()} variant {variant} {setting} "
                       f"(looked for {model}); the zoo has: {', '.join(have) or 'nothing'}")
    return folder
