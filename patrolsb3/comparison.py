"""Planning and running a comparison (``patrolsb3 compare``): its cells (map, strategy, team
size), the figures already stored for them, and evaluating the rest here or on Ray.

A cell's stored figures come from one lookup (:class:`StoredResults`) over the two places a
comparison keeps them: a learned column's from its zoo entries' ``eval.json`` (the main zoo
or a recipe shelf: every training seed with this protocol, pooled with the seed as the unit;
behind the return guard: the entry's own), a heuristic's from the comparison's ``results.json``
(:class:`~patrolsb3.result_store.ResultStore`). Zoo figures are never taken from
``results.json``: a model's weights can change under the same name.
"""
from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass

from . import zoo
from .core.maps import load_map
from .distributed import connect, evaluate_on_ray
from .evaluate import evaluate, evaluation_setup, request_of
from .names import SHELVES, canonical_name, is_learned
from .report import EXTRA_COLUMNS, ZOO_COLUMNS
from .result_store import ResultStore
from .strategies import REGISTRY

Cell = tuple[str, str, int]
"""(map name as given, strategy name, team size)."""


@dataclass(frozen=True)
class Protocol:
    """What every cell of a comparison runs: ``tests`` x ``episodes`` episodes of ``steps`` steps
    from simulator seed ``seed``, zoo models greedy (``deterministic``) or sampling, their
    networks on ``device``."""

    episodes: int
    tests: int
    steps: int
    seed: int
    deterministic: bool = True
    device: str = "cpu"


def default_strategies(map_name: str, say: Callable[[str], None] = print) -> list[str]:
    """The columns of a map when none are asked for: the heuristics, RANDOM and CYCLIC, and each
    zoo variant with an entry in the paper's setting (``say`` names those without one)."""
    names = ["CR", "PART", "SEBS", *EXTRA_COLUMNS]
    names += [s for s in ZOO_COLUMNS.values() if zoo.available(map_name, zoo.parse_strategy(s)[0])]
    absent = [s for s in ZOO_COLUMNS.values() if s not in names]
    if absent:
        say(f"map {map_name.upper()}: no entry in the paper's setting for {', '.join(absent)}; those columns "
            f"stay empty (the entries behind the return guard: --strategies ...,{absent[0]}:guarded)")
    return names


def plan_cells(maps: list[str], sizes: list[int], strategies: list[str] | None,
               say: Callable[[str], None] = print) -> list[Cell]:
    """Check a comparison's maps, team sizes and strategies, and list its cells in report order.

    Args:
        maps: map names or files, each once.
        sizes: team sizes (1..5).
        strategies: strategy names (any case), or None for :func:`default_strategies`.
        say: receives the notes about empty zoo columns.

    Raises:
        ValueError: a map given twice or not loadable, a team above 5, an unknown strategy, a zoo
            strategy without a model on some map, or a zoo entry with several seeds and no
            default (each in one line, before any episode runs).
    """
    if duplicates := sorted({m for m in maps if maps.count(m) > 1}):
        raise ValueError(f"--maps {','.join(maps)}: {', '.join(duplicates)} given more than once")
    for m in maps:
        load_map(m)
    if max(sizes) > 5:
        raise ValueError(f"--agents: at most 5 agents (max_agents) per team, got {max(sizes)}")
    asked = [canonical_name(s) for s in strategies or [] if s.strip()]
    for name in asked:
        if not is_learned(name) and name not in REGISTRY:
            raise ValueError(f"unknown strategy {name!r}; known: {', '.join(REGISTRY)}, zoo:<variant> "
                             f"or zoo:<variant>:<shelf> (shelves: {', '.join(SHELVES)})")
        if is_learned(name):
            variant, shelf = zoo.parse_strategy(name)
            missing = [m for m in maps if not zoo.available(m, variant, shelf=shelf)]
            if missing:
                raise ValueError(f"{name}: no zoo model for map(s) {', '.join(missing)}"
                                 + (f" on the shelf {shelf!r}" if shelf else " in the main zoo"))
    cells = [(m, name, n) for m in maps for name in (asked or default_strategies(m, say)) for n in sizes]
    for m, name in dict.fromkeys((m, name) for m, name, _ in cells if is_learned(name)):
        variant, shelf = zoo.parse_strategy(name)
        if shelf != zoo.GUARDED:          # several seeds and no default.yml: one line saying how to choose
            zoo.default_seed(m, variant, shelf=shelf)
    return cells


class StoredResults:
    """The figures a comparison already has, for each cell: one lookup over the zoo entries'
    ``eval.json`` (learned columns) and ``OUT/results.json`` (heuristics; module docstring).

    Args:
        out: the comparison's folder.
        protocol: the comparison's :class:`Protocol`; a stored result counts only if it ran exactly that.
        rerun_heuristics: ignore the heuristics' stored results (``--rerun-heuristics``).
        rerun_zoo: ignore the zoo entries' eval.json (``--rerun-zoo``).
    """

    def __init__(self, out, protocol: Protocol, rerun_heuristics: bool = False, rerun_zoo: bool = False):
        self.store = ResultStore(out)
        self.protocol = protocol
        self.rerun_heuristics, self.rerun_zoo = rerun_heuristics, rerun_zoo
        self.pooled = {}          # {(MAP, zoo strategy): (training seeds pooled, seeds left out)}
        self.reused = set()       # the cells whose figures were found here

    @property
    def path(self):
        """The comparison's results.json."""
        return self.store.path

    def find(self, cell: Cell) -> tuple[dict | None, str]:
        """The stored result of ``cell`` for this protocol and where it came from (a note for the
        progress line), or ``(None, "")``."""
        m, name, n = cell
        p = self.protocol
        if is_learned(name):
            if self.rerun_zoo:
                return None, ""
            variant, shelf = zoo.parse_strategy(name)
            if shelf == zoo.GUARDED:
                r = zoo.cached_result(m, variant, n, p.episodes, p.steps, p.seed, p.tests,
                                      deterministic=p.deterministic, shelf=shelf)
            else:                 # the main zoo or a recipe shelf: every seed with this protocol, pooled
                r = zoo.pooled_result(m, variant, n, p.episodes, p.steps, p.seed, p.tests,
                                      deterministic=p.deterministic, shelf=shelf)
                if r is not None:
                    self.pooled[(m.upper(), name)] = (r["training_seeds"], r["unpooled_seeds"])
            source = "  (from the zoo's eval.json; --rerun-zoo to run it)"
        else:
            if self.rerun_heuristics:
                return None, ""
            spec, cfg = evaluation_setup(m, n, p.episodes, p.tests, p.steps)
            r = self.store.find(request_of(name, spec, n, p.episodes, p.tests, p.steps, p.seed, cfg,
                                           deterministic=p.deterministic))
            source = f"  (from {self.store.path}; --rerun-heuristics to run it)"
        if r is None:
            return None, ""
        self.reused.add(cell)
        return r, source

    def add(self, cell: Cell, result: dict) -> None:
        """Keep a heuristic's new result in results.json at once (a zoo model's is not kept here)."""
        if not is_learned(cell[1]):
            self.store.add(result)

    def zoo_notes(self, cells: list[Cell]) -> dict:
        """{(MAP, zoo strategy): the report's line about that column (:func:`zoo_note`)}."""
        return {(m.upper(), name): zoo_note(m, name, reused=(m, name, n) in self.reused,
                                            pooled=self.pooled.get((m.upper(), name)))
                for m, name, n in cells if is_learned(name)}


def evaluate_cells(cells: list[Cell], protocol: Protocol, progress: bool = True, ray: bool = False,
                   address: str | None = None, say: Callable[[str], None] = print
                   ) -> Iterator[tuple[Cell, dict, float]]:
    """Evaluate ``cells`` (:func:`patrolsb3.evaluate.evaluate` each), one after the other or as
    Ray tasks of one CPU each (joining ``address``, or a local Ray).

    Yields:
        (cell, its result, seconds it took), in the order they finish.
    """
    p = protocol
    jobs = [dict(strategy=name, map_name=m, n_agents=n, episodes=p.episodes, tests=p.tests, steps=p.steps,
                 seed=p.seed, deterministic=p.deterministic, device=p.device) for m, name, n in cells]
    if ray:
        cpus = connect(address).get("CPU", 0)
        say(f"ray: {len(jobs)} cells on {cpus:.0f} CPUs")
        for i, result, seconds in evaluate_on_ray(jobs):
            yield cells[i], result, seconds
        return
    for cell, job in zip(cells, jobs):
        begun = time.time()
        result = evaluate(progress=progress, **job)
        yield cell, result, time.time() - begun


def learning_curves(cells: list[Cell]) -> dict:
    """{MAP: {variant (or variant:shelf): [curve.csv of every training seed]}} of the zoo
    columns among ``cells`` (the report's training figure)."""
    curves = {}
    for m, name, _ in cells:
        if is_learned(name):
            variant, shelf = zoo.parse_strategy(name)
            if found := zoo.seed_curves(m, variant, shelf=shelf):
                curves.setdefault(m.upper(), {})[name[4:]] = found
    return curves


def zoo_note(map_name: str, strategy: str, reused: bool, pooled=None) -> str:
    """The report's line about a zoo column: its setting (behind the return guard or the paper's),
    which training seeds its figures are (pooled: ``(seeds pooled, seeds left out)``), whether
    they were reused from the entries' eval.json or computed now, and the recipe the seeds were
    trained with (:func:`patrolsb3.zoo.trained_with`)."""
    variant, shelf = zoo.parse_strategy(strategy)
    folder = zoo.entry_dir(map_name, variant, shelf=shelf)
    config = zoo.read_entry(folder)["config"]
    guarded = bool((config.get("env") or {}).get("return_guard"))
    setting = ("behind the return guard (env.return_guard, ours: the heuristics' recharge rule as a "
               "shield)" if guarded else "the paper's setting (no return guard)")
    if shelf == zoo.GUARDED:
        which = ""
    elif pooled and len(pooled[0]) > 1:
        which = (f"training seeds {', '.join(map(str, pooled[0]))} pooled (the figure is the mean of the "
                 f"seeds' means, +- their std, the interval over the seeds' means; a rate's over all their "
                 f"episodes, exact); ")
    else:
        shown = pooled[0][0] if pooled else config.get("seed", "?")
        which = f"training seed {shown} ({default_reason(map_name, variant, shelf)}); "
    if pooled and pooled[1]:
        which += (f"seed{'s' if len(pooled[1]) > 1 else ''} {', '.join(map(str, pooled[1]))} left out (no "
                  f"eval.json with per-episode figures for this protocol: 'patrolsb3 zoo eval'); ")
    return (f"{setting}; {which}figures {'reused from the eval.json' if reused else 'computed now'}; "
            f"trained with {zoo.trained_with(map_name, variant, shelf=shelf)}")


def default_reason(map_name: str, variant: str, shelf: str = "") -> str:
    """Why the entry's default seed (the main zoo's or a recipe shelf's) is the default, for the report."""
    chosen = zoo.default_seed(map_name, variant, shelf=shelf) or {}
    have = zoo.seeds(map_name, variant, shelf=shelf)
    return f"{chosen.get('chosen_by', '?')}; the entry has {len(have)} seed{'s' if len(have) != 1 else ''}"
