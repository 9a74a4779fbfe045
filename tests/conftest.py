"""Shared tiny maps and helpers that build deterministic simulator states by hand.

Every scripted test starts from :func:`reset_state` and then overwrites the plain numpy
fields of the state (positions, batteries, push probabilities), so the expected positions,
rewards and idleness can be written down exactly.
"""
from __future__ import annotations

import pytest

from patrolsb3.core import make_config, parse_map, reset_state

# 1 x 6 corridor, station at the left end: vertices are (0, 1) .. (0, 5).
LINE = "S....."

# 3 x 7, non-square on purpose (axis mix-ups show up as wrong cells or index errors):
#   row 0:  S . . # . . 2
#   row 1:  . # . . . . .
#   row 2:  . . . # 5 . .
NON_SQUARE = "S..#..2\n.#.....\n...#5.."

# 1 x 5 with the station in the middle: two agents may both enter it at once.
MIDDLE_STATION = "..S.."

# 3 x 3 room, station in the centre, one priority-3 corner.
ROOM = "3..\n.S.\n..."


def deterministic_config(**overrides):
    """An EnvConfig with no randomness left in the drain and no pushes (unless overridden)."""
    values = dict(drain=(1.0, 1.0), p_dyn_max=0.0)
    values.update(overrides)
    return make_config(**values)


def place(spec, cfg, cells, battery=None, seed=0):
    """A one-episode state with agents standing exactly on ``cells``.

    Args:
        spec: the map.
        cfg: environment parameters.
        cells: list of (row, col), one per deployed agent (slot order).
        battery: list of battery units per agent (default: full, ``cfg.b_max``).
        seed: seed of the state's generator.

    Returns:
        A :class:`~patrolsb3.core.state.State` with n_envs = 1, p_dyn = 0, idleness 0 and
        every vertex marked visited.
    """
    state = reset_state(spec, cfg, len(cells), n_envs=1, seed=seed)
    W = spec.shape[1]
    for k, (r, c) in enumerate(cells):
        state.pos[0, k] = r * W + c
    state.battery[0, :len(cells)] = cfg.b_max if battery is None else battery
    state.p_dyn[:] = 0.0
    state.idle[:] = 0.0
    state.visited[:] = True
    return state


def cell(spec, r, c):
    """Cell index of (row, col)."""
    return r * spec.shape[1] + c


def streams_drawing_pushes(n_slots, wanted, limit=10_000):
    """Random streams of one episode whose first step pushes slots in the wanted directions.

    ``core.step`` reads each step's push directions from the episode's world stream
    (:class:`patrolsb3.core.streams.StepDraws`); with ``p_dyn = 1`` a slot is always pushed.

    Args:
        n_slots: A (max_agents).
        wanted: {slot: direction}.

    Returns:
        The :class:`EpisodeStreams` of the first seed that draws those directions; assign it to
        ``state.streams`` before the step.
    """
    from patrolsb3.core.streams import EpisodeStreams
    for seed in range(limit):
        direction = EpisodeStreams(seed, [0], n_slots).step().push_direction()[0]
        if all(direction[k] == d for k, d in wanted.items()):
            return EpisodeStreams(seed, [0], n_slots)
    raise AssertionError(f"no seed below {limit} draws pushes {wanted}")


@pytest.fixture
def line_map():
    return parse_map(LINE, name="line")


@pytest.fixture
def non_square_map():
    return parse_map(NON_SQUARE, name="non_square")


@pytest.fixture
def middle_station_map():
    return parse_map(MIDDLE_STATION, name="middle_station")


@pytest.fixture
def room_map():
    return parse_map(ROOM, name="room")


@pytest.fixture(scope="session")
def tiny_zoo(tmp_path_factory):
    """A zoo of its own for unit tests (not the committed one, which retraining changes): map A,
    rl-msg and rl-no-msg, each a few hundred agent-steps of a small network with the zoo's
    observation settings (symbol planes, local idleness), exported as seed 0.

    Returns:
        The zoo folder, for ``zoo.load("A", variant, zoo_dir=...)``.
    """
    from patrolsb3 import zoo
    from patrolsb3.sb3.train import train
    root = tmp_path_factory.mktemp("tiny_zoo")
    hp = {"n_steps": 8, "n_minibatches": 1, "n_envs": 2, "eval_freq": 0, "checkpoint_freq": 10 ** 9,
          "precision": "fp32", "env": {"episode_steps": 20, "message_encoding": "planes", "local_idleness": True},
          "policy_kwargs": {"dense_sizes": [32, 16], "lstm_hidden_size": 8}}
    for variant in ("rl-msg", "rl-no-msg"):
        run = train(map="A", variant=variant, timesteps=160, run_dir=root / "runs" / variant, seed=0,
                    hyperparams=hp, progress_bar=False)
        zoo.export(run, zoo_dir=root / "zoo")
    return root / "zoo"
