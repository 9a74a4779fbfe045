"""Strategy names, in one place: the grammar of the command line (a heuristic's name, or
``zoo:<variant>`` and ``zoo:<variant>:<shelf>`` for the zoo's entries), and one display name
per strategy for every table, plot and claim (the paper's names: RL-MSG, RL-NO-MSG,
RL-INTENTION), whatever it is called on the command line or in the paper's data files (the CSV
columns ``INTENTION``, ``NOMSG``, ``MSG`` its LaTeX tables read, which ``compare`` keeps).
Imports nothing heavy (neither torch nor SuperSuit).
"""
from __future__ import annotations

VARIANT_NAMES = ("rl-msg", "rl-no-msg", "rl-intention")
"""The learned variants (their env settings: :mod:`patrolsb3.sb3.variants`)."""
LEARNED_PREFIX = "zoo:"
"""A strategy name that starts with this is a zoo entry: ``zoo:<variant>[:<shelf>]``."""
GUARDED = "guarded"
"""The shelf of the entries behind the return guard (``zoo:rl-msg:guarded``, ``zoo/guarded/``)."""
SHELVES = {
    GUARDED: "guarded",
    "paper-recipe": "paper recipe",
    "cd10": "c_d 10",
}
"""The zoo's shelves: ``zoo/<shelf>/``, entries kept apart from the main zoo's and named
``zoo:<variant>:<shelf>``; shelf -> the label tables add to the variant's name. ``guarded``: the
earlier entries that act behind the return guard (not the paper's setting); ``paper-recipe``: the
paper's recipe at its budget (issue 43's E2); ``cd10``: the zoo's recipe with the paper's
difference-reward weight c_d = 10 (issue 43's E1). The main zoo (no shelf) holds the entries
trained with the recipe the zoo has chosen. What each shelf means: docs/zoo.md."""


class StrategyNameError(ValueError):
    """A strategy name that does not follow the grammar (names it and what is wrong)."""


def is_learned(name) -> bool:
    """True for a zoo strategy name (``zoo:...``, any case)."""
    return str(name).strip().lower().startswith(LEARNED_PREFIX)


def check_shelf(shelf: str, what: str = "--shelf") -> str:
    """``shelf`` in lower case, "" for the main zoo.

    Raises:
        StrategyNameError: not a shelf of :data:`SHELVES` (names ``what``).
    """
    shelf = str(shelf or "").strip().lower()
    if shelf and shelf not in SHELVES:
        raise StrategyNameError(f"{what} {shelf!r}: not a shelf of the zoo; known: {', '.join(SHELVES)}")
    return shelf


def shelf_option(shelf: str, guarded: bool) -> str:
    """The shelf a command's ``--shelf SHELF`` and ``--guarded`` (short for ``--shelf guarded``)
    name together; "" for the main zoo.

    Raises:
        StrategyNameError: an unknown shelf, or ``--guarded`` with another shelf.
    """
    shelf = check_shelf(shelf)
    if guarded and shelf not in ("", GUARDED):
        raise StrategyNameError(f"--guarded and --shelf {shelf}: --guarded is --shelf {GUARDED}; give one of them")
    return GUARDED if guarded else shelf


def parse_strategy(name: str) -> tuple[str, str]:
    """``"zoo:rl-msg"`` -> ``("rl-msg", "")``; ``"zoo:rl-msg:guarded"`` -> ``("rl-msg", "guarded")``.

    Returns:
        (variant, shelf), shelf "" for the main zoo.

    Raises:
        StrategyNameError: not a zoo strategy, an unknown variant or an unknown shelf.
    """
    parts = str(name).strip().split(":")
    if parts[0].lower() != "zoo" or len(parts) not in (2, 3):
        raise StrategyNameError(f"{name!r} is not a zoo strategy; expected zoo:<variant> or zoo:<variant>:<shelf> "
                                f"(shelves: {', '.join(SHELVES)})")
    variant = parts[1].lower()
    if variant not in VARIANT_NAMES:
        raise StrategyNameError(f"{name!r}: unknown variant {variant!r}; known: {', '.join(VARIANT_NAMES)}")
    shelf = check_shelf(parts[2], f"{name!r}: shelf") if len(parts) == 3 else ""
    if len(parts) == 3 and not shelf:
        raise StrategyNameError(f"{name!r}: empty shelf; known: {', '.join(SHELVES)}")
    return variant, shelf


def strategy_name(variant: str, shelf: str = "") -> str:
    """The strategy name of an entry: ``zoo:<variant>``, or ``zoo:<variant>:<shelf>``."""
    return f"{LEARNED_PREFIX}{variant}" + (f":{shelf}" if shelf else "")


VARIANT_DISPLAY = {"rl-msg": "RL-MSG", "rl-no-msg": "RL-NO-MSG", "rl-intention": "RL-INTENTION"}
"""Learned variant -> its name in the paper."""

CSV_COLUMNS = {"MSG": "rl-msg", "NOMSG": "rl-no-msg", "INTENTION": "rl-intention"}
"""The paper's data-file column -> the learned variant it holds."""


def shelf_column(column: str, shelf: str) -> str:
    """A data-file column of a shelf's entries: ``MSG`` on the ``paper-recipe`` shelf is
    ``MSG-PAPER-RECIPE``."""
    return f"{column}-{shelf.upper()}"


def display_name(name: str) -> str:
    """The name people read for a strategy (``zoo:rl-msg`` -> ``RL-MSG``,
    ``zoo:rl-msg:guarded`` -> ``RL-MSG (guarded)``), a CSV column (``NOMSG``, ``MSG-GUARDED``)
    or a heuristic (its own name).

    >>> display_name("zoo:rl-no-msg"), display_name("NOMSG-GUARDED"), display_name("zoo:rl-msg:paper-recipe")
    ('RL-NO-MSG', 'RL-NO-MSG (guarded)', 'RL-MSG (paper recipe)')
    >>> display_name("SEBS")
    'SEBS'
    """
    base, label = name, ""
    for shelf, shown in SHELVES.items():
        for suffix in (f":{shelf}", "-" + shelf.upper()):
            if name.lower().endswith(suffix.lower()) and len(name) > len(suffix):
                base, label = name[:-len(suffix)], shown
    variant = base[len(LEARNED_PREFIX):].lower() if is_learned(base) else CSV_COLUMNS.get(base)
    if label and not variant:          # a heuristic whose name happens to end like a shelf
        base, label = name, ""
    shown = VARIANT_DISPLAY.get(variant, base) if variant else base
    return f"{shown} ({label})" if label else shown


def canonical_name(name: str) -> str:
    """The name tables use: heuristics in capitals ('sebs' -> 'SEBS'), zoo models as
    'zoo:<variant>' (or 'zoo:<variant>:<shelf>') in lower case."""
    name = str(name).strip()
    if is_learned(name):
        return name.lower()
    return name.upper()
