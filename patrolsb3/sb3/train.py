"""``train()``: one parameter-shared training run, its run folder, and ``--resume``.

The run folder's layout, files and resume rules belong to :class:`patrolsb3.runs.RunFolder`;
``train()`` checks every setting, builds the model, makes the folder, learns and saves, in
that order (a setting refused leaves no folder behind).

Timesteps count agent-steps: vec-env rows (parallel episodes x max_agents slots) x env steps
(two env steps per simulator step with same-step messages). Discounts are per simulator step
in the hyperparameters and converted per env step (``gamma ** (1 / phases_per_step)``).
"""
from __future__ import annotations

import math
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from stable_baselines3.common.callbacks import CallbackList, CheckpointCallback
from stable_baselines3.common.vec_env import VecNormalize

from .. import __version__
from ..core.config import ENV_VERSION, EnvConfig, make_config
from ..core.maps import is_shipped, load_map, source_label
from ..runs import RunFolder, is_valid_model_file, model_steps, recorded_path, write_atomically
from .algorithms import DEFAULT_ALGORITHM, get_algorithm, torch_device
from .callbacks import LearningCurveCallback, PaperMetricsEvalCallback
from .cpu_time import CpuTimeCallback, cpu_hours_of, read_rows, restart_at
from .curriculum import CURRICULUM, CurriculumCallback
from .hyperparams import load_hyperparams, merge, per_phase, schedule
from .policy import policy_kwargs_for
from .precision import PRECISIONS, resolve_precision, resumed_precision, warned_if_emulated
from .variants import variant_overrides
from .vec_env import DEFAULT_AGENTS, make_vec_env, training_config

COMMUNICATION_KEYS = ("ent_coef_message", "signal_coef", "listen_coef", "message_team_share")
"""Optional coefficients of MaskableRecurrentPPO for learned messages (None: off)."""
ALGO_KEYS = ("learning_rate", "n_steps", "n_epochs", "gamma", "gae_lambda", "clip_range", "ent_coef",
             "vf_coef", "max_grad_norm", "n_minibatches", "batch_size", "policy_kwargs", "target_kl",
             *COMMUNICATION_KEYS)
RUN_KEYS = ("algo", "timesteps", "n_envs", "curriculum", "env", "checkpoint_freq", "eval_freq",
            "eval_episode_steps", "eval_episodes", "torch_threads", "normalize_reward", "mix", "precision")


def curriculum_teams(n_envs: int, max_agents: int, curriculum=CURRICULUM) -> list[list[int]]:
    """The curriculum for ``n_envs`` parallel episodes: the paper's 8 columns sampled evenly
    (first and last kept) and team sizes capped at ``max_agents``."""
    width = len(curriculum[0])
    index = [0] if n_envs == 1 else [round(i * (width - 1) / (n_envs - 1)) for i in range(n_envs)]
    return [[min(int(row[i]), max_agents) for i in index] for row in curriculum]


def save_atomically(model, path) -> Path:
    """``model.save`` under a temporary name beside ``path``, then a rename: a kill during the
    write leaves no file with the checkpoint's name."""
    return write_atomically(path, model.save)


def save_statistics_atomically(vec_normalize, path) -> Path:
    """``VecNormalize.save`` the same way (temporary name, then a rename)."""
    return write_atomically(path, lambda partial: vec_normalize.save(str(partial)))


class AtomicCheckpointCallback(CheckpointCallback):
    """SB3's CheckpointCallback with atomic writes under the run folder's names: the reward
    statistics first, then the model (a checkpoint whose model file exists has its statistics).

    Args:
        save_freq: calls (vector-env steps) between checkpoints.
        run: the run folder.
    """

    def __init__(self, save_freq: int, run: RunFolder, verbose: int = 0):
        super().__init__(save_freq=save_freq, save_path=str(run.checkpoints_dir), name_prefix="model",
                         save_vecnormalize=True, verbose=verbose)
        self.run = run

    def _on_step(self) -> bool:
        if self.n_calls % self.save_freq == 0:
            save_checkpoint(self.model, self.run)
        return True


def save_checkpoint(model, run: RunFolder) -> Path:
    """The model's checkpoint at its agent-steps, its reward statistics first (if any)."""
    normalize = model.get_vec_normalize_env()
    if normalize is not None:
        save_statistics_atomically(normalize, run.statistics_file(model.num_timesteps))
    return save_atomically(model, run.checkpoint_file(model.num_timesteps))


def versions() -> dict:
    """Versions of the packages a checkpoint depends on."""
    import sb3_contrib
    import stable_baselines3
    import torch

    return {"patrolsb3": str(__version__), "env_version": str(ENV_VERSION),
            "stable_baselines3": str(stable_baselines3.__version__),
            "sb3_contrib": str(sb3_contrib.__version__), "torch": str(torch.__version__), "numpy": str(np.__version__)}


def resolve_hyperparams(map_name: str, hyperparams_file=None, overrides: dict | None = None) -> dict:
    """Package (or file) hyperparameters of the map merged with ``overrides``.

    Raises:
        ValueError: an unknown key (the message lists the known ones).
    """
    hp = merge(load_hyperparams(map_name, hyperparams_file), overrides or {})
    unknown = sorted(set(hp) - set(ALGO_KEYS) - set(RUN_KEYS))
    if unknown:
        raise ValueError(f"unknown hyperparameter(s) {unknown}; known: {sorted(ALGO_KEYS + RUN_KEYS)}")
    return hp


ROLLOUT_EPISODE = "episode"
"""``n_steps: episode``: a rollout of one whole training episode per row (the paper's: it
collects its 8 parallel episodes of 5,000 steps, then splits them into 50 minibatches)."""


def rollout_env_steps(n_steps, episode_steps: int, phases_per_step: int) -> int:
    """Env steps per row of a rollout: ``n_steps``, or with ``n_steps: episode`` one training
    episode (``episode_steps`` simulator steps x the variant's phases per step)."""
    if n_steps == ROLLOUT_EPISODE:
        return int(episode_steps) * int(phases_per_step)
    return int(n_steps)


def algorithm_kwargs(hp: dict, spec, layout, phases_per_step: int, rows: int, episode_steps: int | None = None) -> dict:
    """Constructor arguments of the SB3 algorithm from resolved hyperparameters.

    Minibatches: ``batch_size`` rows, unless ``n_minibatches`` is given: then
    MaskableRecurrentPPO splits each rollout's deployed rows into that many minibatches, and
    the sb3-contrib algorithms (which train on every row) use ``n_steps * rows / n_minibatches``.
    Gamma and GAE lambda are converted per env step; policy_kwargs the algorithm's policy does
    not take are dropped. ``episode_steps`` (the training episode's simulator steps; default
    the env's) gives the rollout of ``n_steps: episode``.

    Raises:
        ValueError: neither ``batch_size`` nor ``n_minibatches``, or one below 1.
    """
    if episode_steps is None:
        episode_steps = (hp.get("env") or {}).get("episode_steps", EnvConfig.episode_steps)
    n_steps = rollout_env_steps(hp["n_steps"], episode_steps, phases_per_step)
    n_minibatches = hp.get("n_minibatches")
    batch_size = hp.get("batch_size")
    for key, value in (("batch_size", batch_size), ("n_minibatches", n_minibatches)):
        if value is not None and int(value) < 1:
            raise ValueError(f"{key} must be >= 1, got {value}")
    if n_minibatches is None and batch_size is None:
        raise ValueError("give batch_size (rows per minibatch) or n_minibatches")
    extra = {}
    for key in COMMUNICATION_KEYS:
        if hp.get(key) is not None:
            if spec.name != "MaskableRecurrentPPO":
                raise ValueError(f"{key} is a setting of MaskableRecurrentPPO, not of {spec.name}")
            extra[key] = float(hp[key])
    if n_minibatches is not None:
        if spec.name == "MaskableRecurrentPPO":
            extra["n_minibatches"] = int(n_minibatches)
        batch_size = max(1, round(n_steps * rows / int(n_minibatches)))
    # keys of another policy family (e.g. the LSTM sizes for MaskablePPO) are dropped
    policy_kwargs = {k: tuple(v) if isinstance(v, list) else v for k, v in (hp.get("policy_kwargs") or {}).items()
                     if k in spec.policy_keys}
    return dict(learning_rate=schedule(hp["learning_rate"]), n_steps=n_steps, batch_size=int(batch_size),
                n_epochs=int(hp["n_epochs"]), gamma=per_phase(hp["gamma"], phases_per_step),
                gae_lambda=per_phase(hp["gae_lambda"], phases_per_step), clip_range=float(hp["clip_range"]),
                ent_coef=float(hp["ent_coef"]), vf_coef=float(hp["vf_coef"]),
                max_grad_norm=float(hp["max_grad_norm"]), target_kl=hp.get("target_kl"),
                policy_kwargs=policy_kwargs_for(layout, **policy_kwargs), **extra)


NUMBER_RANGES = {"gamma": (0.0, 1.0, True), "gae_lambda": (0.0, 1.0, True), "clip_range": (0.0, math.inf, False),
                 "max_grad_norm": (0.0, math.inf, False), "vf_coef": (0.0, math.inf, True),
                 "ent_coef": (0.0, math.inf, True)}
"""(low, high, low included) of the PPO numbers: discounts in [0, 1], a clip range and a gradient
norm above 0, coefficients at least 0."""


def _in_range(value: float, low: float, high: float, low_included: bool) -> bool:
    return (value >= low if low_included else value > low) and value <= high and not math.isnan(value)


def _range_text(low: float, high: float, low_included: bool) -> str:
    if math.isinf(high):
        return f"{'at least' if low_included else 'above'} {low:g}"
    return f"between {low:g} and {high:g}"


def _schedule_values(value) -> list[float]:
    """The rates a learning-rate setting takes (a number, lin_<v>'s start, drop_<v>_<w>'s two)."""
    text = str(value)
    if isinstance(value, (int, float)):
        return [float(value)]
    if text.startswith("lin_"):
        return [float(text[4:])]
    if text.startswith("drop_"):
        return [float(v) for v in text[5:].split("_")]
    return [float(text)]


def check_run_settings(hp: dict, total) -> None:
    """Refuse, before any work and before the run folder exists, the settings that would fail
    later or train nothing: counts below their minimum, a learning rate that is not a number
    or schedule, a total that is not a positive whole number.

    Raises:
        ValueError: one line naming the setting and the cause.
    """
    minimum = {"n_steps": 2, "n_epochs": 1, "checkpoint_freq": 1, "n_envs": 1, "eval_episode_steps": 1,
               "eval_episodes": 1, "torch_threads": 1, "batch_size": 2, "n_minibatches": 1, "eval_freq": 0}
    values = {**{k: hp.get(k) for k in minimum}, "timesteps": total}
    minimum["timesteps"] = 1
    for key, low in minimum.items():
        value = values[key]
        if value is None and key in ("batch_size", "n_minibatches"):
            continue
        if key == "n_steps" and value == ROLLOUT_EPISODE:
            continue
        if isinstance(value, bool) or not isinstance(value, int) or value < low:
            raise ValueError(f"{key} must be a whole number >= {low}"
                             + (f" or '{ROLLOUT_EPISODE}'" if key == "n_steps" else "") + f", got {value!r}")
    for key in ("learning_rate", "clip_range", "gamma", "gae_lambda", "ent_coef", "vf_coef", "max_grad_norm",
                *COMMUNICATION_KEYS):
        if key == "learning_rate":
            schedule(hp[key])
        elif key in COMMUNICATION_KEYS and hp.get(key) is None:
            continue                                    # optional, off by default
        elif isinstance(hp.get(key), bool) or not isinstance(hp.get(key), (int, float)):
            raise ValueError(f"{key} must be a number, got {hp.get(key)!r}")
        elif key in NUMBER_RANGES and not _in_range(hp[key], *NUMBER_RANGES[key]):
            raise ValueError(f"{key} must be {_range_text(*NUMBER_RANGES[key])}, got {hp[key]!r}")
    rates = _schedule_values(hp["learning_rate"])
    if any(not rate > 0 or math.isinf(rate) or math.isnan(rate) for rate in rates):
        raise ValueError(f"learning_rate must be above 0 (every value of a schedule), got {hp['learning_rate']!r}")
    for key in COMMUNICATION_KEYS:
        if hp.get(key) is not None and get_algorithm(hp.get("algo", DEFAULT_ALGORITHM)).name \
                != "MaskableRecurrentPPO":
            raise ValueError(f"{key} is a setting of MaskableRecurrentPPO, not of {hp.get('algo')}")
    if hp.get("precision", "auto") not in PRECISIONS:
        raise ValueError(f"precision must be one of {', '.join(PRECISIONS)}, got {hp.get('precision')!r}")
    if hp.get("message_team_share") is not None and not 0.0 <= float(hp["message_team_share"]) <= 1.0:
        raise ValueError(f"message_team_share must be between 0 and 1 (a share of the team's reward), got "
                         f"{hp['message_team_share']}")
    if hp.get("listen_coef") and (hp.get("env") or {}).get("message_encoding", EnvConfig.message_encoding) != "planes":
        raise ValueError("listen_coef needs legible messages: set env.message_encoding=planes (with "
                         "'scalar' messages the received symbols have no channel of their own)")


def normalized_rewards(vec_env, checkpoint: Path | None, gamma: float):
    """SB3's ``VecNormalize`` on rewards only (observations are already scaled by the env).

    The policy and value losses share one optimizer and one gradient-norm clip, so raw returns
    of -1,000 (battery failures) would let the value loss swamp the policy gradient; scaling
    rewards by the running std of the discounted return keeps both in range. Only training
    sees it: rewards in curve.csv and every evaluation are the env's own. On resume the
    statistics saved beside the checkpoint are loaded (fresh ones if there are none).

    Args:
        vec_env: the training vector env.
        checkpoint: the checkpoint being resumed, or None.
        gamma: the per-env-step discount (the return whose std scales the rewards).
    """
    if checkpoint is not None:
        stats = RunFolder.of_model(checkpoint).statistics_file(model_steps(checkpoint))
        if stats.is_file():
            return VecNormalize.load(str(stats), vec_env)
    return VecNormalize(vec_env, norm_obs=False, norm_reward=True, gamma=gamma)


RESUME_FREE = ("timesteps", "checkpoint_freq", "eval_freq", "eval_episode_steps", "eval_episodes", "torch_threads",
               "precision")
"""Hyperparameters a resumed run may change: the target, the bookkeeping and the machine's
threads (``precision`` is the run's own: :func:`run_precision`). Any other differs from the
run's config.yml only by a refusal."""


def _check_resumable(run: RunFolder, config: dict) -> Path:
    """The newest valid checkpoint of a run folder whose config.yml matches this run's map,
    variant, algorithm, seed, env and hyperparameters (newer invalid checkpoints are named on
    stderr and passed over).

    Raises:
        FileNotFoundError: no valid checkpoint, or no config.yml (nothing to check the settings
            against).
        ValueError: a setting other than the run's (one line naming it and both values).
    """
    skipped = []
    checkpoint = run.newest_checkpoint(skipped)
    for path in skipped:
        print(f"--resume: skipped {path} (empty, cut or corrupt)", file=sys.stderr)
    run_dir = run.path
    if checkpoint is None:
        raise FileNotFoundError(f"--resume: no valid checkpoint found in {run.checkpoints_dir} "
                                f"(looked for model_<steps>_steps.zip)")
    if not run.config_file.is_file():
        raise FileNotFoundError(f"--resume: {run.config_file} is missing, so this run's settings cannot be checked "
                                f"against the run's; restore it, or start a new run from the checkpoint with "
                                f"--init-from {checkpoint}")
    saved = run.read_config()
    for key in ("map", "map_shape", "variant", "algo", "seed"):
        if saved.get(key) != config[key]:
            raise ValueError(f"--resume: {run_dir} was trained with {key}={saved.get(key)!r}, "
                             f"this run asks for {config[key]!r}")
    if saved.get("versions", {}).get("env_version") != config["versions"]["env_version"]:
        raise ValueError(f"--resume: {run_dir} was trained on env version "
                         f"{saved.get('versions', {}).get('env_version')!r}, this package has "
                         f"{config['versions']['env_version']!r}")
    if saved.get("env") != config["env"]:
        changed = sorted(k for k in set(saved.get("env") or {}) | set(config["env"])
                         if (saved.get("env") or {}).get(k) != config["env"].get(k))
        raise ValueError(f"--resume: the env config of {run_dir} differs from this run's in {', '.join(changed)}")
    old_hp, new_hp = saved.get("hyperparams") or {}, config["hyperparams"]
    for key in sorted(set(old_hp) & set(new_hp) - set(RESUME_FREE)):
        if old_hp[key] != new_hp[key]:
            raise ValueError(f"--resume: {run_dir} was trained with {key}={old_hp[key]!r}, this run asks for "
                             f"{new_hp[key]!r}; resume with the run's settings (its config.yml), or start a new "
                             f"run from its weights with --init-from")
    return checkpoint


def run_precision(hp: dict, device_type: str, resumed: RunFolder | None = None,
                  at_timesteps: int = 0) -> tuple[str, str]:
    """The precision (``fp32`` or ``bf16``) a run trains with, and why a resumed run changed it.

    A new run: its ``precision`` hyperparameter resolved on this device
    (:func:`patrolsb3.sb3.precision.resolve_precision`). A resumed run keeps the one its
    config.yml records (``fp32`` when it records none: runs from before the setting existed) and
    says so on stderr when the hyperparameters asked for another, except where the machine
    decides (:func:`patrolsb3.sb3.precision.resumed_precision`: a bf16 run without native bf16
    goes on in fp32, and back to bf16 where it is native again); config.yml records such a change, and
    the run's precision at ``at_timesteps`` (the checkpoint it resumes from) is the latest change
    before it.

    Returns:
        (precision, why it changed on this resume; "" when it did not).
    """
    asked = hp.get("precision", "auto")
    wanted = resolve_precision(asked, device_type)
    if resumed is None or not resumed.config_file.is_file():
        return warned_if_emulated(wanted, device_type), ""
    recorded = resumed.read_config()
    started = (recorded.get("hyperparams") or {}).get("precision", "fp32")
    kept = started
    for change in recorded.get("precision_changes") or []:       # the latest change before the checkpoint
        if change["timesteps"] < max(at_timesteps, 1):
            kept = change["precision"]
    used, why = resumed_precision(kept, asked, device_type, started=started)
    if why:
        print(f"--resume: {resumed.path} was trained in {kept} so far and goes on in {used}: {why}; "
              f"config.yml records the change (precision_changes)", file=sys.stderr)
    elif used != wanted:
        print(f"--resume: {resumed.path} keeps the precision it was trained with ({used}), not {wanted}",
              file=sys.stderr)
    return warned_if_emulated(used, device_type), why


def mixed_episodes(hp: dict, n_episodes: int) -> dict:
    """The ``mix`` hyperparameter as ``make_vec_env``'s ``episode_env``: the parallel episodes
    named by ``mix.episodes`` (a count K: the first K; or a list of indices) run with ``env`` +
    ``mix.env`` (e.g. a recharge drill of short low-battery episodes beside the long ones), the
    others with ``env``. Team sizes are per index too (``1,1,1,1,2,3,4,5`` at the end of the
    curriculum), so a list like ``[0,2,4,6]`` mixes teams of every size.

    Raises:
        ValueError: a mix without ``episodes`` and ``env``, or episodes the run does not have.
    """
    mix = hp.get("mix")
    if not mix:
        return {}
    if not isinstance(mix, dict) or set(mix) != {"episodes", "env"} or not isinstance(mix["env"], dict):
        raise ValueError(f"mix must be {{episodes: K or [indices], env: {{EnvConfig overrides}}}} "
                         f"(e.g. --set mix.episodes=4 mix.env.episode_steps=400), got {mix!r}")
    chosen = mix["episodes"]
    indices = list(range(int(chosen))) if isinstance(chosen, int) else [int(i) for i in chosen]
    if not indices or not all(0 <= i < n_episodes for i in indices):
        raise ValueError(f"mix.episodes={chosen!r}: the run has {n_episodes} parallel episodes "
                         f"(give a count 1..{n_episodes} or indices 0..{n_episodes - 1})")
    return {i: dict(mix["env"]) for i in indices}


def earlier_stages(model_path: Path) -> int:
    """Agent-steps of the runs a checkpoint's own run was warm-started from (0 if none).

    A run records ``init_from.timesteps`` in its config.yml, which already includes the stages
    before it, so a chain of warm starts (stage 1 -> 2 -> 3 ...) adds up to the whole budget.
    """
    return int((RunFolder.of_model(model_path).read_config().get("init_from") or {}).get("timesteps") or 0)


def warm_start_weights(init_from, algo_class, policy_class) -> tuple[dict, dict]:
    """The policy weights of a previous model, to start a new run from them (``--init-from``).

    Args:
        init_from: a checkpoint of ``patrolsb3 train`` (``model_<steps>_steps.zip`` or a run's
            ``model.zip``), a zoo ``model.zip`` (policy only), or a folder: a zoo entry or a
            run folder (its ``model.zip``, or the newest checkpoint of a run stopped early).
        algo_class, policy_class: the classes of this run's algorithm.

    Returns:
        (state_dict of the policy, {"path": str, "timesteps": agent-steps it was trained for,
        with every stage it was itself warm-started from}).

    Raises:
        FileNotFoundError: nothing loadable at that path.
        ValueError: a file that is neither a model nor a policy of this algorithm.
    """
    path = Path(init_from)
    if path.is_dir():   # a zoo entry or a finished run: model.zip; a stopped run: its newest checkpoint
        path = RunFolder(path).newest_model() or RunFolder(path).model_file
    if not path.is_file():
        raise FileNotFoundError(f"--init-from: no model at {path} (give a checkpoint .zip, a zoo "
                                f"model.zip or a folder holding model.zip)")
    errors = []
    if is_valid_model_file(path):   # a whole model (checkpoint or run's model.zip), not a policy only
        try:
            model = algo_class.load(str(path), device="cpu")
            return model.policy.state_dict(), {"path": recorded_path(path),
                                               "timesteps": int(model.num_timesteps) + earlier_stages(path),
                                               "cpu_hours": cpu_hours_of(path)}
        except Exception as exc:  # noqa: BLE001 - try the policy-only layout next
            errors.append(f"as a {algo_class.__name__}: {type(exc).__name__}: {exc}")
    try:  # a policy only (the zoo's model.zip)
        policy = policy_class.load(str(path), device="cpu")
    except Exception as exc:  # noqa: BLE001
        errors.append(f"as a {policy_class.__name__}: {type(exc).__name__}: {exc}")
        raise ValueError(f"--init-from: {path} cannot be loaded ({'; '.join(errors)})") from exc
    return policy.state_dict(), {"path": recorded_path(path), **policy_budget(RunFolder(path.parent))}


def policy_budget(folder: RunFolder) -> dict:
    """``timesteps`` and ``cpu_hours`` behind a policy-only ``model.zip`` (None where unknown).

    A zoo entry records them in its config's ``budget``. A finished run folder whose model was
    kept as a policy only (a stage-1 run saved for a later session) has no ``budget``; its
    ``cpu_time.csv`` ends at the step where the run finished, so its last row, plus the stages
    the run was itself warm-started from, gives the same two figures.
    """
    config = folder.read_config()
    budget = config.get("budget") or {}
    rows = read_rows(folder.path)
    if budget or not rows:
        return {"timesteps": budget.get("timesteps"), "cpu_hours": budget.get("cpu_hours")}
    steps, seconds = rows[-1]                                  # the run's last record: its end
    earlier = config.get("init_from") or {}
    if earlier and (earlier.get("timesteps") is None or earlier.get("cpu_hours") is None):
        return {"timesteps": None, "cpu_hours": None}          # an unmeasured stage before it
    return {"timesteps": steps + int(earlier.get("timesteps") or 0),
            "cpu_hours": seconds / 3600 + float(earlier.get("cpu_hours") or 0.0)}


def train(map="A", variant: str = "rl-msg", timesteps: int | None = None, out="runs/", algo: str | None = None,
          seed: int = 0, resume: bool = False, init_from=None, hyperparams: dict | None = None, hyperparams_file=None,
          n_envs: int | None = None, eval_freq: int | None = None, checkpoint_freq: int | None = None,
          progress_bar: bool = True, verbose: int = 0, run_id: str | None = None, run_dir=None,
          command: str | None = None, device: str = "auto", recipe: str | None = None) -> Path:
    """Train a parameter-shared policy and write its run folder (see module docstring).

    Args:
        map: map name ("A" .. "D") or map file path.
        variant: "rl-msg", "rl-no-msg" or "rl-intention".
        timesteps: total agent-steps of the run (a resumed run trains up to this total).
        out: root of the run folders.
        algo: "MaskableRecurrentPPO" (default), "MaskablePPO" or "RecurrentPPO".
        seed: seed of the env and the algorithm.
        resume: continue the run folder from its newest checkpoint (step count, curriculum
            stage and learning-rate schedule continue; curve.csv is appended).
        init_from: start a new run from the policy weights of another model (a checkpoint, a
            run folder or a zoo entry of the same map size, variant and algorithm): a warm
            start with a fresh optimizer, step count, schedules and reward statistics. The
            source and its training steps are recorded in config.yml as ``init_from``.
        hyperparams: overrides of the YAML hyperparameters (nested dicts merge).
        hyperparams_file: a YAML keyed by map with a ``default:`` entry (default: the package's).
        n_envs, eval_freq, checkpoint_freq: shortcuts overriding those hyperparameters.
        progress_bar: SB3's tqdm/rich progress bar.
        verbose: SB3 verbosity.
        run_id: folder name of the run (default ``<algo>_seed<seed>``).
        run_dir: the full run folder (overrides out/map/variant/run_id).
        command: the command line recorded in command.txt (default: sys.argv).
        device: where the networks train: "auto" (cuda when torch sees one, else cpu), "cpu"
            or "cuda". The simulator always runs on the CPU.
        recipe: the name of the recipe whose overrides ``hyperparams`` holds
            (:mod:`patrolsb3.sb3.recipes`), recorded in config.yml as ``recipe`` so that a zoo
            column can say how it was trained; None records nothing.

    Returns:
        The run folder.

    Raises:
        ValueError: unknown algorithm / variant / hyperparameter, a run folder that exists
            without ``resume``, or a resume against another map / env version, or an
            ``init_from`` model whose network does not match this run's.
        FileNotFoundError: ``resume`` without a checkpoint (names where it looked).
    """
    import torch


    device = torch_device(device)  # a device torch cannot use: one line, before any work
    shortcuts = {k: v for k, v in dict(n_envs=n_envs, eval_freq=eval_freq, checkpoint_freq=checkpoint_freq,
                                       algo=algo, timesteps=timesteps).items() if v is not None}
    settings = resolve_settings(map, variant, merge(hyperparams or {}, shortcuts), hyperparams_file)
    spec_map, hp, spec, total = settings.map, settings.hyperparams, settings.algorithm, settings.timesteps
    cfg, teams, start_teams = settings.env, settings.teams, settings.start_teams
    torch.set_num_threads(int(hp.get("torch_threads", 1)))
    run = RunFolder(run_dir if run_dir is not None else
                    Path(out) / spec_map.name / variant / (run_id or f"{spec.name}_seed{seed}"))
    config = {"map": spec_map.name, "map_source": source_label(spec_map),
              **({} if is_shipped(spec_map) else {"map_text": spec_map.to_text()}), "map_shape": list(spec_map.shape),
              "variant": variant, "algo": spec.name, "seed": int(seed), "timesteps": total,
              "env": cfg.to_dict(), "hyperparams": hp, "versions": versions(),
              **({"recipe": recipe} if recipe else {})}
    if resume and init_from is not None:
        raise ValueError("--init-from starts a new run; --resume continues one: give only one of them")
    warm_weights = None
    if init_from is not None:
        warm_weights, config["init_from"] = warm_start_weights(init_from, *spec.classes())
    if resume:
        checkpoint = _check_resumable(run, config)
    elif run.has_files():
        raise ValueError(f"run folder {run.path} exists; pass --resume to continue it or --run-id to start another")
    else:
        checkpoint = None
    model, vec_env = _build_model(spec_map, variant, spec, hp, seed, start_teams, checkpoint, warm_weights,
                                  config, run, device, verbose)
    model.policy.precision, precision_change = run_precision(hp, model.device.type,
                                                             run if checkpoint is not None else None,
                                                             at_timesteps=model.num_timesteps)
    config["hyperparams"] = {**hp, "precision": model.policy.precision}
    if precision_change:
        config["precision_change"] = {"timesteps": int(model.num_timesteps), "precision": model.policy.precision,
                                      "why": precision_change}
    # every setting has been accepted (the model is built): now the run folder is made, and held
    folder_lock = run.lock()
    try:
        return _train_in_folder(run, model, vec_env, checkpoint, resume, config, command, spec_map, variant, spec,
                                hp, seed, teams, total, progress_bar, cfg)
    finally:
        folder_lock.release()


def _train_in_folder(run: RunFolder, model, vec_env, checkpoint, resume: bool, config: dict, command, spec_map,
                     variant: str, spec, hp: dict, seed: int, teams, total: int, progress_bar: bool, cfg) -> Path:
    """The part of :func:`train` that writes the run folder, while this process holds it."""
    if checkpoint is None and run.has_files():    # another process made it after our first look
        raise ValueError(f"run folder {run.path} exists; pass --resume to continue it or --run-id to start another")
    if checkpoint is not None and run.newest_checkpoint() != checkpoint:
        raise ValueError(f"--resume: {run.path} changed while this run was being set up (another process "
                         f"wrote a checkpoint); run --resume again")
    run.create()
    if checkpoint is not None:
        run.cut_back_to(model.num_timesteps)    # the abandoned stretch after the checkpoint goes
        if "precision_change" in config:        # a resumed run changed precision: config.yml says from when
            run.record_precision_change(config.pop("precision_change"))
    else:
        run.write_config(config)
    run.record_command(command or " ".join(sys.argv))
    callbacks, curve, cpu_time = _callbacks(spec_map, variant, spec, hp, seed, teams, total, run, model,
                                            vec_env, resumed=checkpoint is not None)
    remaining = total - model.num_timesteps
    started_at = model.num_timesteps
    if remaining <= 0 and checkpoint is not None:
        print(f"--resume: {run.path} is already at {model.num_timesteps:,} agent-steps, at or past the "
              f"{total:,} asked for; nothing to train (raise --timesteps to train further)", file=sys.stderr)
    try:
        if remaining > 0:
            model.learn(remaining, callback=CallbackList(callbacks), reset_num_timesteps=checkpoint is None,
                        progress_bar=progress_bar, tb_log_name=spec.name)
    finally:
        _save_final(model, vec_env, run, cpu_time)
    save_atomically(model, run.model_file)
    if curve.rows_written == 0 and remaining > 0:
        print(f"curve.csv: no episode finished in these {model.num_timesteps - started_at:,} agent-steps (episodes last "
              f"{cfg.episode_steps:,} simulator steps); it holds its header only", file=sys.stderr)
    return run.path


@dataclass(frozen=True)
class Settings:
    """A run's settings, resolved and checked (:func:`resolve_settings`)."""
    map: Any                 # MapSpec
    hyperparams: dict
    algorithm: Any           # AlgorithmSpec
    timesteps: int           # total agent-steps
    env: Any                 # EnvConfig of the run (mixed episodes add their overrides)
    teams: list              # the curriculum's team sizes, one list per stage
    start_teams: list        # the team sizes the run starts with


def resolve_settings(map, variant: str, hyperparams: dict | None = None, hyperparams_file=None) -> Settings:
    """Every setting of a run resolved and checked, without building anything: what ``train``
    refuses before any work (and ``patrolsb3 sweep`` checks for each trial before it starts).

    Raises:
        ValueError: an unknown map, variant, algorithm or hyperparameter, or a value out of its
            range (one line naming it).
        MapError: a map file that cannot be read.
    """
    spec_map = load_map(map)
    variant_overrides(variant)  # unknown variant -> ValueError listing the known ones
    hp = resolve_hyperparams(spec_map.name, hyperparams_file, hyperparams or {})
    spec = get_algorithm(hp.get("algo", DEFAULT_ALGORITHM))
    check_run_settings(hp, hp.get("timesteps"))
    cfg, teams, start_teams = _run_teams(spec_map, variant, hp, strict=spec.masked)
    for episode_env in mixed_episodes(hp, len(start_teams)).values():     # each mixed setting is valid too
        make_config(spec_map.name, **{**variant_overrides(variant), **dict(hp.get("env") or {}), **episode_env})
    return Settings(spec_map, hp, spec, int(hp["timesteps"]), cfg, teams, start_teams)


def _run_teams(spec_map, variant: str, hp: dict, strict: bool = True):
    """The run's env config (the one its vec env runs: :func:`patrolsb3.sb3.vec_env.training_config`),
    its curriculum of team sizes and the teams it starts with."""
    cfg = training_config(spec_map, variant, strict, **dict(hp.get("env") or {}))
    n_par = int(hp.get("n_envs", 8))
    teams = curriculum_teams(n_par, min(cfg.max_agents, spec_map.n_vertices))
    final_teams = [min(k, cfg.max_agents, spec_map.n_vertices) for k in
                   (DEFAULT_AGENTS if n_par == len(DEFAULT_AGENTS) else teams[-1])]
    return cfg, teams, (teams[0] if hp.get("curriculum", True) else final_teams)


CHECKPOINT_WARN_BYTES = 100 * 2 ** 20
"""A checkpoint above this size (100 MiB) is announced on stderr before training starts."""


def memory_estimate(hp: dict, layout, rows: int, phases_per_step: int, episode_steps: int) -> dict:
    """Bytes a run will need, estimated before its model is built: ``rollout`` (the rollout
    buffer: observations, masks, LSTM states and the per-row scalars of ``n_steps`` x rows) and
    ``checkpoint`` (weights and Adam's two moments, and the last observations SB3 saves).

    Args:
        hp: the run's hyperparameters.
        layout: the vec env's observation layout (grid shape, vector and critic sizes).
        rows: vec-env rows (parallel episodes x max_agents).
        phases_per_step, episode_steps: for ``n_steps: episode``.
    """
    n_steps = rollout_env_steps(hp["n_steps"], episode_steps, phases_per_step)
    kwargs = hp.get("policy_kwargs") or {}
    hidden = int(kwargs.get("lstm_hidden_size", 128))
    dense = [int(v) for v in kwargs.get("dense_sizes", (512, 341, 227))]
    channels = [int(v) for v in kwargs.get("conv_channels", (4, 8))]
    C, H, W = layout.grid_shape
    obs_dim = C * H * W + layout.vector_size + layout.critic_size
    n_actions = 21
    per_row = obs_dim + n_actions + 4 * hidden + 8                  # floats stored per row and env step
    conv_out = channels[-1] * max(1, H - 4) * max(1, W - 4)
    params = 0
    for extra in (layout.vector_size, layout.vector_size + layout.critic_size):   # actor, critic
        width = conv_out + extra
        for size in dense:
            params += width * size + size
            width = size
    params += 4 * hidden * (dense[-1] + hidden + 2) + (hidden + 1) * n_actions + dense[-1] + 1
    return {"rollout": 4 * n_steps * rows * per_row,
            "checkpoint": 4 * (3 * params + rows * (obs_dim + 4 * hidden)), "parameters": params}


def physical_memory() -> int | None:
    """This machine's memory in bytes (Linux and macOS), None where it cannot be read."""
    import os
    try:
        return os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):
        return None


def check_memory(estimate: dict, vec_env=None) -> None:
    """Refuse a run whose rollout buffer would not fit in 80 % of this machine's memory; announce
    a checkpoint above :data:`CHECKPOINT_WARN_BYTES` on stderr (sizes in MiB).

    Raises:
        ValueError: the rollout would not fit (one line with the sizes).
    """
    total = physical_memory()
    if total and estimate["rollout"] > 0.8 * total:
        if vec_env is not None:
            vec_env.close()
        raise ValueError(f"the rollout buffer would need about {estimate['rollout'] / 2 ** 20:,.0f} MiB, more than "
                         f"80 % of this machine's {total / 2 ** 20:,.0f} MiB: fewer n_steps, parallel episodes "
                         f"(n_envs) or env.max_agents")
    if estimate["checkpoint"] > CHECKPOINT_WARN_BYTES:
        print(f"note: each checkpoint of this run will be about {estimate['checkpoint'] / 2 ** 20:,.0f} MiB "
              f"({estimate['parameters']:,} parameters, the optimizer state and the last observations)",
              file=sys.stderr)


def _build_model(spec_map, variant: str, spec, hp: dict, seed: int, start_teams, checkpoint, warm_weights,
                 config: dict, run: RunFolder, device: str, verbose: int):
    """The training vec env and the model: loaded from ``checkpoint``, or new (from
    ``warm_weights`` if given)."""
    env_kwargs = dict(hp.get("env") or {})
    cls, policy_cls = spec.classes()
    vec_env = make_vec_env(spec_map, agents=start_teams, variant=variant, seed=seed, strict=spec.masked,
                           episode_env=mixed_episodes(hp, len(start_teams)), **env_kwargs)  # bad env: no run folder
    rows = vec_env.num_envs
    check_memory(memory_estimate(hp, vec_env.layout, rows, vec_env.phases_per_step, config["env"]["episode_steps"]),
                 vec_env)
    if hp.get("normalize_reward", False):
        vec_env = normalized_rewards(vec_env, checkpoint, per_phase(hp["gamma"], vec_env.phases_per_step))
    if checkpoint is not None:
        model = cls.load(checkpoint, env=vec_env, device=device, tensorboard_log=recorded_path(run.tensorboard_dir),
                         verbose=verbose)
        model._last_obs = None  # the saved observation belongs to the old env: learn() resets
        if verbose:
            print(f"resuming {run.path} from {checkpoint.name} at {model.num_timesteps} timesteps")
        return model, vec_env
    kwargs = algorithm_kwargs(hp, spec, vec_env.layout, vec_env.phases_per_step, rows,
                              episode_steps=config["env"]["episode_steps"])
    model = cls(policy_cls, vec_env, tensorboard_log=recorded_path(run.tensorboard_dir), seed=seed, verbose=verbose,
                device=device, **kwargs)
    if warm_weights is not None:
        try:
            model.policy.load_state_dict(warm_weights)
        except RuntimeError as exc:
            raise ValueError(f"--init-from {config['init_from']['path']}: its network does not match "
                             f"this run's (another map size, variant or policy_kwargs?): {exc}") from exc
    return model, vec_env


def _callbacks(spec_map, variant: str, spec, hp: dict, seed: int, teams, total: int, run: RunFolder, model,
               vec_env, resumed: bool):
    """The run's callbacks (curriculum, CPU time, checkpoints, learning curve, evaluation), and
    the curve and CPU-time ones by name."""
    rows = vec_env.num_envs
    max_agents = vec_env.layout.max_agents
    eval_teams = [k for k in range(1, max_agents + 1) if k <= spec_map.n_vertices] * int(hp.get("eval_episodes", 1))
    eval_env_kwargs = {**dict(hp.get("env") or {}), "episode_steps": int(hp.get("eval_episode_steps", 500))}

    def make_eval_env():
        return make_vec_env(spec_map, agents=eval_teams, variant=variant, seed=seed + 10_000,
                            strict=spec.masked, **eval_env_kwargs)

    curve = LearningCurveCallback(run.curve_file, max_agents)
    cpu_time = CpuTimeCallback(run.path, restart_at(run.path, model.num_timesteps) if resumed else 0.0)
    callbacks = [cpu_time, AtomicCheckpointCallback(max(1, int(hp.get("checkpoint_freq", 200_000)) // rows), run),
                 curve,
                 PaperMetricsEvalCallback(make_eval_env, run.eval_file, int(hp.get("eval_freq", 0)))]
    if hp.get("curriculum", True):
        callbacks.insert(0, CurriculumCallback(total, curriculum=teams))
    return callbacks, curve, cpu_time


def _save_final(model, vec_env, run: RunFolder, cpu_time) -> None:
    """The last checkpoint (and its reward statistics) whatever ended the run, its CPU time, and
    the env closed."""
    save_checkpoint(model, run)
    cpu_time.record(model.num_timesteps)
    vec_env.close()
