"""The ZooPolicy adapter: a trained model (a zoo entry or a training checkpoint) loaded and made
to act like a heuristic, SB3's ``predict()`` on the batched simulator ``State``.

``load("A", "rl-msg")`` returns a :class:`ZooPolicy`. It builds the observations and masks with
the core's own functions (:mod:`patrolsb3.core.protocol`), runs the message phase and then the
move phase (or one phase, as the model was trained), and carries the LSTM state.
"""
from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np

from ..core import protocol
from ..core.config import ENV_VERSION, EnvConfig, make_config
from ..core.maps import MapSpec, load_map
from ..names import GUARDED
from ..runs import RunFolder, ZooEntry, zip_is_intact
from .folders import ZooError, existing_entry_dir, read_entry, training_map


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
        actions, lstm = self.act_rows(obs, masks, lstm, starts, deterministic)
        return actions.reshape(E, A, 2), lstm

    def act_rows(self, obs, masks, lstm, starts, deterministic: bool = True):
        """The network's (message, move) for rows of flat observations: SB3's ``predict`` with
        masks, carrying the recurrent state (a feed-forward policy has none).

        Args:
            obs: (R, layout.size) float32, the flat observations (:class:`ObservationLayout`).
            masks: (R, n_symbols + 5) bool, the legal messages and moves of each row.
            lstm: the recurrent state of the previous call for these rows (None at the start).
            starts: (R,) bool, rows whose episode starts here.
            deterministic: most likely legal action, else a sample.

        Returns:
            (R, 2) int64 actions (message index, move) and the new recurrent state.
        """
        if self.recurrent:
            actions, lstm = self.policy.predict(obs, state=lstm, episode_start=starts,
                                               deterministic=deterministic, action_masks=masks)
        else:
            actions, _ = self.policy.predict(obs, deterministic=deterministic, action_masks=masks)
        return np.asarray(actions, dtype=np.int64).reshape(len(obs), 2), lstm

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
    from ..sb3.algorithms import get_algorithm
    algo_class, _ = get_algorithm(config.get("algo", "MaskableRecurrentPPO")).classes()
    try:
        model = algo_class.load(str(path), device="cpu")
    except Exception as exc:  # a corrupt or foreign file: say which one
        raise ZooError(f"{path}: cannot be loaded as a {algo_class.__name__} checkpoint "
                       f"({type(exc).__name__}: {exc})") from exc
    info = {"path": str(path), "config": config, "timesteps": int(model.num_timesteps)}
    return ZooPolicy(model.policy, spec, env_config(config), info)


def load(map_name: str, variant: str, zoo_dir=None, spec=None, device: str = "cpu",
         seed: int | None = None, shelf: str = "", guard: bool = False) -> ZooPolicy:
    """Load a zoo model ready to act: ``patrolsb3.zoo.load("A", "rl-msg")``.

    Args:
        map_name: the map the model was trained on ("A" .. "D").
        variant: "rl-msg", "rl-no-msg" or "rl-intention".
        zoo_dir: another zoo folder (default: the repository's ``zoo/``).
        spec: the map to act on (default: ``map_name``); must match the training map's size.
        device: where the network runs: "cpu" (default), "cuda" or "auto".
        seed: one training seed's model (``seed<k>``); None: the entry's default, the seed
            chosen by validation (:func:`default_seed`).
        shelf: a shelf of the zoo instead of the main zoo (:data:`patrolsb3.names.SHELVES`):
            ``"paper-recipe"``, ``"cd10"``, or ``"guarded"`` (the entry trained and acting behind
            the return guard, ``zoo/guarded/``, not the paper's setting).
        guard: ``shelf="guarded"``, said the way earlier releases did.

    Raises:
        ZooError: no such entry or seed (lists what the zoo has), or a checkpoint trained for
            another env version or map size.
        ValueError: a device torch cannot use.
    """
    if guard and shelf not in ("", GUARDED):
        raise ZooError(f"guard=True and shelf={shelf!r}: the entries behind the return guard are the shelf "
                       f"{GUARDED!r}; give one of the two")
    folder = existing_entry_dir(map_name, variant, zoo_dir, seed, GUARDED if guard else shelf)
    return load_entry(folder, spec=spec if spec is not None else map_name, device=device)


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
    from ..sb3.algorithms import get_algorithm, torch_device
    _, policy_class = get_algorithm(config.get("algo", "MaskableRecurrentPPO")).classes()
    model_file = ZooEntry(folder).model_file
    if not zip_is_intact(model_file):
        raise ZooError(f"{model_file}: the file is missing, empty, cut or corrupt (its zip check "
                       f"fails); restore it from git")
    try:
        policy = policy_class.load(str(model_file), device=torch_device(device))
    except Exception as exc:  # a corrupt or foreign file: say which one
        raise ZooError(f"{model_file}: cannot be loaded as a {policy_class.__name__} "
                       f"({type(exc).__name__}: {exc})") from exc
    expected = (protocol.ObservationLayout.of(spec, cfg).size,)
    if tuple(policy.observation_space.shape) != expected:
        raise ZooError(f"{model_file}: the policy reads observations of shape "
                       f"{tuple(policy.observation_space.shape)}, this code makes {expected} "
                       f"(a checkpoint of another observation layout); retrain it")
    return ZooPolicy(policy, spec, cfg, info)
