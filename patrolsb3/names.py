"""What a strategy is called where people read it: one display name per strategy for every
table, plot and claim (the paper's names: RL-MSG, RL-NO-MSG, RL-INTENTION), whatever it is
called on the command line (``zoo:rl-msg``) or in the paper's data files (the CSV columns
``INTENTION``, ``NOMSG``, ``MSG`` its LaTeX tables read, which ``compare`` keeps). Imports
nothing heavy.
"""
from __future__ import annotations

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
    guarded = name.endswith(":guarded") or name.endswith("-GUARDED")
    base = name.removesuffix(":guarded").removesuffix("-GUARDED")
    variant = base.removeprefix("zoo:") if base.startswith("zoo:") else CSV_COLUMNS.get(base)
    shown = VARIANT_DISPLAY.get(variant, base) if variant else base
    return f"{shown} (guarded)" if guarded else shown
