"""The learning variants of the paper: same network and budget, only the message channel differs."""
from __future__ import annotations

from ..names import VARIANT_NAMES

# in the order of VARIANT_NAMES (rl-msg, rl-no-msg, rl-intention): RIAL's learned 16-symbol
# messages; positions only, no message channel; each agent's intended move, a fixed meaning
VARIANTS = dict(zip(VARIANT_NAMES, ({"comm": "learned"}, {"comm": "none"}, {"comm": "intention"}), strict=True))
"""Variant name -> environment config overrides (:class:`patrolsb3.core.config.EnvConfig`)."""


def variant_overrides(variant: str) -> dict:
    """The environment config overrides of a variant.

    Args:
        variant: a key of :data:`VARIANTS`.

    Returns:
        A fresh dict of EnvConfig field overrides.

    Raises:
        ValueError: an unknown variant (the message lists the known ones).
    """
    if variant not in VARIANTS:
        raise ValueError(f"unknown variant {variant!r}; known variants: {sorted(VARIANTS)}")
    return dict(VARIANTS[variant])
