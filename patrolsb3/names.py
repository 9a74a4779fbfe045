"""Strategy names, in one place: the grammar of the command line (a heuristic's name, or
``zoo:<variant>`` and ``zoo:<variant>:guarded`` for the zoo's entries), and one display name
per strategy for every table, plot and claim (the paper's names: RL-MSG, RL-NO-MSG,
RL-INTENTION), whatever it is called on the command line or in the paper's data files (the CSV
columns ``INTENTION``, ``NOMSG``, ``MSG`` its LaTeX tables read, which ``compare`` keeps).
Imports nothing heavy (neither torch nor SuperSuit).
"""
from __future__ import annotations

VARIANT_NAMES = ("rl-msg", "rl-no-msg", "rl-intention")
"""The learned variants (their env settings: :mod:`patrolsb3.sb3.variants`)."""
LEARNED_PREFIX = "zoo:"
"""A strategy name that starts with this is a zoo entry: ``zoo:<variant>[:guarded]``."""
GUARDED = "guarded"
"""The suffix that selects the entries behind the return guard (``zoo:rl-msg:guarded``), and
their subfolder of the zoo."""


class StrategyNameError(ValueError):
    """A strategy name that does not follow the grammar (names it and what is wrong)."""


def is_learned(name) -> bool:
    """True for a zoo strategy name (``zoo:...``, any case)."""
    return str(name).strip().lower().startswith(LEARNED_PREFIX)


def parse_strategy(name: str) -> tuple[str, bool]:
    """``"zoo:rl-msg"`` -> ``("rl-msg", False)``; ``"zoo:rl-msg:guarded"`` -> ``("rl-msg", True)``.

    Raises:
        StrategyNameError: not a zoo strategy, an unknown variant or an unknown suffix.
    """
    parts = str(name).strip().split(":")
    if parts[0].lower() != "zoo" or len(parts) not in (2, 3):
        raise StrategyNameError(f"{name!r} is not a zoo strategy; expected zoo:<variant> or zoo:<variant>:{GUARDED}")
    variant = parts[1].lower()
    if variant not in VARIANT_NAMES:
        raise StrategyNameError(f"{name!r}: unknown variant {variant!r}; known: {', '.join(VARIANT_NAMES)}")
    if len(parts) == 3 and parts[2].lower() != GUARDED:
        raise StrategyNameError(f"{name!r}: unknown suffix {parts[2]!r}; the only one is :{GUARDED} (the entries "
                                f"behind the return guard)")
    return variant, len(parts) == 3


def strategy_name(variant: str, guard: bool = False) -> str:
    """The strategy name of an entry: ``zoo:<variant>``, or ``zoo:<variant>:guarded``."""
    return f"{LEARNED_PREFIX}{variant}" + (f":{GUARDED}" if guard else "")


VARIANT_DISPLAY = {"rl-msg": "RL-MSG", "rl-no-msg": "RL-NO-MSG", "rl-intention": "RL-INTENTION"}
"""Learned variant -> its name in the paper."""

CSV_COLUMNS = {"MSG": "rl-msg", "NOMSG": "rl-no-msg", "INTENTION": "rl-intention"}
"""The paper's data-file column -> the learned variant it holds."""


def display_name(name: str) -> str:
    """The name people read for a strategy (``zoo:rl-msg`` -> ``RL-MSG``,
    ``zoo:rl-msg:guarded`` -> ``RL-MSG (guarded)``), a CSV column (``NOMSG``, ``MSG-GUARDED``)
    or a heuristic (its own name).

    >>> display_name("zoo:rl-no-msg"), display_name("NOMSG-GUARDED"), display_name("SEBS")
    ('RL-NO-MSG', 'RL-NO-MSG (guarded)', 'SEBS')
    """
    guarded = name.endswith(f":{GUARDED}") or name.endswith("-GUARDED")
    base = name.removesuffix(f":{GUARDED}").removesuffix("-GUARDED")
    variant = base[len(LEARNED_PREFIX):] if is_learned(base) else CSV_COLUMNS.get(base)
    shown = VARIANT_DISPLAY.get(variant, base) if variant else base
    return f"{shown} (guarded)" if guarded else shown


def canonical_name(name: str) -> str:
    """The name tables use: heuristics in capitals ('sebs' -> 'SEBS'), zoo models as
    'zoo:<variant>' (or 'zoo:<variant>:guarded') in lower case."""
    name = str(name).strip()
    if is_learned(name):
        return name.lower()
    return name.upper()
