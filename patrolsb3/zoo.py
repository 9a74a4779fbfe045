"""The model zoo: trained checkpoints in ``zoo/<map>/<variant>/``, loadable in one line.

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
import json
from pathlib import Path

import numpy as np
import yaml

from .core.config import ENV_VERSION, EnvConfig
from .core.maps import load_map
from .core.masks import composite_action_mask
from .core.observe import actor_observation, critic_state

ZOO_DIR = Path(__file__).resolve().parent.parent / "zoo"
VARIANT_NAMES = ("rl-msg", "rl-no-msg", "rl-intention")


class ZooError(ValueError):
    """A zoo entry that is missing, incomplete or incompatible with this code."""


def flat_observation(spec, cfg: EnvConfig, state, phase: int) -> np.ndarray:
    """Observations in the training layout [grid (2*H*W), vector (8), critic (3*A)].

    Returns:
        (E * A, 2*H*W + 8 + 3*A) float32, row e * A + i = slot i of episode e.
    """
    grid, vector = actor_observation(spec, cfg, state, phase=phase)        # (E,A,2,H,W), (E,A,8)
    E, A = state.pos.shape
    critic = np.broadcast_to(critic_state(spec, cfg, state)[:, None, :], (E, A, 3 * A))
    flat = np.concatenate([grid.reshape(E, A, -1), vector, critic], axis=-1)
    return flat.reshape(E * A, -1).astype(np.float32)


def entry_dir(map_name: str, variant: str, zoo_dir=None) -> Path:
    """Folder of one zoo entry (it need not exist)."""
    return Path(zoo_dir or ZOO_DIR) / str(map_name).upper() / variant


def read_entry(path: Path) -> dict:
    """config.yml and eval.json of one entry folder, as one dict with its ``path``."""
    config_file = path / "config.yml"
    if not config_file.is_file():
        raise ZooError(f"{path}: no config.yml; not a zoo entry")
    config = yaml.safe_load(config_file.read_text()) or {}
    eval_file = path / "eval.json"
    evaluation = json.loads(eval_file.read_text()) if eval_file.is_file() else None
    return {"path": str(path), "config": config, "eval": evaluation}


def list_entries(zoo_dir=None) -> list[dict]:
    """Every entry of the zoo (maps A..D x variants), sorted by map then variant."""
    root = Path(zoo_dir or ZOO_DIR)
    return [read_entry(p.parent) for p in sorted(root.glob("*/*/config.yml"))]


def available(map_name: str, variant: str, zoo_dir=None) -> bool:
    """True when the zoo has a model for (map, variant)."""
    return (entry_dir(map_name, variant, zoo_dir) / "model.zip").is_file()


class ZooPolicy:
    """A trained shared policy acting for every slot of a batch of episodes.

    ``predict(sim_state, state=None, episode_start=None, deterministic=True)`` returns
    ``(actions, state)``: actions (E, A, 2) int (message symbol shown this step, move), and the
    recurrent state to pass back at the next call.
    """

    def __init__(self, model, spec, cfg: EnvConfig, info: dict):
        self.model = model
        self.spec = spec
        self.cfg = cfg
        self.info = info
        self.two_phase = cfg.comm != "none" and cfg.message_timing == "same_step"
        self.recurrent = hasattr(model.policy, "lstm_actor")

    def _act(self, sim_state, phase: int, lstm, starts):
        message_mask, move_mask = composite_action_mask(self.spec, self.cfg, sim_state,
                                                        message_phase=phase == 0)
        E, A = sim_state.pos.shape
        masks = np.concatenate([message_mask, move_mask], axis=-1).reshape(E * A, -1)
        obs = flat_observation(self.spec, self.cfg, sim_state, phase)
        if self.recurrent:
            actions, lstm = self.model.predict(obs, state=lstm, episode_start=starts,
                                               deterministic=self._deterministic, action_masks=masks)
        else:
            actions, _ = self.model.predict(obs, deterministic=self._deterministic, action_masks=masks)
        return np.asarray(actions).reshape(E, A, 2), lstm

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
        self._deterministic = deterministic
        E, A = sim.pos.shape
        if episode_start is None:
            episode_start = np.full(E, state is None)
        starts = np.repeat(np.asarray(episode_start, dtype=bool), A)
        active = sim.status == 0
        if self.two_phase:
            silent = dataclasses.replace(sim, messages=np.zeros_like(sim.messages))
            chosen, state = self._act(silent, 0, state, starts)
            symbols = np.where(active, chosen[..., 0] + 1, 0)
            shown = dataclasses.replace(sim, messages=symbols)
            chosen, state = self._act(shown, 1, state, np.zeros_like(starts))
            moves = chosen[..., 1]
        else:
            chosen, state = self._act(sim, 1, state, starts)
            moves = chosen[..., 1]
            symbols = np.where(active & (self.cfg.comm != "none"), chosen[..., 0] + 1, 0)
        return np.stack([symbols, moves], axis=-1).astype(np.int64), state


def load(map_name: str, variant: str, zoo_dir=None, spec=None) -> ZooPolicy:
    """Load a zoo model ready to act: ``patrolsb3.zoo.load("A", "rl-msg")``.

    Args:
        map_name: the map the model was trained on ("A" .. "D").
        variant: "rl-msg", "rl-no-msg" or "rl-intention".
        zoo_dir: another zoo folder (default: the repository's ``zoo/``).
        spec: the map to act on (default: ``map_name``); must match the training map's size.

    Raises:
        ZooError: no such entry (lists what the zoo has), or a checkpoint trained for another
            env version or map size.
    """
    if variant not in VARIANT_NAMES:
        raise ZooError(f"unknown variant {variant!r}; known: {', '.join(VARIANT_NAMES)}")
    folder = entry_dir(map_name, variant, zoo_dir)
    if not (folder / "model.zip").is_file():
        have = [f"{Path(e['path']).parent.name}/{Path(e['path']).name}" for e in list_entries(zoo_dir)]
        raise ZooError(f"no zoo model for map {str(map_name).upper()} variant {variant} "
                       f"(looked for {folder / 'model.zip'}); the zoo has: {', '.join(have) or 'nothing'}")
    info = read_entry(folder)
    config = info["config"]
    version = config.get("env_version")
    if version != ENV_VERSION:
        raise ZooError(f"{folder}: trained for env version {version!r}, this code is {ENV_VERSION!r}; "
                       f"retrain it or use a matching patrolsb3 release")
    spec = load_map(spec if spec is not None else map_name)
    trained_shape = tuple(config.get("map_shape", ()))
    if trained_shape != tuple(spec.shape):
        raise ZooError(f"{folder}: trained on a {trained_shape} map, cannot act on "
                       f"{spec.name} of size {spec.shape}")
    env_fields = {f.name for f in dataclasses.fields(EnvConfig)}
    env_cfg = {k: (tuple(v) if isinstance(v, list) else v)
               for k, v in (config.get("env") or {}).items() if k in env_fields}
    cfg = EnvConfig(**env_cfg)
    from .sb3.algorithms import get_algorithm
    algo = get_algorithm(config.get("algo", "MaskableRecurrentPPO"))
    model = algo.load(folder / "model.zip", device="cpu")
    return ZooPolicy(model, spec, cfg, info)
