"""Evaluations kept on disk so that a comparison can be resumed or rerun without repeating them.

``patrolsb3 compare`` writes every heuristic result it computes to ``<out>/results.json`` as
soon as it has it; run again with the same ``--out``, it takes each (map, strategy, team size)
whose stored result was run with exactly the same protocol (episodes, tests, steps, seed,
action mode), env settings and env version, and evaluates only the rest. Zoo models are not
taken from here (their weights can change under the same name): they come from their entry's
``eval.json`` (``patrolsb3.zoo.cached_result``) or are evaluated again.
"""
from __future__ import annotations

import json

from .core.config import ENV_VERSION, EnvConfig
from .names import is_learned
from .outputs import read_results, write_json
from .runs import ComparisonFolder

PROTOCOL_KEYS = ("strategy", "map", "n_agents", "episodes", "tests", "steps", "seed", "faults", "env", "draws")
"""Result fields that must match for a stored result to stand for a new run."""


def env_with_defaults(env) -> dict | None:
    """A result's env settings with every EnvConfig field it lacks at its default.

    A field added to EnvConfig after a result was stored (``c_home``, say) keeps the old
    rules at its default, so the old result stands for a run with the default.
    """
    return {**EnvConfig().to_dict(), **env} if isinstance(env, dict) else env


def protocol(result: dict) -> tuple:
    """The fields of a result (or of a request shaped like one) that decide whether it can be
    reused: those of :data:`PROTOCOL_KEYS` (env settings with defaults filled in:
    :func:`env_with_defaults`), the action mode for zoo models (heuristics ignore it) and the
    env version."""
    learned = is_learned(result["strategy"])
    fields = {k: result.get(k) for k in PROTOCOL_KEYS}
    fields["env"] = env_with_defaults(fields["env"])
    return (json.dumps([fields[k] for k in PROTOCOL_KEYS], sort_keys=True),
            bool(result.get("deterministic", True)) if learned else None,
            result.get("env_version", ENV_VERSION))


class ResultStore:
    """The results of one comparison folder, ``<folder>/results.json`` (a JSON list of
    ``evaluate()`` results, each with its ``env_version``).

    Args:
        folder: the comparison's output folder (created on the first :meth:`add`).
    """

    def __init__(self, folder):
        self.path = ComparisonFolder(folder).results_json
        self.results: list[dict] = []
        if self.path.is_file():
            try:
                self.results = json.loads(self.path.read_text())
                if not isinstance(self.results, list):
                    raise ValueError("not a list of results")
                self.results = read_results(self.results)
            except ValueError as err:
                raise ValueError(f"{self.path} is not a results file written by 'patrolsb3 compare' "
                                 f"({err}); move it away or choose another --out") from None

    def find(self, request: dict):
        """The stored result with the same protocol as ``request`` (an ``evaluate()`` result
        or a dict with the same keys), or None."""
        key = protocol(request)
        return next((r for r in reversed(self.results) if protocol(r) == key), None)

    def add(self, result: dict) -> None:
        """Store a result (replacing one with the same protocol) and write the file at once, so
        an interrupted comparison keeps what it finished. The file is merged, not overwritten:
        under a lock (``.results.lock`` beside it) the results another ``compare`` on the same
        folder stored meanwhile are read back first, so two comparisons on one ``--out`` keep
        both's results."""
        from filelock import FileLock
        result = {**result, "env_version": result.get("env_version", ENV_VERSION)}
        key = protocol(result)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        with FileLock(self.path.with_name(".results.lock")):
            stored = ResultStore(self.path.parent).results if self.path.is_file() else []
            mine = {protocol(r) for r in self.results}
            merged = [r for r in stored if protocol(r) not in mine] + self.results
            self.results = [r for r in merged if protocol(r) != key] + [result]
            write_json(self.path, self.results)
