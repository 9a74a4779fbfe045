"""Many jobs on many machines with Ray: sweep trials as Ray Tune trials, comparison cells as
Ray tasks. Nothing here changes what a job computes; it only decides where it runs.

* :func:`connect`: with no address, Ray starts on this machine with its cores (or ``num_cpus``);
  with an address (``ray start --head`` on one machine, ``ray start --address HEAD:6379`` on
  the others), the jobs spread over that cluster. Every machine needs patrolsb3 installed (the
  same version) and, for sweeps, the run folders' root on a shared file system.
* :func:`sweep_on_ray`: each trial of a sweep (:mod:`patrolsb3.sweeps`) runs as a Ray Tune
  trial with ``cpus_per_trial`` CPUs (and as many torch threads). A trial that raises fails
  alone: Tune goes on with the others and the summary holds its error. The run folders, not
  Tune's experiment state, say what is done, so a rerun resumes (see :mod:`patrolsb3.sweeps`).
* :func:`evaluate_on_ray`: comparison cells (map, strategy, team size) as Ray tasks of one CPU,
  yielded as they finish so the caller stores each at once (``results.json``).

Ray is an extra (``pip install -e ".[ray]"``); without it :func:`require_ray` raises a one-line
error saying how to install it.
"""
from __future__ import annotations

import logging
import os
import time
from pathlib import Path
from typing import Callable, Iterator

from .evaluate import evaluate

INSTALL_HINT = 'Ray is not installed; install the extra with: pip install -e ".[ray]"  (or pip install "ray[tune]")'


class RayMissing(ValueError):
    """Ray is not installed (the message says how to install it)."""


def require_ray():
    """The ``ray`` module (with Tune).

    Raises:
        RayMissing: Ray or Ray Tune is not installed.
    """
    try:
        import ray
        import ray.tune  # noqa: F401
    except ImportError:
        raise RayMissing(INSTALL_HINT) from None
    return ray


def connect(address: str | None = None, num_cpus: int | None = None) -> dict:
    """Start Ray on this machine (no address) or join a running cluster.

    Args:
        address: a cluster's address (``HOST:6379``, or ``auto`` for one started on this machine
            with ``ray start --head``); None starts a local Ray.
        num_cpus: CPUs a local Ray may use (default: all of this machine's); ignored with an
            address (the cluster's nodes say what they have).

    Returns:
        The CPUs Ray sees, {"CPU": n, ...}.
    """
    ray = require_ray()
    if not ray.is_initialized():
        options = dict(include_dashboard=False, log_to_driver=False, logging_level=logging.WARNING)
        if address:
            ray.init(address=address, **options)
        else:
            ray.init(num_cpus=num_cpus, **options)
    return ray.cluster_resources()


def _cause(error) -> str:
    """The last line of a trial's or task's error: the original exception, not Ray's wrapper."""
    cause = getattr(error, "cause", None) or error
    text = f"{type(cause).__name__}: {cause}"
    lines = [line for line in text.splitlines() if line.strip()]
    return lines[-1] if lines else type(cause).__name__


def sweep_on_ray(trials, run_trial: Callable, cpus_per_trial: int = 1, storage: Path | None = None,
                 say: Callable[[str], None] = print) -> dict:
    """Run trials as Ray Tune trials (Ray must be connected: :func:`connect`). This module knows
    nothing of what a trial is: the caller gives the function that runs one.

    Args:
        trials: the trials to run (``patrolsb3.sweeps.Trial``: a ``name``, a ``timesteps``).
        run_trial: ``run_trial(trial, torch_threads=k) -> {"timesteps", "seconds"}``
            (``patrolsb3.sweeps.run_trial``).
        cpus_per_trial: CPUs Tune reserves per trial; also its torch threads.
        storage: where Tune keeps its own record (results, error files); default
            ``<run folders' root>/.tune``.
        say: receives one line per finished or failed trial, with its wall time.

    Returns:
        {trial name: :func:`trial_outcome`'s ``{"status": "finished" | "error" | "stopped", "seconds": s,
        "error": one line}``}.
    """
    require_ray()
    from ray import tune

    trials = list(trials)
    if not trials:
        return {}
    by_index = dict(enumerate(trials))

    def trainable(config):
        tune.report(run_trial(by_index[config["trial"]], torch_threads=cpus_per_trial))

    started: dict = {}

    class ProgressLines(tune.Callback):
        def on_trial_start(self, iteration, trials, trial, **info):
            started[trial.trial_id] = time.time()

        def on_trial_complete(self, iteration, trials, trial, **info):
            seconds = time.time() - started.get(trial.trial_id, time.time())
            t = by_index[trial.config["trial"]]
            say(f"trial {t.name}: finished in {seconds:.1f} s")

        def on_trial_error(self, iteration, trials, trial, **info):
            seconds = time.time() - started.get(trial.trial_id, time.time())
            say(f"trial {by_index[trial.config['trial']].name}: failed after {seconds:.1f} s")

    os.environ.setdefault("RAY_AIR_NEW_OUTPUT", "0")      # with verbose=0: no status tables, our lines only
    root = storage or trials[0].run_dir.parents[2] / ".tune"
    tuner = tune.Tuner(
        tune.with_resources(trainable, {"cpu": int(cpus_per_trial)}),
        param_space={"trial": tune.grid_search(list(by_index))},
        run_config=tune.RunConfig(name=time.strftime("sweep-%Y%m%d-%H%M%S"), storage_path=str(Path(root).resolve()),
                                  verbose=0, callbacks=[ProgressLines()],
                                  failure_config=tune.FailureConfig(max_failures=0)))
    outcome = {t.name: {"status": "error", "seconds": 0.0, "error": "Ray returned no result for this trial"}
               for t in trials}
    for result in tuner.fit():
        if not result.config:            # a trial whose record Ray could not read back: stays an error
            continue
        trial = by_index[result.config["trial"]]
        outcome[trial.name] = trial_outcome(result.metrics or {}, _cause(result.error) if result.error else "",
                                            trial.timesteps)
    return outcome


STOPPED = ("stopped before its end without an error (the sweep was interrupted: Ctrl-C, SIGINT or a time "
           "limit); run the sweep again to continue from its newest checkpoint")
"""What the summary says of a trial that Tune stopped: it reported nothing and raised nothing."""


def trial_outcome(metrics: dict, error: str, timesteps: int) -> dict:
    """How one trial ended, from what Tune returned for it.

    Args:
        metrics: the trial's last report (``{"timesteps", "seconds"}``; {} when it reported nothing).
        error: the one-line cause of its exception ("" without one).
        timesteps: the agent-steps it was asked for.

    Returns:
        ``{"status", "seconds", "error"}``: ``finished`` (it reported its whole budget), ``error``
        (an exception, or a report short of the budget), or ``stopped`` (no report and no
        exception: the sweep was interrupted; the run folder resumes from its newest checkpoint).
    """
    seconds = float(metrics.get("seconds", 0.0))
    if error:
        return {"status": "error", "seconds": seconds, "error": error}
    if "timesteps" not in metrics:
        return {"status": "stopped", "seconds": seconds, "error": STOPPED}
    reached = int(metrics["timesteps"])
    if reached < timesteps:
        return {"status": "error", "seconds": seconds,
                "error": f"the trial ended at {reached:,} of its {timesteps:,} agent-steps"}
    return {"status": "finished", "seconds": seconds, "error": ""}


def evaluate_on_ray(jobs: list[dict]) -> Iterator[tuple[int, dict, float]]:
    """Evaluate comparison cells as Ray tasks of one CPU each (Ray must be connected).

    Args:
        jobs: keyword arguments of :func:`patrolsb3.evaluate.evaluate`, one dict per cell.

    Yields:
        (index of the job, its result, seconds it took), in the order the tasks finish.

    Raises:
        The first error of a task, with its cause (a bad cell stops the comparison, as it does
        when run serially; what finished before is already stored by the caller).
    """
    ray = require_ray()

    @ray.remote(num_cpus=1)
    def evaluate_cell(kwargs: dict):
        import torch

        torch.set_num_threads(1)
        begun = time.time()
        return evaluate(**kwargs), time.time() - begun

    pending = {evaluate_cell.remote(job): i for i, job in enumerate(jobs)}
    while pending:
        ready, _ = ray.wait(list(pending), num_returns=1)
        index = pending.pop(ready[0])
        try:
            result, seconds = ray.get(ready[0])
        except ray.exceptions.RayTaskError as exc:
            for ref in pending:
                ray.cancel(ref)
            raise ValueError(f"cell {jobs[index].get('strategy')} on {jobs[index].get('map_name')} "
                               f"n={jobs[index].get('n_agents')}: {_cause(exc)}") from None
        yield index, result, seconds
