"""Heuristic patrolling strategies, batched over episodes, with SB3's ``predict()`` signature.

``get(name, spec, n_agents, cfg=None, seed=0)`` builds one by name (case-insensitive):

* ``RANDOM`` — uniform random valid move (a floor), :mod:`.random_walk`;
* ``CR`` — conscientious reactive, own memory only, :mod:`.cr`;
* ``PART`` — one connected, balanced part per agent, :mod:`.part`;
* ``SEBS`` — state exchange Bayesian strategy with intentions, :mod:`.sebs`;
* ``CYCLIC`` — one tour of all vertices, agents spread on it, :mod:`.cyclic`.

All share the recharge planner (:mod:`.recharge`) and the navigation / deadlock rules
(:mod:`.navigation`); ``predict`` takes the batched simulator ``State`` as its observation
(see :mod:`.base`).
"""
from __future__ import annotations

from .base import HeuristicPolicy
from .cr import CRPolicy
from .cyclic import CyclicPolicy
from .part import PARTPolicy
from .random_walk import RandomPolicy
from .sebs import SEBSPolicy

REGISTRY: dict[str, type] = {"RANDOM": RandomPolicy, "CR": CRPolicy, "PART": PARTPolicy,
                             "SEBS": SEBSPolicy, "CYCLIC": CyclicPolicy}
"""Strategy name -> class."""


def names() -> list[str]:
    """The known strategy names."""
    return list(REGISTRY)


def get(name: str, spec, n_agents: int, cfg=None, seed: int = 0) -> HeuristicPolicy:
    """Build a heuristic by name.

    Args:
        name: RANDOM, CR, PART, SEBS or CYCLIC (case-insensitive).
        spec: the map (a ``MapSpec`` or a map name).
        n_agents: the team size.
        cfg: environment parameters (default: the map's defaults).
        seed: seed of the strategy's random draws.

    Raises:
        ValueError: an unknown name (the message lists the known ones).
    """
    key = str(name).upper()
    if key not in REGISTRY:
        raise ValueError(f"unknown strategy {name!r}; known: {', '.join(REGISTRY)} "
                         f"(or zoo:<variant> in evaluate/compare)")
    return REGISTRY[key](spec, n_agents, cfg=cfg, seed=seed)


__all__ = ["HeuristicPolicy", "REGISTRY", "get", "names", "CRPolicy", "CyclicPolicy",
           "PARTPolicy", "RandomPolicy", "SEBSPolicy"]
