"""The model zoo: trained checkpoints, loadable in one line.

Two settings, two folders (the rule lives here, in :func:`entry_dir`):

- the **paper's setting** (the default): ``zoo/<MAP>/<variant>/seed<k>/``, one folder per
  training seed, trained and evaluated with no return guard; ``zoo/<MAP>/<variant>/default.yml``
  names the seed chosen by validation (``patrolsb3 zoo choose``, on the validation seed, never
  the evaluation's). With a single seed and no ``default.yml``, that seed is the default.
- **behind the return guard** (``guard=True``, strategy ``zoo:<variant>:guarded``):
  ``zoo/guarded/<MAP>/<variant>/``, the earlier entries that act with the heuristics' recharge
  rule as a shield (``env.return_guard``, ours; not the paper's setting).

Each entry folder holds ``model.zip`` (policy only, no optimizer state), ``config.yml`` (env
config, algorithm, hyperparameters, versions, training budget), ``command.txt``,
``curve.csv`` (learning curve) and ``eval.json`` (paper metrics for 1-5 agents).

``load("A", "rl-msg")`` returns a :class:`ZooPolicy`: SB3's ``predict()`` signature on the
batched simulator ``State``, so the evaluation treats it like a heuristic. It builds the
observations and masks with the core's own functions, runs the message phase and then the
move phase (or one phase, as the model was trained), and carries the LSTM state.
"""
from __future__ import annotations

import dataclasses
import os
from pathlib import Path

import numpy as np
import yaml

from .core import protocol
from .core.config import ENV_VERSION, EnvConfig, make_config
from .core.maps import MapSpec, load_map, parse_map
from . import names
from .names import GUARDED, VARIANT_NAMES, strategy_name  # noqa: F401 - the zoo's names, re-exported
from .outputs import read_eval_file
from .runs import read_config, write_atomically, zip_is_intact  # noqa: F401  (zoo.read_config is public)


class ZooError(ValueError):
    """A zoo entry that is missing, incomplete or incompatible with this code."""


ZOO_DIR = Path(__file__).resolve().parent.parent / "zoo"
"""The checkout's zoo (the zoo ships with the git repository, not with the wheel)."""
ZOO_ENV = "PATROLSB3_ZOO"
"""Environment variable naming a zoo folder (e.g. a clone's ``zoo/``) for an installed package."""


def training_map(config: dict):
    """The map a run or entry was trained on, from its config.yml: the map file if it is still
    there, else the map text it recorded (a map not shipped), else the shipped map by name."""
    source = config.get("map_source")
    if source and Path(source).is_file():
        return source
    if config.get("map_text"):
        return parse_map(config["map_text"], name=config["map"], source=str(source or "<config.yml>"))
    return config["map"]


def use_zoo_dir(zoo_dir) -> None:
    """Make ``zoo_dir`` the zoo of this process and the processes it starts (Ray's included):
    what a command's ``--zoo-dir`` does, through ``$PATROLSB3_ZOO``.

    Raises:
        ZooError: not a folder.
    """
    root = Path(zoo_dir)
    if not root.is_dir():
        raise ZooError(f"--zoo-dir {root}: not a folder; give the zoo/ folder of a patrolsb3 clone")
    os.environ[ZOO_ENV] = str(root.resolve())


def zoo_root(zoo_dir=None) -> Path:
    """Where the zoo is: ``zoo_dir`` if given, else ``$PATROLSB3_ZOO``, else the checkout's ``zoo/``.

    Raises:
        ZooError: none of them is a folder; the message says where it looked and how to get it.
    """
    import os
    if zoo_dir is not None:
        return Path(zoo_dir)
    if os.environ.get(ZOO_ENV):
        root = Path(os.environ[ZOO_ENV])
        if not root.is_dir():
            raise ZooError(f"${ZOO_ENV}={root} is not a folder; point it at the zoo/ folder of a "
                           f"patrolsb3 clone")
        return root
    if ZOO_DIR.is_dir():
        return ZOO_DIR
    raise ZooError(f"no zoo found (looked for ${ZOO_ENV} and {ZOO_DIR.name}/ beside the package): the zoo "
                   f"ships with the git repository, not the wheel; clone it and set {ZOO_ENV} to its zoo/ "
                   f"folder, or give the zoo folder with --zoo-dir (commands) or zoo_dir= (Python)")


DEFAULT_FILE = "default.yml"
"""In a paper-setting entry folder: ``{seed: k, chosen_by: ...}``, the seed ``load`` uses by default."""


def parse_strategy(name: str) -> tuple[str, bool]:
    """:func:`patrolsb3.names.parse_strategy`, its error a :class:`ZooError`."""
    try:
        return names.parse_strategy(name)
    except names.StrategyNameError as exc:
        raise ZooError(str(exc)) from None


def variant_folder(map_name: str, variant: str, zoo_dir=None, guard: bool = False) -> Path:
    """``<zoo>/<MAP>/<variant>`` (paper's setting) or ``<zoo>/guarded/<MAP>/<variant>``; it need not exist."""
    root = zoo_root(zoo_dir)
    return (root / GUARDED if guard else root) / str(map_name).upper() / variant


def seeds(map_name: str, variant: str, zoo_dir=None, guard: bool = False) -> list[int]:
    """The training seeds an entry holds (its ``seed<k>`` subfolders with a model)."""
    folder = variant_folder(map_name, variant, zoo_dir, guard)
    return sorted(int(p.parent.name[4:]) for p in folder.glob("seed*/model.zip") if p.parent.name[4:].isdigit())


def seed_curves(map_name: str, variant: str, zoo_dir=None, guard: bool = False) -> list[Path]:
    """The curve.csv of every training seed of an entry (the paper's setting; a guarded entry's
    one), in seed order; [] when there is none."""
    if guard:
        path = entry_dir(map_name, variant, zoo_dir, guard=True) / "curve.csv"
        return [path] if path.is_file() else []
    found = [entry_dir(map_name, variant, zoo_dir, seed=k) / "curve.csv" for k in seeds(map_name, variant, zoo_dir)]
    return [p for p in found if p.is_file()]


def default_seed(map_name: str, variant: str, zoo_dir=None) -> dict | None:
    """The paper-setting entry's default seed: ``{"seed": k, "chosen_by": text}`` from its
    ``default.yml``, else its only seed; None when it has no seed.

    Raises:
        ZooError: several seeds and no ``default.yml`` (say how to choose), or a default.yml
            naming a seed the entry lacks.
    """
    folder = variant_folder(map_name, variant, zoo_dir)
    have = seeds(map_name, variant, zoo_dir)
    if (folder / DEFAULT_FILE).is_file():
        try:
            chosen = yaml.safe_load((folder / DEFAULT_FILE).read_text()) or {}
        except (yaml.YAMLError, UnicodeDecodeError) as exc:
            raise ZooError(f"{folder / DEFAULT_FILE}: not valid YAML, cut or damaged ({str(exc).splitlines()[0]}); "
                           f"write it again with 'patrolsb3 zoo choose {map_name} {variant}'") from None
        if not isinstance(chosen, dict):
            raise ZooError(f"{folder / DEFAULT_FILE}: expected a mapping with 'seed', got {type(chosen).__name__}; "
                           f"write it again with 'patrolsb3 zoo choose {map_name} {variant}'")
        if chosen.get("seed") not in have:
            raise ZooError(f"{folder / DEFAULT_FILE}: names seed {chosen.get('seed')!r}, the entry has {have}")
        return chosen
    if len(have) > 1:
        raise ZooError(f"{folder}: seeds {have} and no {DEFAULT_FILE}; run 'patrolsb3 zoo choose "
                       f"{str(map_name).upper()} {variant}' to pick one by validation")
    return {"seed": have[0], "chosen_by": "the only seed"} if have else None


def entry_dir(map_name: str, variant: str, zoo_dir=None, seed: int | None = None, guard: bool = False) -> Path:
    """Folder of one zoo entry (it need not exist).

    Paper's setting: ``<zoo>/<MAP>/<variant>/seed<k>``, ``seed`` or else the default seed
    (:func:`default_seed`; the bare variant folder when there is none). Behind the guard:
    ``<zoo>/guarded/<MAP>/<variant>``, or its ``seed<k>`` subfolder.
    """
    folder = variant_folder(map_name, variant, zoo_dir, guard)
    if seed is None and not guard:
        chosen = default_seed(map_name, variant, zoo_dir)
        seed = chosen["seed"] if chosen else None
    return folder if seed is None else folder / f"seed{int(seed)}"


def read_entry(path: Path, damaged_eval_ok: bool = False) -> dict:
    """config.yml and eval.json of one entry folder, as one dict with its ``path``.

    Args:
        path: the entry folder.
        damaged_eval_ok: a damaged eval.json reads as none (``zoo eval`` rewrites it) instead of
            an error.

    Raises:
        ZooError: no config.yml. ValueError: a damaged config.yml or eval.json (names it).
    """
    path = Path(path)
    config_file = path / "config.yml"
    if not config_file.is_file():
        raise ZooError(f"{path}: no config.yml; not a zoo entry")
    config = read_config(config_file)
    eval_file = path / "eval.json"
    evaluation = None
    if eval_file.is_file():
        try:
            evaluation = read_eval_file(eval_file)
        except ValueError:
            if not damaged_eval_ok:
                raise
    return {"path": str(path), "config": config, "eval": evaluation}


def list_entries(zoo_dir=None) -> list[dict]:
    """Every entry folder of the zoo, the paper's setting (every seed) first, then the guarded
    ones; sorted by map, variant and seed. Each dict also has ``guard`` (bool) and ``seed``
    (the folder's training seed, None for a guarded entry's default folder)."""
    root = zoo_root(zoo_dir)
    found = []
    for guard, pattern in ((False, "[A-Z]*/*/seed*/config.yml"),
                           (True, f"{GUARDED}/*/*/config.yml"), (True, f"{GUARDED}/*/*/seed*/config.yml")):
        for path in sorted(root.glob(pattern)):
            entry = read_entry(path.parent)
            name = path.parent.name
            entry["guard"] = guard
            entry["seed"] = int(name[4:]) if name.startswith("seed") and name[4:].isdigit() else None
            found.append(entry)
    return found


def available(map_name: str, variant: str, zoo_dir=None, guard: bool = False) -> bool:
    """True when the zoo has a model for (map, variant) in that setting (in the paper's setting:
    at least one trained seed, whether or not a default has been chosen among several; ask
    :func:`default_seed` for that); False also when there is no zoo."""
    try:
        if not guard:
            return bool(seeds(map_name, variant, zoo_dir))
        return (entry_dir(map_name, variant, zoo_dir, guard=guard) / "model.zip").is_file()
    except ZooError:
        return False


class ZooPolicy:
    """A trained shared policy acting for every slot of a batch of episodes.

    ``predict(sim_state, state=None, episode_start=None, deterministic=True)`` returns
    ``(actions, state)``: actions (E, A, 2) int (message symbol shown this step, move), and the
    recurrent state to pass back at the next call. Phases, masks and the flat observation
    come from :mod:`patrolsb3.core.protocol`, as in the training env.
    """

    def __init__(self, policy, spec, cfg: EnvConfig, info: dict):
        self.policy = policy
        self.spec = spec
        self.cfg = cfg
        self.info = info
        self.layout = protocol.ObservationLayout.of(spec, cfg)
        self.recurrent = hasattr(policy, "lstm_actor")

    SETTINGS = ("max_agents", "comm", "message_timing", "n_symbols", "local_idleness", "message_encoding",
                "return_guard")
    """The EnvConfig fields an env must share with the policy: its observations, actions, phases
    and, for the entries behind the return guard, the shield on its masks."""

    def env_settings(self) -> dict:
        """The env settings this policy acts under: ``patrolsb3.parallel_env(map, n_agents,
        **policy.env_settings())`` builds a PettingZoo env it can act in."""
        return {key: getattr(self.cfg, key) for key in self.SETTINGS}

    def act_phase(self, sim_state, phase: int, lstm, starts, deterministic: bool = True):
        """One phase's actions for every slot of ``sim_state``.

        Args:
            sim_state: the batched simulator ``State`` (E episodes), its symbols as they are
                shown in this phase.
            phase: protocol.MESSAGE_PHASE or MOVE_PHASE.
            lstm: the recurrent state of the previous call (None at the start).
            starts: (E * A,) bool, rows whose episode starts here.
            deterministic: most likely legal action, else a sample.

        Returns:
            (E, A, 2) int64 actions (message index, move) and the new recurrent state.
        """
        decision = protocol.decide(self.spec, self.cfg, sim_state, phase)
        E, A = sim_state.pos.shape
        masks = decision.masks.reshape(E * A, -1)                              # (E*A, n_symbols + 5)
        obs = decision.flat(self.layout).reshape(E * A, -1)                    # (E*A, layout.size)
        if self.recurrent:
            actions, lstm = self.policy.predict(obs, state=lstm, episode_start=starts,
                                               deterministic=deterministic, action_masks=masks)
        else:
            actions, _ = self.policy.predict(obs, deterministic=deterministic, action_masks=masks)
        return np.asarray(actions).reshape(E, A, 2), lstm

    def move_probabilities(self, sim_state, lstm):
        """The move distribution of every slot in the move phase of ``sim_state``, continuing
        from the recurrent state ``lstm`` (that of the step's message phase, or of the last step).

        Returns:
            (E, A, 5) float64 probabilities (0 on masked moves) and the new recurrent state.
        """
        import torch as th
        decision = protocol.decide(self.spec, self.cfg, sim_state, protocol.MOVE_PHASE)
        E, A = sim_state.pos.shape
        device = self.policy.device
        obs = th.as_tensor(decision.flat(self.layout).reshape(E * A, -1), device=device)
        masks = th.as_tensor(decision.masks.reshape(E * A, -1), device=device)
        with th.no_grad():
            if self.recurrent:
                if lstm is None:
                    shape = self.policy.lstm_hidden_state_shape
                    lstm = (np.zeros((shape[0], E * A, shape[2]), np.float32),) * 2
                states = tuple(th.as_tensor(np.asarray(x), dtype=th.float32, device=device) for x in lstm)
                starts = th.zeros(E * A, dtype=th.float32, device=device)
                distribution, states = self.policy.get_distribution(obs, states, starts, action_masks=masks)
                lstm = (states[0].cpu().numpy(), states[1].cpu().numpy())
            else:
                distribution = self.policy.get_distribution(obs, action_masks=masks)
        probs = distribution.distributions[-1].probs                             # the move dimension
        return probs.cpu().numpy().astype(np.float64).reshape(E, A, -1), lstm

    def seed_sampling(self, seed: int) -> None:
        """Seed torch's generator, which draws the sampled actions (``deterministic=False``)."""
        import torch
        torch.manual_seed(int(seed))

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        """Act for every slot of the batched simulator state ``observation``.

        Args:
            observation: the simulator ``State`` (E episodes).
            state: recurrent state returned by the previous call (None at the start).
            episode_start: (E,) bool, episodes that have just been reset.
            deterministic: greedy actions when True.

        Returns:
            actions (E, A, 2) int64 (message symbol 0..16, move 0..4) and the recurrent state.
        """
        sim = observation
        E, A = sim.pos.shape
        if episode_start is None:
            episode_start = np.full(E, state is None)
        starts = np.repeat(np.asarray(episode_start, dtype=bool), A)
        active = sim.active
        if self.cfg.two_phase:
            silent = dataclasses.replace(sim, messages=np.zeros_like(sim.messages))
            chosen, state = self.act_phase(silent, protocol.MESSAGE_PHASE, state, starts, deterministic)
            symbols = protocol.symbols_of(chosen[..., 0], active)
            shown = dataclasses.replace(sim, messages=symbols)
            chosen, state = self.act_phase(shown, protocol.MOVE_PHASE, state, np.zeros_like(starts), deterministic)
        else:
            chosen, state = self.act_phase(sim, protocol.MOVE_PHASE, state, starts, deterministic)
            symbols = protocol.symbols_of(chosen[..., 0], active & (self.cfg.comm != "none"))
        return np.stack([symbols, chosen[..., 1]], axis=-1).astype(np.int64), state


def env_config(config: dict) -> EnvConfig:
    """The env parameters a model was trained with, from its config.yml ``env`` section.

    Raises:
        ZooError: keys this code does not know (a config of another version), or bad values.
    """
    env = config.get("env") or {}
    unknown = sorted(set(env) - {f.name for f in dataclasses.fields(EnvConfig)})
    if unknown:
        raise ZooError(f"config.yml env section has settings this code does not know: {unknown}; "
                       f"a model of another patrolsb3 version?")
    try:
        return EnvConfig(**{k: (tuple(v) if isinstance(v, list) else v) for k, v in env.items()})
    except (TypeError, ValueError) as exc:
        raise ZooError(f"config.yml env section: {exc}") from None


def checked_map(config: dict, spec, where) -> MapSpec:
    """Load the map a model should act on and refuse one of another size than it was trained on.

    Raises:
        ZooError: names ``where`` (the model), the trained size and the map's.
    """
    spec = load_map(spec)
    trained_shape = tuple(config.get("map_shape", ()))
    if trained_shape != tuple(spec.shape):
        raise ZooError(f"{where}: trained on a {trained_shape} map, cannot act on "
                       f"{spec.name} of size {spec.shape}")
    return spec


def evaluation_config(policy: ZooPolicy, steps: int) -> EnvConfig:
    """The env a model is evaluated in: the paper's values for its training map (not the
    training settings), its number of slots, ``steps`` per episode, invalid actions refused."""
    return make_config(policy.info["config"].get("map"), max_agents=policy.cfg.max_agents,
                       episode_steps=int(steps), invalid_action="raise")


def load_checkpoint(path, spec=None) -> ZooPolicy:
    """A training checkpoint of ``patrolsb3 train`` as a ready policy, like :func:`load`.

    Args:
        path: ``<run>/checkpoints/model_<steps>_steps.zip`` or ``<run>/model.zip``; the run's
            config.yml (next to it, or one folder up) gives the map and the env parameters.
        spec: the map to act on (default: the training map); must match its size.

    Raises:
        ZooError: no such file, no config.yml beside it, a file that is not a model of the run's
            algorithm, or a map of another size.
    """
    path = Path(path)
    if not path.is_file():
        raise ZooError(f"no checkpoint at {path}")
    from .runs import RunFolder
    run = RunFolder.of_model(path)
    run_dir = run.path
    if not run.config_file.is_file():
        raise ZooError(f"{path}: no config.yml in {run_dir}; give a checkpoint inside a run folder of "
                       f"'patrolsb3 train'")
    config = run.read_config()
    version = (config.get("versions") or {}).get("env_version")
    if version != ENV_VERSION:
        raise ZooError(f"{run_dir / 'config.yml'}: trained for env version {version!r}, this code is "
                       f"{ENV_VERSION!r}; retrain it or use a matching patrolsb3 release")
    if not zip_is_intact(path):
        raise ZooError(f"{path}: the file is empty, cut or corrupt (its zip check fails)")
    if spec is None:
        spec = training_map(config)
    spec = checked_map(config, spec, path)
    import torch
    torch.set_num_threads(1)
    from .sb3.algorithms import get_algorithm
    algo_class, _ = get_algorithm(config.get("algo", "MaskableRecurrentPPO")).classes()
    try:
        model = algo_class.load(str(path), device="cpu")
    except Exception as exc:  # a corrupt or foreign file: say which one
        raise ZooError(f"{path}: cannot be loaded as a {algo_class.__name__} checkpoint "
                       f"({type(exc).__name__}: {exc})") from exc
    info = {"path": str(path), "config": config, "timesteps": int(model.num_timesteps)}
    return ZooPolicy(model.policy, spec, env_config(config), info)


def load(map_name: str, variant: str, zoo_dir=None, spec=None, device: str = "cpu",
         seed: int | None = None, guard: bool = False) -> ZooPolicy:
    """Load a zoo model ready to act: ``patrolsb3.zoo.load("A", "rl-msg")``.

    Args:
        map_name: the map the model was trained on ("A" .. "D").
        variant: "rl-msg", "rl-no-msg" or "rl-intention".
        zoo_dir: another zoo folder (default: the repository's ``zoo/``).
        spec: the map to act on (default: ``map_name``); must match the training map's size.
        device: where the network runs: "cpu" (default), "cuda" or "auto".
        seed: one training seed's model (``seed<k>``); None: the entry's default, the seed
            chosen by validation (:func:`default_seed`).
        guard: the entry trained and acting behind the return guard (``zoo/guarded/``, not the
            paper's setting) instead of the paper's setting.

    Raises:
        ZooError: no such entry or seed (lists what the zoo has), or a checkpoint trained for
            another env version or map size.
        ValueError: a device torch cannot use.
    """
    folder = existing_entry_dir(map_name, variant, zoo_dir, seed, guard)
    return load_entry(folder, spec=spec if spec is not None else map_name, device=device)


def existing_entry_dir(map_name: str, variant: str, zoo_dir=None, seed: int | None = None,
                       guard: bool = False) -> Path:
    """:func:`entry_dir`, checked: the folder holds a model.

    Raises:
        ZooError: an unknown variant, or no such entry or seed (the message lists what the zoo has).
    """
    if variant not in VARIANT_NAMES:
        raise ZooError(f"unknown variant {variant!r}; known: {', '.join(VARIANT_NAMES)}")
    setting = "behind the return guard" if guard else "in the paper's setting"
    folder = entry_dir(map_name, variant, zoo_dir, seed, guard)
    if seed is not None and not (folder / "model.zip").is_file():
        raise ZooError(f"no seed {seed} of {str(map_name).upper()}/{variant} {setting} (looked for "
                       f"{folder / 'model.zip'}); its seeds: {seeds(map_name, variant, zoo_dir, guard) or 'none'}")
    if not (folder / "model.zip").is_file():
        have = sorted({f"{str(e['config'].get('map', '?')).upper()}/{e['config'].get('variant', '?')}"
                       + (f":{GUARDED}" if e["guard"] else "") for e in list_entries(zoo_dir)})
        raise ZooError(f"no zoo model for map {str(map_name).upper()} variant {variant} {setting} "
                       f"(looked for {folder / 'model.zip'}); the zoo has: {', '.join(have) or 'nothing'}")
    return folder


def load_entry(folder, spec=None, device: str = "cpu") -> ZooPolicy:
    """The policy of one entry folder (``model.zip`` + ``config.yml``), like :func:`load`.

    Args:
        folder: an entry folder, e.g. ``zoo/A/rl-msg/seed0``.
        spec: the map to act on (default: the training map file if it is still there, else
            the map by name); must match its size.
        device: "cpu" (default), "cuda" or "auto".

    Raises:
        ZooError: no model or config, a checkpoint of another env version, observation layout
            or map size, or a file that cannot be loaded.
    """
    folder = Path(folder)
    info = read_entry(folder, damaged_eval_ok=True)      # acting needs no figures; zoo eval rewrites them
    config = info["config"]
    version = config.get("env_version")
    if version != ENV_VERSION:
        raise ZooError(f"{folder}: trained for env version {version!r}, this code is {ENV_VERSION!r}; "
                       f"retrain it or use a matching patrolsb3 release")
    if spec is None:
        spec = training_map(config)
    spec = checked_map(config, spec, folder)
    cfg = env_config(config)
    import torch
    torch.set_num_threads(1)     # small networks: one thread is fastest, and several oversubscribe
    from .sb3.algorithms import get_algorithm, torch_device
    _, policy_class = get_algorithm(config.get("algo", "MaskableRecurrentPPO")).classes()
    if not zip_is_intact(folder / "model.zip"):
        raise ZooError(f"{folder / 'model.zip'}: the file is missing, empty, cut or corrupt (its zip check "
                       f"fails); restore it from git")
    try:
        policy = policy_class.load(str(folder / "model.zip"), device=torch_device(device))
    except Exception as exc:  # a corrupt or foreign file: say which one
        raise ZooError(f"{folder / 'model.zip'}: cannot be loaded as a {policy_class.__name__} "
                       f"({type(exc).__name__}: {exc})") from exc
    expected = (protocol.ObservationLayout.of(spec, cfg).size,)
    if tuple(policy.observation_space.shape) != expected:
        raise ZooError(f"{folder / 'model.zip'}: the policy reads observations of shape "
                       f"{tuple(policy.observation_space.shape)}, this code makes {expected} "
                       f"(a checkpoint of another observation layout); retrain it")
    return ZooPolicy(policy, spec, cfg, info)


def export_destination(run_dir, zoo_dir=None, as_seed: bool = False) -> Path:
    """The entry folder :func:`export` writes a run into (module docstring of :func:`export`).

    Raises:
        ZooError: the run folder has no config.yml.
    """
    from .runs import RunFolder
    run = RunFolder(run_dir)
    if not run.config_file.is_file():
        raise ZooError(f"{run.path}: no config.yml; not a run folder of 'patrolsb3 train'")
    config = run.read_config()
    guard = bool((config.get("env") or {}).get("return_guard"))
    return entry_dir(config["map"], config["variant"], zoo_dir, guard=guard,
                     seed=config.get("seed", 0) if as_seed or not guard else None)


def export(run_dir, zoo_dir=None, budget: dict | None = None, checkpoint=None, as_seed: bool = False,
           into=None) -> Path:
    """Copy a training run into the zoo, keeping the policy only (no optimizer).

    Args:
        run_dir: a run folder of ``patrolsb3 train`` (model.zip, config.yml, command.txt,
            curve.csv, eval.csv). A run stopped before its end has no model.zip: its newest
            checkpoint is taken (and named in config.yml as ``source_model``).
        checkpoint: a specific checkpoint file of the run to export instead.
        zoo_dir: the zoo root (default: the repository's ``zoo/``).
        budget: extra facts about the training budget, stored in config.yml. Without
            ``cpu_hours`` in it, the CPU hours the run measured (``cpu_time.csv``, its
            warm-start stages included) are recorded, when every stage measured them.
        as_seed: for a run behind the return guard, write into the guarded entry's ``seed<k>``
            subfolder (k: the run's training seed) instead of its default folder. A run in the
            paper's setting always goes to ``zoo/<MAP>/<variant>/seed<k>/``.
        into: write into this folder instead (a staging folder: ``patrolsb3 zoo export`` builds
            the whole entry there, then swaps it in; :func:`replace_entry`).

    Returns:
        The entry folder: ``zoo/<MAP>/<variant>/seed<k>`` for a run in the paper's setting (no
        return guard), ``zoo/guarded/<MAP>/<variant>`` (or its ``seed<k>``) for a guarded one.

    Raises:
        ZooError: the run folder lacks a model or a config.
    """
    import datetime
    import shutil
    from .runs import RunFolder
    from .sb3.cpu_time import cpu_hours_of
    run = RunFolder(run_dir)
    run_dir = run.path
    if not run.config_file.is_file():
        raise ZooError(f"{run_dir}: no config.yml; not a run folder of 'patrolsb3 train'")
    source = Path(checkpoint) if checkpoint else run.newest_model()
    if source is None or not source.is_file():
        raise ZooError(f"{run_dir}: no model.zip and no checkpoint to export")
    config = run.read_config()
    from .sb3.algorithms import get_algorithm
    algo_class, _ = get_algorithm(config["algo"]).classes()
    model = algo_class.load(str(source), device="cpu")
    folder = Path(into) if into is not None else export_destination(run_dir, zoo_dir, as_seed)
    folder.mkdir(parents=True, exist_ok=True)
    write_atomically(folder / "model.zip", lambda partial: model.policy.save(str(partial)))
    for name in (run.COMMAND, *run.RECORDS):
        if (run_dir / name).is_file():
            shutil.copyfile(run_dir / name, folder / name)
    config["env_version"] = config.get("versions", {}).get("env_version", ENV_VERSION)
    config["date"] = datetime.date.fromtimestamp(source.stat().st_mtime).isoformat()
    config["source_model"] = str(source)
    config["budget"] = {"timesteps": int(model.num_timesteps), **(budget or {})}
    if "cpu_hours" in config["budget"]:
        config["budget"]["cpu_hours_source"] = "given (--cpu-hours)"
    elif (measured := cpu_hours_of(source)) is not None:
        config["budget"]["cpu_hours"] = round(measured, 3)
        config["budget"]["cpu_hours_source"] = ("measured (this run's cpu_time.csv) + the cpu_hours "
                                                "its warm-start source recorded, if any")
    warm = (config.get("init_from") or {}).get("timesteps")
    if warm:  # a warm-started run: its budget includes the run it started from
        config["budget"]["timesteps_this_run"] = int(model.num_timesteps)
        config["budget"]["timesteps"] = int(model.num_timesteps) + int(warm)
    config["source_run"] = str(run_dir)
    text = yaml.safe_dump(config, sort_keys=False)
    write_atomically(folder / "config.yml", lambda partial: partial.write_text(text))
    return folder


def replace_entry(staged: Path, entry: Path) -> None:
    """Put a complete staged entry in place of ``entry`` in one step: the old entry (its model and
    every figure of it: eval.json, listening.json, ablation files) is moved aside, the staged one
    renamed in, then the old one deleted; a new model never stands beside old figures."""
    import shutil
    staged, entry = Path(staged), Path(entry)
    old = entry.with_name(f".{entry.name}.old-{os.getpid()}")
    if entry.exists():
        entry.rename(old)
    staged.rename(entry)
    if old.exists():
        shutil.rmtree(old)


def cached_result(map_name: str, variant: str, n_agents: int, episodes: int, steps: int, seed: int,
                  tests: int = 1, zoo_dir=None, deterministic: bool = True, guard: bool = False,
                  training_seed: int | None = None):
    """One entry's eval.json result for exactly this protocol and action mode, or None: the
    default seed's, or ``training_seed``'s."""
    path = entry_dir(map_name, variant, zoo_dir, seed=training_seed, guard=guard) / "eval.json"
    if not path.is_file():
        return None
    data = read_eval_file(path)
    if (data.get("episodes"), data.get("steps"), data.get("seed"), data.get("tests"),
            data.get("deterministic", True)) != (episodes, steps, seed, tests, deterministic):
        return None
    found = next((r for r in data.get("results", []) if r["n_agents"] == n_agents), None)
    return None if found is None else {**found, "strategy": strategy_name(variant, guard)}


def pooled_result(map_name: str, variant: str, n_agents: int, episodes: int, steps: int, seed: int,
                  tests: int = 1, zoo_dir=None, deterministic: bool = True):
    """The paper-setting entry's figures pooled over its training seeds, from their eval.json.

    Every seed whose eval.json holds this protocol and per-episode figures contributes. The
    training seed is the unit: a mean metric's figure is the mean of the seeds' means and its 95 %
    interval Student's t over them (:func:`patrolsb3.stats.seed_interval`), so two seeds far
    apart give a wide interval that contains both. A rate (the battery failure rate) pools the
    seeds' episodes and takes the exact binomial interval (:func:`patrolsb3.stats.rate_interval`):
    with three seeds of 10 episodes, a t over three rates of 0 would say [0, 0].
    ``summary[metric]["tests"]`` holds the seeds' own means, ``["episodes"]`` every episode. With
    one usable seed this is that seed's result unchanged (its intervals are over its episodes:
    a figure, not a verdict; ``claims`` tests no cell below three seeds).

    Returns:
        The result dict (like :func:`cached_result`) with ``training_seeds`` (the seeds pooled)
        and ``unpooled_seeds`` (seeds left out: no eval.json for this protocol, or one written
        before per-episode figures were stored), or None when no seed has such a result.
    """
    from .stats import RATE_METRICS, rate_interval, seed_interval
    usable, left_out = [], []
    for k in seeds(map_name, variant, zoo_dir):
        r = cached_result(map_name, variant, n_agents, episodes, steps, seed, tests, zoo_dir,
                          deterministic, training_seed=k)
        if r is not None and all("episodes" in v for v in r["summary"].values() if isinstance(v, dict) and "ci95" in v):
            usable.append((k, r))
        else:
            left_out.append(k)
    if not usable:
        return None
    if len(usable) == 1:
        return {**usable[0][1], "training_seeds": [usable[0][0]], "unpooled_seeds": left_out}
    first = usable[0][1]
    summary = {}
    for metric, value in first["summary"].items():
        if isinstance(value, dict) and "episodes" in value:
            pooled = np.concatenate([np.asarray(r["summary"][metric]["episodes"], dtype=np.float64)
                                     for _, r in usable])                     # (seeds x episodes,)
            seed_means = [float(r["summary"][metric]["mean"]) for _, r in usable]
            finite_means = [m for m in seed_means if np.isfinite(m)]
            if metric in RATE_METRICS:        # a rate: every episode a 0 or a 1, the exact interval
                finite = pooled[np.isfinite(pooled)]
                mean, ci = (float(finite.mean()) if len(finite) else float("nan")), rate_interval(pooled)
            else:                             # a mean: the training seed is the unit
                mean = float(np.mean(finite_means)) if finite_means else float("nan")
                ci = seed_interval(seed_means)
            summary[metric] = {"mean": mean, "std": float(np.nanstd(seed_means)), "tests": seed_means,
                               "ci95": ci, "episodes": [float(v) for v in pooled]}
        elif metric == "clean_episodes":
            summary[metric] = [int(sum(r["summary"][metric])) for _, r in usable]
        else:
            summary[metric] = value
    return {**first, "summary": summary, "training_seeds": [k for k, _ in usable], "unpooled_seeds": left_out}
