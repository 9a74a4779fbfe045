"""The folders the commands write, owned here: their layout, names and files. A training run's
folder (:class:`RunFolder`), a zoo entry's (:class:`ZooEntry`) and a comparison's
(:class:`ComparisonFolder`).

Run folder ``<out>/<map>/<variant>/<run_id>/`` (:class:`RunFolder`)::

    model.zip          final model (SB3 zip)
    checkpoints/       model_<agent-steps>_steps.zip every ``checkpoint_freq`` agent-steps, and
                       model_vecnormalize_<agent-steps>_steps.pkl (reward statistics) beside each
    config.yml         env config, map name and shape, hyperparameters, versions (CONFIG_SCHEMA)
    command.txt        the command line(s) that made / resumed the run
    curve.csv          one row per finished parallel episode (learning curve)
    cpu_time.csv       CPU seconds spent by agent-steps reached (``patrolsb3.sb3.cpu_time``)
    eval.csv           periodic evaluation on the paper metrics at 1..max_agents agents
    tb/                TensorBoard logs (SB3 logger)

Every file is written atomically (:func:`write_atomically`: a hidden ``.partial/`` copy, then a
rename), CSV row blocks included (:func:`append_csv_rows`), so a run killed at any moment
leaves each file whole: as it was before the write, or with the whole block. ``--resume`` takes
the newest *valid* checkpoint (:meth:`RunFolder.newest_checkpoint`) and cuts the three CSV
files back to it (:meth:`RunFolder.cut_back_to`). ``sb3/train.py``, ``sb3/cpu_time.py``,
``sb3/callbacks.py`` and the ``zoo`` package reach the folder through here only.

Zoo entry ``zoo/<MAP>/<variant>/seed<k>/`` (:class:`ZooEntry`): a run's ``model.zip`` (the
policy only), ``config.yml``, ``command.txt``, ``curve.csv``, ``cpu_time.csv``, and its
figures ``eval.json`` (``zoo eval``), ``listening.json`` and ``ablation.json``; the variant
folder's ``default.yml`` names the default seed. Comparison ``<out>/`` (:class:`ComparisonFolder`):
``results.json`` (every result, written as each finishes), ``results.csv`` (every figure with its
interval), ``episodes.csv`` (the per-episode values the claims pair) and ``report.md``.
"""
from __future__ import annotations

import csv
import json
import os
import re
import shutil
import zipfile
from pathlib import Path

import yaml

from .locks import hold

CHECKPOINT_RE = re.compile(r"model_(\d+)_steps\.zip$")
"""A checkpoint's file name: ``checkpoints/model_<agent-steps>_steps.zip`` (SB3's CheckpointCallback)."""


class RunFolderBusy(ValueError):
    """A run folder another process is writing (:meth:`RunFolder.lock`)."""


class ConfigError(ValueError):
    """A config.yml that cannot be read (not YAML, not a mapping)."""


CONFIG_SCHEMA = {"map": str, "map_source": str, "map_text": str, "map_shape": list, "variant": str, "algo": str, "seed": int,
                 "timesteps": int, "env": dict, "hyperparams": dict, "versions": dict, "init_from": dict,
                 "env_version": str, "date": str, "source_model": str, "source_run": str, "budget": dict,
                 "recipe": str, "precision_changes": list}
"""The keys a run's (or a zoo entry's) config.yml may hold, with their types: the train's own
(map .. versions, init_from for a warm start, recipe: the ``--recipe`` it was given,
precision_changes: the resumes that went on in another precision, each ``{timesteps,
precision, why}``) and those ``zoo export`` adds."""


def read_config(path: Path) -> dict:
    """A config.yml as a dict, checked against :data:`CONFIG_SCHEMA`.

    Raises:
        ConfigError: not valid YAML, not a mapping, a key the schema does not know or a value of
            the wrong type (names the file and the problem).
    """
    try:
        config = yaml.safe_load(Path(path).read_text())
    except yaml.YAMLError as exc:
        raise ConfigError(f"{path}: not valid YAML ({str(exc).splitlines()[0]})") from None
    if config is None:
        return {}
    if not isinstance(config, dict):
        raise ConfigError(f"{path}: expected a mapping of settings, got {type(config).__name__}")
    unknown = sorted(set(config) - set(CONFIG_SCHEMA))
    if unknown:
        raise ConfigError(f"{path}: settings this code does not know: {unknown}")
    for key, kind in CONFIG_SCHEMA.items():
        if key in config and config[key] is not None and not isinstance(config[key], kind):
            raise ConfigError(f"{path}: {key} must be of type {kind.__name__}, got {config[key]!r}")
    return config


def recorded_path(path) -> str:
    """How a record (config.yml, a command's output, a checkpoint's TensorBoard folder) names a
    file: relative to the working directory when it lies under it (a run started from the
    repository root names its source as ``runs/...``, no path of this machine), else resolved
    and absolute. "Under it" is judged before symbolic links are followed, then after: a
    worktree whose ``runs/`` links to another checkout's still records ``runs/...``."""
    path = Path(path)
    cwd = Path.cwd()
    for candidate, base in ((Path(os.path.abspath(path)), Path(os.path.abspath(cwd))), (path.resolve(), cwd.resolve())):
        try:
            return str(candidate.relative_to(base))
        except ValueError:
            continue
    return str(path.resolve())


def relative_tensorboard_log(model_zip, folder: str) -> None:
    """Write ``folder`` as the TensorBoard folder an SB3 checkpoint records (its ``data``
    member's ``tensorboard_log``), where it records an absolute path; every other member stays
    byte for byte. A resume sets the folder anew (``train``), so this only keeps the path of the
    machine that wrote it out of a copy that travels (:meth:`RunFolder.snapshot`)."""
    path = Path(model_zip)
    with zipfile.ZipFile(path) as source:
        members = [(info, source.read(info)) for info in source.infolist()]
    changed = False
    for i, (info, payload) in enumerate(members):
        if info.filename == "data":
            data = json.loads(payload)
            if isinstance(data.get("tensorboard_log"), str) and os.path.isabs(data["tensorboard_log"]):
                data["tensorboard_log"] = str(folder)
                members[i] = (info, json.dumps(data, indent=4).encode())
                changed = True
    if changed:
        def write(partial: Path) -> None:
            with zipfile.ZipFile(partial, "w") as out:
                for info, payload in members:
                    out.writestr(info, payload)
        write_atomically(path, write)


def zip_is_intact(path) -> bool:
    """True for a non-empty zip whose every member passes its CRC check (a model file)."""
    import zipfile
    path = Path(path)
    try:
        if path.stat().st_size == 0:
            return False
        with zipfile.ZipFile(path) as archive:
            return archive.testzip() is None
    except (OSError, zipfile.BadZipFile, EOFError):
        return False


def is_valid_model_file(path) -> bool:
    """True for a readable SB3 algorithm zip: intact (:func:`zip_is_intact`) with a ``data``
    record (a run killed while writing leaves an empty or cut file; flipped bytes fail the CRC)."""
    import zipfile
    if not zip_is_intact(path):
        return False
    with zipfile.ZipFile(path) as archive:
        return "data" in archive.namelist()


def append_csv_rows(path, fields, rows) -> None:
    """Append a block of dict rows to a CSV (the header first when the file is new), atomically:
    the file with the block is written beside it and renamed over it, so a kill leaves the file
    with the whole block or without it, never a cut line.

    Args:
        path: the CSV file.
        fields: its columns (keys of ``rows`` not among them are left out).
        rows: the rows to append (none: the file is only created with its header).
    """
    import csv
    import shutil
    path = Path(path)

    def write(partial: Path) -> None:
        new = not path.is_file()
        if not new:
            shutil.copyfile(path, partial)
        with partial.open("a" if not new else "w", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=list(fields), extrasaction="ignore")
            if new:
                writer.writeheader()
            writer.writerows(rows)
    if rows or not path.is_file():
        write_atomically(path, write)


def trim_rows(path, timesteps: int) -> int:
    """Cut a run's CSV (curve.csv, eval.csv) back to the rows at or before ``timesteps`` (the
    checkpoint a resume starts from), dropping a cut last line; rewritten atomically. Returns the
    rows kept (0 when the file does not exist)."""
    import csv
    path = Path(path)
    if not path.is_file():
        return 0
    with path.open(newline="") as f:
        reader = csv.reader(f)
        header = next(reader, None)
        if header is None or "timesteps" not in header:
            return 0
        column = header.index("timesteps")
        kept = []
        for row in reader:
            try:
                if len(row) == len(header) and int(row[column]) <= timesteps:
                    kept.append(row)
            except ValueError:          # a line cut by a kill
                continue
    def write(partial: Path) -> None:
        with partial.open("w", newline="") as f:
            writer = csv.writer(f)
            writer.writerow(header)
            writer.writerows(kept)
    write_atomically(path, write)
    return len(kept)


def read_curve(path) -> dict:
    """A run's curve.csv (or an entry's) as columns: {column: (N,) float array}, one row per
    finished training episode; {} for a curve with its header only.

    Raises:
        ValueError: a file that is cut, damaged or not a curve (names it and the row).
    """
    import numpy as np
    path = Path(path)
    try:
        with path.open(newline="") as handle:
            reader = csv.DictReader(handle)
            if reader.fieldnames is None or "timesteps" not in reader.fieldnames:
                raise ValueError(f"no timesteps column (columns {reader.fieldnames})")
            rows = list(reader)
            columns = {key: np.array([float(r[key]) for r in rows]) for key in reader.fieldnames}
    except (ValueError, TypeError, UnicodeDecodeError, csv.Error) as exc:
        raise ValueError(f"{path}: not a curve.csv of 'patrolsb3 train', or cut or damaged ({exc})") from None
    return columns if rows else {}


def write_atomically(path, write) -> Path:
    """``write(partial_path)`` into a hidden ``.partial/`` folder beside ``path`` under the same
    file name (so writers that derive content from the name, like torch's zip archives, write
    the same bytes), then a rename over ``path``: a kill during the write leaves the old file
    (or none), never a cut one.

    Args:
        path: the file to (re)write.
        write: a function that writes the whole file at the path it is given.
    """
    import os
    path = Path(path)
    folder = path.parent / ".partial"
    folder.mkdir(parents=True, exist_ok=True)
    partial = folder / path.name
    write(partial)
    os.replace(partial, path)
    try:
        folder.rmdir()                  # left only while a write is under way (or was killed)
    except OSError:
        pass
    return path


def model_steps(model_path) -> int | None:
    """Agent-steps a model file was saved at: from a checkpoint's name
    (``model_<steps>_steps.zip``), else from the SB3 zip's own ``data`` record (a run's
    ``model.zip``); None when neither tells."""
    model_path = Path(model_path)
    if m := CHECKPOINT_RE.search(model_path.name):
        return int(m.group(1))
    try:
        with zipfile.ZipFile(model_path) as archive:
            return int(json.loads(archive.read("data"))["num_timesteps"])
    except (OSError, KeyError, ValueError, zipfile.BadZipFile):
        return None


def _in_folder(name: str) -> property:
    """A read-only path attribute: the folder's file whose name is the class attribute ``name``."""
    return property(lambda self: self.path / getattr(self, name), doc=f"``<folder>/<{name}>``.")


class RunFolder:
    """The files of one training run (layout in the module docstring): their paths, the
    checkpoints, config.yml through :data:`CONFIG_SCHEMA`, the CSV records and their cut back
    on resume.

    Args:
        path: the run folder (need not exist yet).
    """

    CONFIG, MODEL, COMMAND = "config.yml", "model.zip", "command.txt"
    CURVE, EVAL, CPU_TIME = "curve.csv", "eval.csv", "cpu_time.csv"
    CHECKPOINTS, TENSORBOARD = "checkpoints", "tb"
    STATISTICS = "model_vecnormalize_{}_steps.pkl"
    """Reward-normalisation statistics beside each checkpoint (SB3's CheckpointCallback name)."""
    RECORDS = (CURVE, EVAL, CPU_TIME)
    """The CSV files keyed by agent-steps, cut back to the checkpoint a resume starts from."""

    def __init__(self, path):
        self.path = Path(path)

    def __repr__(self) -> str:
        return f"RunFolder({str(self.path)!r})"

    def __eq__(self, other) -> bool:
        return isinstance(other, RunFolder) and other.path == self.path

    def __hash__(self) -> int:
        return hash(self.path)

    @classmethod
    def of_model(cls, model_path) -> "RunFolder":
        """The run folder of a model file: ``<run>/checkpoints/model_<steps>_steps.zip`` or
        ``<run>/model.zip``."""
        model_path = Path(model_path)
        return cls(model_path.parent.parent if model_path.parent.name == cls.CHECKPOINTS else model_path.parent)

    # -- paths ---------------------------------------------------------------------------------
    config_file = _in_folder("CONFIG")
    model_file = _in_folder("MODEL")
    command_file = _in_folder("COMMAND")
    curve_file = _in_folder("CURVE")
    eval_file = _in_folder("EVAL")
    cpu_time_file = _in_folder("CPU_TIME")
    checkpoints_dir = _in_folder("CHECKPOINTS")
    tensorboard_dir = _in_folder("TENSORBOARD")
    def checkpoint_file(self, timesteps: int) -> Path:
        """``checkpoints/model_<timesteps>_steps.zip``."""
        return self.checkpoints_dir / f"model_{int(timesteps)}_steps.zip"

    def statistics_file(self, timesteps: int) -> Path:
        """The reward statistics saved with the checkpoint of ``timesteps``."""
        return self.checkpoints_dir / self.STATISTICS.format(int(timesteps))

    LOCK = ".lock"
    """The lock file of the process writing the run (:meth:`lock`); not part of the run."""

    # -- state ---------------------------------------------------------------------------------
    def has_files(self) -> bool:
        """True when the folder exists and holds anything but its lock file (a new run must not
        write into it)."""
        return self.path.is_dir() and any(p.name != self.LOCK for p in self.path.iterdir())

    def lock(self):
        """Hold the run folder for this process: a ``filelock`` lock on ``<run>/.lock``, held
        until it is released (``with folder.lock(): ...`` or ``.release()``), or the process ends.

        Raises:
            RunFolderBusy: another process holds it (one line naming the folder).
        """
        self.path.mkdir(parents=True, exist_ok=True)
        try:
            return hold(self.path / self.LOCK, f"{self.path} is being written by another process (a train, sweep "
                                               f"or resume of the same run); wait for it to end, or use another --run-id")
        except ValueError as exc:
            raise RunFolderBusy(str(exc)) from None

    def create(self) -> None:
        """Make the folder and its checkpoints folder."""
        self.checkpoints_dir.mkdir(parents=True, exist_ok=True)

    def checkpoints(self) -> list[Path]:
        """The checkpoints ``checkpoints/model_<steps>_steps.zip``, fewest steps first (valid
        or not)."""
        found = sorted((int(m.group(1)), p) for p in self.checkpoints_dir.glob("model_*_steps.zip")
                       if (m := CHECKPOINT_RE.search(p.name)))
        return [p for _, p in found]

    def newest_checkpoint(self, skipped: list | None = None) -> Path | None:
        """The valid checkpoint with the most agent-steps, or None.

        Args:
            skipped: a list that receives the newer checkpoints passed over as invalid (empty,
                cut or corrupt).
        """
        for path in reversed(self.checkpoints()):
            if is_valid_model_file(path):
                return path
            if skipped is not None:
                skipped.append(path)
        return None

    def newest_model(self) -> Path | None:
        """``model.zip`` when the run finished, else its newest valid checkpoint, else None."""
        return self.model_file if self.model_file.is_file() else self.newest_checkpoint()

    def snapshot(self, dest, keep: int = 1, milestones=(), chosen=None) -> Path:
        """Copy what ``--resume`` needs into a new run folder ``dest``: the newest valid checkpoint
        (the model with its optimizer state) and its reward statistics, config.yml, command.txt
        and the CSV records; TensorBoard logs and, unless ``keep`` asks for them, older
        checkpoints are left behind. Used to carry a stopped run to another machine
        (``zoo/snapshot_run.sh``).

        Args:
            dest: the snapshot's folder; replaced if it exists.
            keep: how many of the newest valid checkpoints to copy, each with its statistics
                (default 1, all that ``--resume`` reads). A run stopped near its end keeps more,
                so that choosing a checkpoint by validation (``zoo validate --last 6``) still
                sees those written before the stop.
            milestones: agent-steps whose checkpoints are kept too, where the run has them (a run
                evaluated along the way, e.g. issue 43's E2 at the zoo's budget of 16 M and at 32 M).
            chosen: the checkpoint that validation chose (``zoo validate RUN --last 6``), a file of
                this run. Needed to snapshot a *finished* run: the snapshot then keeps ``model.zip``,
                the chosen checkpoint and the milestones (not the newest ``keep``), which is all
                that exporting the run later reads (issue 43's E1 finishes sessions before E2, and
                nothing is exported before the rule has chosen). For a stopped run it is kept
                beside the newest ones.

        Returns:
            The newest checkpoint copied, in ``dest`` (``model.zip`` for a finished run whose
            final model was chosen and which keeps no milestone).

        Raises:
            ValueError: ``keep`` is below 1, or ``chosen`` is not a valid checkpoint of this run.
            FileNotFoundError: no valid checkpoint, or the statistics file of one to copy is
                missing in a run that normalises its rewards (names it).
            FileExistsError: the run has finished (``model.zip``) and no ``chosen`` checkpoint is
                given: a snapshot would drop the older checkpoints that choosing one reads.
        """
        if isinstance(keep, bool) or not isinstance(keep, int) or keep < 1:
            raise ValueError(f"keep: {keep!r} is not a whole number of checkpoints >= 1")
        finished = self.model_file.is_file()
        if finished and chosen is None:
            raise FileExistsError(
                f"{self.path}: finished (model.zip), nothing to resume; a snapshot keeps only the newest checkpoints, "
                "so validate and export the run (zoo/finish_paper_run.sh) while its checkpoints are there, "
                "or pass the checkpoint validation chose (chosen=)")
        valid = [p for p in reversed(self.checkpoints()) if is_valid_model_file(p)]     # newest first
        chosen_model = chosen is not None and finished and Path(chosen).resolve() == self.model_file.resolve()
        if chosen is not None and not chosen_model and Path(chosen).resolve() not in {p.resolve() for p in valid}:
            raise ValueError(f"chosen: {chosen} is not a valid checkpoint of {self.path}")
        if not valid:
            raise FileNotFoundError(f"{self.path}: no valid checkpoint to snapshot")
        wanted = {int(m) for m in milestones} | ({model_steps(chosen)} if chosen and not chosen_model else set())
        newest = [] if finished else valid[:keep]
        kept = newest + [p for p in valid if p not in newest and model_steps(p) in wanted]
        # a run that normalises its rewards is resumed with the statistics beside its checkpoint
        normalized = not self.config_file.is_file() or bool(
            (self.read_config().get("hyperparams") or {}).get("normalize_reward", True))
        sources = []
        for checkpoint in kept:
            statistics = self.statistics_file(model_steps(checkpoint))
            if statistics.is_file():
                sources.append(statistics)
            elif normalized:
                raise FileNotFoundError(f"{statistics}: missing (a checkpoint is resumed with its statistics)")
            sources.append(checkpoint)
        target = RunFolder(dest)
        if target.path.exists():
            shutil.rmtree(target.path)
        target.create()
        for source in sources:
            shutil.copy2(source, target.checkpoints_dir / source.name)
            if source.suffix == ".zip":      # no path of this machine travels inside a checkpoint
                relative_tensorboard_log(target.checkpoints_dir / source.name, recorded_path(self.tensorboard_dir))
        names = (self.MODEL,) if finished else ()
        for name in names + (self.CONFIG, self.COMMAND) + self.RECORDS:
            if (self.path / name).is_file():
                shutil.copy2(self.path / name, target.path / name)
        if finished:
            relative_tensorboard_log(target.model_file, recorded_path(self.tensorboard_dir))
        if not kept:            # a finished run whose final model validation chose, no milestones
            return target.model_file
        return target.checkpoints_dir / max(kept, key=model_steps).name

    # -- config and command --------------------------------------------------------------------
    def read_config(self) -> dict:
        """config.yml, checked (:func:`read_config`); {} when the folder has none."""
        return read_config(self.config_file) if self.config_file.is_file() else {}

    def write_config(self, config: dict) -> None:
        """Write config.yml (atomically), refusing keys outside :data:`CONFIG_SCHEMA`."""
        unknown = sorted(set(config) - set(CONFIG_SCHEMA))
        if unknown:
            raise ConfigError(f"{self.config_file}: settings this code does not know: {unknown}")
        text = yaml.safe_dump(config, sort_keys=False)
        write_atomically(self.config_file, lambda partial: partial.write_text(text))

    def record_precision_change(self, change: dict) -> None:
        """Add ``{timesteps, precision, why}`` to config.yml's ``precision_changes``: from those
        agent-steps on, the run trained in that precision."""
        config = self.read_config()
        config["precision_changes"] = (config.get("precision_changes") or []) + [change]
        self.write_config(config)

    def record_command(self, command: str) -> None:
        """Append a command line to command.txt (atomically)."""
        import shutil

        def write(partial: Path) -> None:
            if self.command_file.is_file():
                shutil.copyfile(self.command_file, partial)
            with partial.open("a") as f:
                f.write(command.rstrip("\n") + "\n")
        write_atomically(self.command_file, write)

    # -- records -------------------------------------------------------------------------------
    def cut_back_to(self, timesteps: int) -> None:
        """Cut curve.csv, eval.csv and cpu_time.csv back to the rows at or before ``timesteps``
        (the checkpoint a resume starts from), and config.yml's ``precision_changes`` to those
        before it: the abandoned stretch after it goes."""
        for name in self.RECORDS:
            trim_rows(self.path / name, timesteps)
        config = self.read_config()
        changes = config.get("precision_changes") or []
        if any(c["timesteps"] >= timesteps for c in changes):
            config["precision_changes"] = [c for c in changes if c["timesteps"] < timesteps]
            self.write_config(config)


class ZooEntry(RunFolder):
    """The files of one zoo entry folder (module docstring): a run's names, and its figures.

    Args:
        path: the entry folder (need not exist yet).
    """

    EVALUATION, LISTENING, ABLATION = "eval.json", "listening.json", "ablation.json"
    FIGURES = (EVALUATION, LISTENING, ABLATION)
    DEFAULT = "default.yml"
    """In the variant folder above the seeds: ``{seed: k, chosen_by: ...}``."""

    def __repr__(self) -> str:
        return f"ZooEntry({str(self.path)!r})"

    evaluation_file = _in_folder("EVALUATION")
    listening_file = _in_folder("LISTENING")
    ablation_file = _in_folder("ABLATION")

class ComparisonFolder:
    """The files of a comparison's ``--out`` folder (``patrolsb3 compare``, read by ``claims``).

    Args:
        path: the folder (need not exist yet).
    """

    RESULTS_JSON, RESULTS_CSV, EPISODES_CSV, REPORT = "results.json", "results.csv", "episodes.csv", "report.md"

    def __init__(self, path):
        self.path = Path(path)

    results_json = _in_folder("RESULTS_JSON")
    results_csv = _in_folder("RESULTS_CSV")
    episodes_csv = _in_folder("EPISODES_CSV")
    report = _in_folder("REPORT")
