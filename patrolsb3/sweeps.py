"""Training sweeps: a grid of runs read from a YAML file, each trial a normal run folder.

A sweep file (``patrolsb3 sweep SWEEP.yml``)::

    out: runs/sweep-a            # root of the run folders (--out overrides); a relative path is
                                 # relative to the working directory, as train's --out
    timesteps: 400000            # agent-steps of every trial
    recipe: zoo-stage1           # optional: named overrides (patrolsb3/sb3/recipes.py)
    set:                         # optional: --set keys applied to every trial
      n_envs: 8
    grid:                        # the product of these lists is the set of trials
      map: [A, C]
      variant: [rl-msg, rl-no-msg]
      seed: [0, 1, 2]
      set:                       # optional: any --set key, each with a list of values
        learning_rate: [3.0e-4, 1.0e-4]

Each trial trains with :func:`patrolsb3.sb3.train.train` into
``<out>/<map>/<variant>/seed<seed>[_<key>=<value>...]`` (the layout of ``patrolsb3 train --out
OUT --run-id ID``), so its folder holds what a train run holds and every tool that reads run
folders reads it. The folders are the sweep's state: a trial whose ``model.zip`` has its
agent-steps is finished and skipped, one with a checkpoint resumes from it (``--resume``), any
new one starts afresh; an existing folder with neither is reported and left alone (the sweep
deletes nothing). Running the same sweep again therefore finishes what is left and starts
nothing when all is done. Ray (``patrolsb3.distributed``) only spreads the trials over CPUs
and machines; the run folders' root is made absolute before any trial starts (Ray runs each
trial in a working directory of its own), and a trial that ends short of its agent-steps is
an error.
"""
from __future__ import annotations

import itertools
import time
from dataclasses import dataclass, field
from pathlib import Path

import yaml

from .core.maps import MapError, load_map
from .distributed import connect, require_ray, sweep_on_ray
from .outputs import check_output_dir
from .runs import RunFolder, model_steps, read_curve

SWEEP_KEYS = {"out", "timesteps", "recipe", "set", "grid"}
GRID_KEYS = {"map", "variant", "seed", "set"}


class SweepError(ValueError):
    """A sweep file that cannot be read (names the file and the problem)."""


@dataclass(frozen=True)
class Trial:
    """One run of a sweep.

    Attributes:
        map, variant, seed: what ``patrolsb3 train`` takes as --map, --variant, --seed.
        timesteps: total agent-steps.
        overrides: hyperparameter overrides (recipe, then the sweep's ``set``, then the grid's).
        varied: the grid's ``set`` values of this trial, {dotted key: value} (in its name).
        run_dir: its run folder.
        recipe: the sweep's ``recipe`` (recorded in the run's config.yml), None without one.
    """
    map: str
    variant: str
    seed: int
    timesteps: int
    overrides: dict
    varied: dict
    run_dir: Path
    recipe: str | None = None

    @property
    def name(self) -> str:
        """``<map>/<variant>/<run_id>``: how the summary and the progress lines name it."""
        return f"{self.run_dir.parent.parent.name}/{self.variant}/{self.run_dir.name}"


@dataclass
class TrialOutcome:
    """How a trial ended: ``status`` is finished, skipped (finished before), error, stopped (the
    sweep was interrupted; it resumes from its newest checkpoint) or pending."""
    trial: Trial
    status: str
    seconds: float = 0.0
    error: str = ""
    figures: dict = field(default_factory=dict)


def run_id(seed: int, varied: dict) -> str:
    """``seed<seed>`` and the varied settings, e.g. ``seed0_learning_rate=0.0003``."""
    parts = [f"seed{seed}"] + [f"{k}={_plain(v)}" for k, v in varied.items()]
    return "_".join(parts).replace("/", "-").replace(" ", "")


def _plain(value) -> str:
    return yaml.safe_dump(value, default_flow_style=True).strip().removesuffix("...").strip()


def _dotted(node: dict, prefix: str = "") -> dict:
    """``{"env": {"c_home": [0, 50]}}`` -> ``{"env.c_home": [0, 50]}``."""
    out = {}
    for key, value in node.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict):
            out.update(_dotted(value, name + "."))
        else:
            out[name] = value
    return out


def _nested(dotted: dict) -> dict:
    out: dict = {}
    for key, value in dotted.items():
        parts = key.split(".")
        node = out
        for part in parts[:-1]:
            node = node.setdefault(part, {})
        node[parts[-1]] = value
    return out


def _map_folder(map_name: str) -> str:
    """The folder name ``train`` uses for a map (its name: ``A``, or a map file's stem); a map
    that cannot be loaded keeps its text (:func:`check_trial` reports why)."""
    try:
        return load_map(map_name).name
    except (MapError, ValueError, OSError):
        return Path(map_name).name.replace(" ", "_")


def read_sweep(path, out=None, precision: str | None = None) -> list[Trial]:
    """The trials of a sweep file, in grid order.

    Args:
        path: the YAML sweep file (module docstring).
        out: the root of the run folders (default: the file's ``out``).
        precision: the training precision of every trial (``--precision``), over the file's.

    Raises:
        SweepError: not YAML, an unknown key, a grid value that is not a non-empty list, no
            ``timesteps`` or no ``out`` (one line naming the file and the key).
    """
    from .sb3.hyperparams import merge
    from .sb3.recipes import recipe
    path = Path(path)
    try:
        spec = yaml.safe_load(path.read_text())
    except FileNotFoundError:
        raise SweepError(f"{path}: no such sweep file") from None
    except (yaml.YAMLError, UnicodeDecodeError) as exc:
        raise SweepError(f"{path}: not valid YAML ({str(exc).splitlines()[0]})") from None
    if not isinstance(spec, dict):
        raise SweepError(f"{path}: expected a mapping with grid, timesteps and out")
    if unknown := sorted(set(spec) - SWEEP_KEYS):
        raise SweepError(f"{path}: unknown key(s) {unknown}; known: {sorted(SWEEP_KEYS)}")
    grid = spec.get("grid")
    if not isinstance(grid, dict) or not grid:
        raise SweepError(f"{path}: 'grid' must be a mapping of lists (map, variant, seed, set)")
    if unknown := sorted(set(grid) - GRID_KEYS):
        raise SweepError(f"{path}: unknown grid key(s) {unknown}; known: {sorted(GRID_KEYS)}")
    timesteps = spec.get("timesteps")
    if isinstance(timesteps, bool) or not isinstance(timesteps, int) or timesteps < 1:
        raise SweepError(f"{path}: 'timesteps' must be a whole number of agent-steps >= 1, got {timesteps!r}")
    root = out if out is not None else spec.get("out")
    if not root:
        raise SweepError(f"{path}: no 'out' folder (give it in the file or with --out)")
    root = Path(root).expanduser().absolute()          # the working directory's, before Ray moves it
    fixed = spec.get("set") or {}
    grid_set = grid.get("set") or {}
    if not isinstance(fixed, dict) or not isinstance(grid_set, dict):
        raise SweepError(f"{path}: 'set' must be a mapping of hyperparameters")
    axes = {"map": grid.get("map", ["A"]), "variant": grid.get("variant", ["rl-msg"]),
            "seed": grid.get("seed", [0]), **_dotted(grid_set)}
    for key, values in axes.items():
        if not isinstance(values, list) or not values:
            raise SweepError(f"{path}: grid value of {key!r} must be a non-empty list, got {values!r}")
    for seed in axes["seed"]:
        if isinstance(seed, bool) or not isinstance(seed, int):
            raise SweepError(f"{path}: grid seeds must be whole numbers, got {seed!r}")
    base = recipe(spec["recipe"]) if spec.get("recipe") else {}
    base = merge(base, fixed)
    if precision is not None:
        base = merge(base, {"precision": precision})
    trials = []
    for combo in itertools.product(*axes.values()):
        values = dict(zip(axes, combo))
        varied = {k: values[k] for k in axes if k not in ("map", "variant", "seed")}
        map_name, variant, seed = str(values["map"]), str(values["variant"]), int(values["seed"])
        trials.append(Trial(map=map_name, variant=variant, seed=seed, timesteps=int(timesteps),
                            overrides=merge(base, _nested(varied)), varied=varied,
                            run_dir=Path(root) / _map_folder(map_name) / variant / run_id(seed, varied),
                            recipe=spec.get("recipe")))
    names = [t.run_dir for t in trials]
    if len(set(names)) != len(names):
        raise SweepError(f"{path}: two trials share a run folder (repeated grid values?)")
    return trials


def check_trial(trial: Trial) -> str:
    """'' when every setting of the trial is valid, else the one-line reason (what ``train``
    would refuse before any work), so a bad trial fails alone before the sweep starts."""
    from .sb3.hyperparams import merge
    from .sb3.train import resolve_settings
    try:
        resolve_settings(trial.map, trial.variant, merge(trial.overrides, {"timesteps": trial.timesteps}))
    except (ValueError, TypeError, MapError, FileNotFoundError) as exc:
        return str(exc)
    return ""


def trial_state(trial: Trial) -> str:
    """finished (model.zip at its agent-steps), resumable (a valid checkpoint), new (no folder,
    or an empty one) or blocked (a folder with files but nothing to resume: never replaced)."""
    run = RunFolder(trial.run_dir)
    if run.model_file.is_file() and (model_steps(run.model_file) or 0) >= trial.timesteps:
        return "finished"
    if run.newest_checkpoint() is not None:
        return "resumable"
    return "blocked" if run.has_files() else "new"


BLOCKED = ("its run folder {} exists with files but no checkpoint to resume; the sweep does not replace it "
           "(move it away or delete it, then run the sweep again)")


def run_trial(trial: Trial, torch_threads: int = 1) -> dict:
    """Train one trial to its agent-steps (resuming its folder when it has a checkpoint; a
    folder without one, left by a run killed at its start, is started afresh).

    Returns:
        {"timesteps": agent-steps reached, "seconds": wall time of this call}.
    """
    from .sb3.hyperparams import merge
    from .sb3.train import train
    started = time.time()
    state = trial_state(trial)
    if state == "blocked":
        raise ValueError(BLOCKED.format(trial.run_dir))
    if state == "new" and trial.run_dir.exists():     # empty but for a lock file: train makes it again
        (trial.run_dir / RunFolder.LOCK).unlink(missing_ok=True)
        trial.run_dir.rmdir()
    if state != "finished":
        hyperparams = merge({"torch_threads": int(torch_threads)}, trial.overrides)
        train(map=trial.map, variant=trial.variant, timesteps=trial.timesteps, seed=trial.seed,
              run_dir=trial.run_dir, resume=state == "resumable", hyperparams=hyperparams,
              progress_bar=False, device="cpu", recipe=trial.recipe,
              command=f"patrolsb3 sweep (trial {trial.name}, {trial.timesteps} agent-steps)")
    return {"timesteps": model_steps(RunFolder(trial.run_dir).model_file) or 0,
            "seconds": round(time.time() - started, 1)}


def run_sweep(path, out=None, precision: str | None = None, address: str | None = None, cpus: int | None = None, cpus_per_trial: int = 1,
              dry_run: bool = False, say=print) -> list[TrialOutcome]:
    """A sweep from its file to its outcomes (what ``patrolsb3 sweep`` runs).

    Every trial is checked first (a refused one fails alone, before anything starts); finished
    trials are skipped; the rest run as Ray Tune trials (:func:`patrolsb3.distributed.sweep_on_ray`).

    Args:
        path: the sweep file (module docstring).
        out: root of the run folders (default: the file's ``out``).
        precision: the training precision of every trial (default: the file's or the YAML's).
        address: a Ray cluster to join; None starts Ray on this machine.
        cpus: CPUs a local Ray may use (default: all).
        cpus_per_trial: CPUs (and torch threads) per trial.
        dry_run: only list the trials and their state.
        say: receives the progress lines.

    Returns:
        One :class:`TrialOutcome` per trial, in grid order.

    Raises:
        SweepError: a sweep file that cannot be read.
        ValueError: bad CPU counts, an output folder that cannot be written, or Ray missing
            when trials are to run (one line saying how to install it).
    """
    if isinstance(cpus_per_trial, bool) or not isinstance(cpus_per_trial, int) or cpus_per_trial < 1:
        raise ValueError(f"cpus_per_trial must be a whole number >= 1, got {cpus_per_trial!r}")
    if cpus is not None and (isinstance(cpus, bool) or not isinstance(cpus, int) or cpus < 1 or address):
        raise ValueError(f"cpus must be a whole number >= 1, for a local Ray only (not with an address), got {cpus!r}")
    trials = read_sweep(path, out=out, precision=precision)
    check_output_dir(trials[0].run_dir.parents[2], "--out")
    outcomes = {t.name: TrialOutcome(t, "pending") for t in trials}
    to_run, resuming = [], 0
    for t in trials:
        problem = check_trial(t)
        if problem:
            outcomes[t.name] = TrialOutcome(t, "error", error=problem)
            say(f"trial {t.name}: refused before it started: {problem}")
            continue
        state = trial_state(t)          # reads (and checks) its checkpoints once
        if state == "blocked":
            outcomes[t.name] = TrialOutcome(t, "error", error=BLOCKED.format(t.run_dir))
            say(f"trial {t.name}: refused before it started: {BLOCKED.format(t.run_dir)}")
        elif state == "finished":
            outcomes[t.name] = TrialOutcome(t, "skipped")
        else:
            to_run.append(t)
            resuming += state == "resumable"
    skipped = sum(o.status == "skipped" for o in outcomes.values())
    say(f"sweep {path}: {len(trials)} trials, {skipped} finished before, {len(to_run)} to run"
        + (f" ({resuming} resume from a checkpoint)" if to_run else ""))
    if to_run and not dry_run:
        require_ray()
        available = connect(address, cpus).get("CPU", 0)
        say(f"ray: {available:.0f} CPUs, {cpus_per_trial} per trial")
        for name, result in sweep_on_ray(to_run, run_trial, cpus_per_trial, say=say).items():
            outcomes[name] = TrialOutcome(outcomes[name].trial, result["status"], result["seconds"], result["error"])
    return list(outcomes.values())


def last_figures(trial: Trial, episodes: int = 20) -> dict:
    """The mean of the last ``episodes`` rows of the trial's curve.csv: reward, mean and max
    idleness, battery failures ({} without a curve)."""
    path = RunFolder(trial.run_dir).curve_file
    columns = read_curve(path) if path.is_file() else {}
    if not columns:
        return {}
    keys = ("reward", "mean_idleness", "max_idleness", "battery_failures")
    return {k: float(columns[k][-episodes:].mean()) for k in keys}


def summary_table(outcomes: list[TrialOutcome]) -> str:
    """A markdown table: trial, status, final agent-steps, last curve figures, time, error."""
    lines = ["| trial | status | agent-steps | reward | mean idleness | max idleness | battery failures "
             "| seconds | error |", "|---|---|---|---|---|---|---|---|---|"]
    for o in outcomes:
        run = RunFolder(o.trial.run_dir)
        model = run.newest_model()
        steps = (model_steps(model) or 0) if model is not None else 0
        f = o.figures or last_figures(o.trial)
        cells = [f"{f[k]:.1f}" if k in f else "" for k in ("reward", "mean_idleness", "max_idleness")]
        cells.append(f"{f['battery_failures']:.2f}" if "battery_failures" in f else "")
        lines.append(f"| {o.trial.name} | {o.status} | {steps:,} | {' | '.join(cells)} | {o.seconds:.0f} "
                     f"| {o.error.splitlines()[0][:200] if o.error else ''} |")
    return "\n".join(lines)
