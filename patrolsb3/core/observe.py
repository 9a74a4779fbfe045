"""Actor observations and the centralised critic state (docs/model.md, section 3).

Grid channel 0 (positions and messages), values divided by ``n_symbols + 2``:

* vertex 0, obstacle -1, station +1;
* an active agent with symbol ``m`` (0 = silent) is written on its cell as ``1 + m``, positive
  for the observing agent itself and negative for the others, so all agent values lie
  strictly inside (-1, 1) and never equal the station's or an obstacle's value;
* others standing on a station are not drawn (the station is shared); an observer on a
  station sees its own value there.

Grid channel 1 (idleness): f(i) = 1 - exp(-i / c_norm) on vertices (1 if never visited),
-1 on obstacles, 0 on stations.

With ``cfg.message_encoding == 'planes'`` (OURS, legible messages) channel 0 holds positions
only, at full scale (self +1, other agents -0.5, station +0.5, obstacle -1, vertex 0; others on
a station are not drawn, as above), and channels 2 .. 1 + n_symbols hold one plane per symbol:
plane 1 + s is +1 on the observer's own cell when it shows symbol s and -1 on the cell of
every other agent (drawn on channel 0) showing s. Symbols then differ by a whole channel, not
by 0.06 of one, and every variant sees the others' positions at the same scale. With 'scalar'
messages (the default) the layout is the paper-like one above.

Vector: [own battery fraction, own move mask (5), phase (0 message, 1 move), active flag,
home distance, battery margin, home direction (5)]:

* home distance = shortest-path steps to the nearest station / (H + W), at most 1;
* battery margin = battery fraction - steps home x the largest drain / b_max (clipped to
  [-1, 1]): about 0 when the battery would only just bring the agent home;
* home direction = one-hot of the first move of a shortest path to the nearest station
  (Stay on a station).

The last three are OURS, not the paper's (its actor sees the graph and its battery only): a
compass to the station, so that the recharge decision is learnable within a CPU budget. Every
learned variant gets them alike. They are 0 for inactive slots.

With ``cfg.local_idleness`` (OURS, off by default) the vector goes on with the local
idleness: for each move (Up, Down, Left, Right, Stay) the value channel 1 shows on the cell
it leads to (f on a vertex, 0 on a station), -1 for a move off the map or into an obstacle.
It is a copy of five grid values next to the agent, so that the patrol rule of CR ("go to the
most idle neighbour") is learnable from the vector without the convolution first finding
the agent on the grid.

Critic state: for every slot its battery fraction, row / (H-1) and col / (W-1); an absent
or failed slot is padded with battery 1 and the station's position (the paper's padding).
"""
from __future__ import annotations

import functools

import numpy as np

from .config import EnvConfig
from .maps import OBSTACLE, STATION, MapSpec
from .masks import action_mask
from .reward import normalised_idleness
from .state import ACTIVE, State

VECTOR_SIZE = 15
"""Length of the actor's vector observation without the local idleness."""
PHASE_INDEX = 6
"""Index of the phase (0 message, 1 move) in the actor's vector."""
LOCAL_IDLENESS_SIZE = 5
"""Values the local idleness adds (one per move)."""
_ONE_HOT = np.eye(5, dtype=np.float32)  # (5, 5) one-hot row of each move
OTHER_AGENT = -0.5
"""'planes' messages: channel 0 value of another agent's cell (self is +1, obstacle -1)."""
STATION_PLANES = 0.5
"""'planes' messages: channel 0 value of a station (no agent's value)."""


def grid_channels(cfg: EnvConfig) -> int:
    """Channels of the actor's grid: 2 ('scalar' messages), 2 + n_symbols ('planes')."""
    return 2 + (cfg.n_symbols if cfg.message_encoding == "planes" else 0)


def vector_size(cfg: EnvConfig) -> int:
    """Length of the actor's vector observation under ``cfg``."""
    return VECTOR_SIZE + (LOCAL_IDLENESS_SIZE if cfg.local_idleness else 0)


@functools.lru_cache(maxsize=64)
def _home_tables(spec: MapSpec, drain_high: float) -> tuple[np.ndarray, np.ndarray]:
    """Per-cell parts of :func:`home_features` that depend on the map only.

    Returns:
        features (H*W, 7) float32: home distance, 0 (the margin, filled per slot), home
        direction one-hot (5); reserve (H*W,) float64: steps home x ``drain_high``.
    """
    H, W = spec.shape
    features = np.zeros((spec.kinds.size, 7), dtype=np.float32)
    features[:, 0] = np.minimum(spec.steps_home / (H + W), 1.0)
    features[:, 2:] = _ONE_HOT[spec.home_move]
    reserve = spec.steps_home * drain_high
    features.flags.writeable = reserve.flags.writeable = False
    return features, reserve


def home_features(spec: MapSpec, cfg: EnvConfig, state: State) -> np.ndarray:
    """Home distance, battery margin and home direction of every slot (see module docstring).

    Returns:
        (E, A, 7) float32, zeros for inactive slots.
    """
    features, reserve = _home_tables(spec, float(cfg.drain[1]))
    out = features[state.pos]                                                  # (E, A, 7) a copy
    margin = (state.battery - reserve[state.pos]) / cfg.b_max                  # (E, A)
    out[..., 1] = np.minimum(np.maximum(margin, -1.0), 1.0)
    out[~state.active] = 0.0
    return out


@functools.lru_cache(maxsize=64)
def _position_base(spec: MapSpec, planes: bool = False) -> np.ndarray:
    """(H*W,) float32 channel 0 without agents: vertex 0, obstacle -1, station +1 ('scalar'
    messages) or STATION_PLANES ('planes')."""
    kinds = spec.kinds.ravel()
    station = STATION_PLANES if planes else 1.0
    return np.where(kinds == OBSTACLE, -1.0, np.where(kinds == STATION, station, 0.0)).astype(np.float32)


def _draw_symbol_planes(grid: np.ndarray, state: State, drawn: np.ndarray) -> None:
    """Write the symbol planes of 'planes' messages into ``grid`` (E, A, 2 + n_symbols, H*W):
    plane 2 + (s - 1) holds symbol s, +1 on an observer's own cell for its own symbol, -1 on
    the cell of every other agent drawn on channel 0 (off the station) for theirs. Silent
    slots (symbol 0) draw nothing."""
    A = state.pos.shape[1]
    speaks = drawn & (state.messages > 0)                                      # (E, A) others we draw
    seen = speaks[:, None, :] & ~np.eye(A, dtype=bool)[None]                   # (E, observer, other)
    e_o, i_o, j_o = np.nonzero(seen)
    grid[e_o, i_o, 1 + state.messages[e_o, j_o], state.pos[e_o, j_o]] = -1.0
    e_s, i_s = np.nonzero(state.active & (state.messages > 0))
    grid[e_s, i_s, 1 + state.messages[e_s, i_s], state.pos[e_s, i_s]] = 1.0


@functools.lru_cache(maxsize=64)
def _idleness_base(spec: MapSpec) -> np.ndarray:
    """(H*W,) float32 channel 1 before the vertices are filled: obstacle -1, else 0."""
    return np.where(spec.kinds.ravel() == OBSTACLE, -1.0, 0.0).astype(np.float32)


def grid_size(spec: MapSpec) -> int:
    """H * W."""
    return spec.kinds.size


def actor_observation(spec: MapSpec, cfg: EnvConfig, state: State, phase: int = 1,
                      mask: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Every slot's view.

    Args:
        spec: the map.
        cfg: environment parameters.
        state: batched state.
        phase: 0 in a message phase, 1 in a move phase.
        mask: (E, A, 5) move mask if already computed.

    Returns:
        grid (E, A, grid_channels(cfg), H, W) float32 and vector (E, A, vector_size(cfg)) float32.
    """
    E, A = state.pos.shape
    H, W = spec.shape
    grid = np.empty((E, A, grid_channels(cfg), H * W), dtype=np.float32)       # (E, A, C, H*W)
    draw_positions(spec, cfg, state, grid)                                     # channels 0, 2 ..
    grid[:, :, 1] = _idleness_base(spec)
    grid[:, :, 1, spec.vertex_cells] = normalised_idleness(state.idle, state.visited, cfg.c_norm)[:, None]

    if mask is None:
        mask = action_mask(spec, state, cfg)
    active = state.active                                                      # (E, A)
    vector = np.empty((E, A, vector_size(cfg)), dtype=np.float32)
    vector[..., 0] = state.battery / cfg.b_max
    vector[..., 1:6] = mask
    vector[..., PHASE_INDEX] = phase
    vector[..., 7] = active
    vector[..., 8:VECTOR_SIZE] = home_features(spec, cfg, state)
    if cfg.local_idleness:
        chan1 = grid[:, 0, 1]                                                  # (E, H*W) alike for all
        target = spec.neighbour[state.pos]                                     # (E, A, 5)
        local = np.take_along_axis(chan1, target.reshape(E, A * 5), axis=1).reshape(E, A, 5)
        local[~spec.move_ok[state.pos]] = -1.0                                 # off map, obstacle
        local[~active] = 0.0
        vector[..., VECTOR_SIZE:] = local
    return grid.reshape(E, A, grid.shape[2], H, W), vector


def draw_positions(spec: MapSpec, cfg: EnvConfig, state: State, grid: np.ndarray) -> None:
    """Write the part of every slot's grid that the symbols shown can change, in place:
    channel 0 (positions, and the symbols with 'scalar' messages) and, with 'planes'
    messages, the symbol planes (channels 2 ..). Channel 1 (idleness) is left as it is.

    Args:
        grid: (E, A, grid_channels(cfg), H*W) float32, overwritten on those channels.
    """
    E, A = state.pos.shape
    planes = cfg.message_encoding == "planes"
    active = state.active                                                      # (E, A)
    if planes:   # positions at full scale; the symbols go to their own planes below
        own, other = np.ones((E, A)), np.full((E, A), OTHER_AGENT)             # (E, A) each
    else:
        own = (1.0 + state.messages) / float(cfg.n_symbols + 2)                # (E, A) slot j's value
        other = -own
    # what every observer sees of the others: agents off the station (active agents never
    # share a cell off the station, so no two writes collide)
    grid[:, :, 0] = _position_base(spec, planes)
    pos = state.pos
    drawn = active & _off_station(spec)[pos]                                   # (E, A)
    e_d, j_d = np.nonzero(drawn)
    grid[e_d, :, 0, pos[e_d, j_d]] = other[e_d, j_d, None]                     # every observer of e
    # each active observer sees itself positive on its own cell (station included)
    e_s, i_s = np.nonzero(active)
    grid[e_s, i_s, 0, pos[e_s, i_s]] = own[e_s, i_s]
    if planes:
        grid[:, :, 2:] = 0.0
        _draw_symbol_planes(grid, state, drawn)


def critic_state(spec: MapSpec, cfg: EnvConfig, state: State) -> np.ndarray:
    """Centralised information every slot's critic gets besides the actor view.

    Returns:
        (E, 3 * A) float32: battery fraction, row / (H-1), col / (W-1) of each slot.
    """
    E, A = state.pos.shape
    present = state.status == ACTIVE
    pos = np.where(present, state.pos, spec.station)
    out = np.empty((E, A, 3), dtype=np.float32)
    out[..., 0] = np.where(present, state.battery / cfg.b_max, 1.0)
    out[..., 1:] = _cell_coordinates(spec)[pos]
    return out.reshape(E, 3 * A)


@functools.lru_cache(maxsize=64)
def _cell_coordinates(spec: MapSpec) -> np.ndarray:
    """(H*W, 2) float32 row / (H-1) and col / (W-1) of every cell (the critic's positions)."""
    H, W = spec.shape
    row, col = np.divmod(np.arange(H * W), W)
    out = np.stack([row / max(H - 1, 1), col / max(W - 1, 1)], axis=1).astype(np.float32)
    out.flags.writeable = False
    return out


@functools.lru_cache(maxsize=64)
def _off_station(spec: MapSpec) -> np.ndarray:
    """(H*W,) bool, True on every cell but the stations."""
    out = spec.kinds.ravel() != STATION
    out.flags.writeable = False
    return out
