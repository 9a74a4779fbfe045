"""Every parameter of the patrolling environment in one frozen dataclass.

Defaults follow the paper and ``docs/model.md``; unknown keys are refused loudly.
"""
from __future__ import annotations

import dataclasses
import math
from typing import Optional

import numpy as np

ENV_VERSION = "patrol_v1"
"""Version of the environment's rules; checkpoints record it and refuse a mismatch."""

COMM_MODES = ("none", "learned", "intention")
MESSAGE_TIMINGS = ("same_step", "delayed")
MESSAGE_ENCODINGS = ("scalar", "planes")
INVALID_ACTION_MODES = ("raise", "stay")

BOOL_FIELDS = ("return_guard", "local_idleness")
INT_FIELDS = {"max_agents": 1, "episode_steps": 1, "n_symbols": 1}
"""Integer fields and their smallest value (a fractional or boolean value is refused)."""
NUMBER_RANGES = {"b_max": (1e-9, math.inf), "step_minutes": (1e-9, math.inf), "c_norm": (1e-9, math.inf),
                 "push_drain_factor": (0.0, math.inf), "p_dyn_max": (0.0, 1.0), "fault_prob": (0.0, 1.0),
                 "b_low_frac": (0.0, 1.0), "c_rp": (0.0, math.inf), "c_pb": (0.0, math.inf),
                 "c_pbb": (0.0, math.inf), "c_pbm": (0.0, math.inf), "c_pc": (0.0, math.inf),
                 "c_home": (0.0, math.inf)}
"""Number fields and their closed range: finite, and > 0 where a zero would divide or empty
the battery (b_max, c_norm, step_minutes)."""
PAIR_RANGES = {"init_battery": (0.0, 1.0), "drain": (0.0, math.inf), "swap_time": (1.0, math.inf)}
"""(low, high) fields: each end in this range and low <= high (a drain below 0 would charge)."""


def _check_number(name: str, value, low: float, high: float) -> None:
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ValueError(f"{name} must be a number, got {value!r}")
    if not math.isfinite(value) or not low <= value <= high:
        bound = f">= {low:g}" if high == math.inf else f"in [{low:g}, {high:g}]"
        raise ValueError(f"{name} must be a finite number {'> 0' if low == 1e-9 else bound}, got {value!r}")


def _check_int(name: str, value, low: int) -> None:
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)) or value < low:
        raise ValueError(f"{name} must be a whole number >= {low}, got {value!r}")


# Per-map parameter changes taken from the paper (c_pbb is 0.5 on map B).
MAP_OVERRIDES = {"B": {"c_pbb": 0.5}}


@dataclasses.dataclass(frozen=True)
class EnvConfig:
    """Parameters of the patrolling world. Units: one step = ``step_minutes`` minutes; one
    battery unit = the nominal drain of one step."""

    max_agents: int = 5
    """Number of agent slots; observations and the critic state are padded to it."""
    episode_steps: int = 5000
    """Simulator steps per episode (truncation). Evaluation uses 14,400 (24 h)."""
    step_minutes: float = 0.1
    """Duration of one step in minutes (a 50 m cell at about 8.3 m/s)."""

    b_max: float = 550.0
    """Battery capacity in units (one unit = nominal drain of one step)."""
    init_battery: tuple = (0.9, 1.0)
    """Initial battery drawn uniformly in this range, as fractions of b_max."""
    drain: tuple = (0.9, 1.1)
    """Drain per step of an active agent, uniform in this range (units)."""
    push_drain_factor: float = 1.5
    """A pushed agent's drain is multiplied by this factor (fighting the wind)."""
    p_dyn_max: float = 0.05
    """Each agent's push probability p_dyn is drawn per episode from U[0, p_dyn_max]."""
    swap_time: tuple = (80, 150)
    """Hot-swap duration in steps, an integer drawn uniformly in [low, high] per swap."""
    b_low_frac: float = 0.2
    """b_l as a fraction of b_max: below it the battery penalty applies; heuristics plan
    to reach the station with about this much left."""

    c_norm: float = 200.0
    """Idleness normalisation f(i) = 1 - exp(-i / c_norm)."""
    c_rp: float = 0.5
    """Weight of the team patrol reward R'_p."""
    c_d: Optional[float] = None
    """Weight of the difference reward D_k; None means 50 / max_agents."""
    c_pb: float = 50.0
    """Penalty once when the battery runs out."""
    c_pbb: float = 1.0
    """Base of the low-battery penalty (0.5 on map B, see MAP_OVERRIDES)."""
    c_pbm: float = 20.0
    """Slope of the low-battery penalty: -(c_pbb + c_pbm (b_l - b) / b_l)."""
    c_pc: float = 1.0
    """Penalty to each agent in a collision event."""
    c_home: float = 0.0
    """OURS: weight of the home shaping, a difference of potentials that pulls an agent with
    a low battery toward the station (``core/reward.py``: ``home_potential``). 0, the
    paper's reward, by default."""

    return_guard: bool = False
    """OURS: a shield on the learned policy's moves. Once an agent's battery is at or below the
    heuristics' recharge threshold for its cell (``core/masks.py``: ``return_threshold``), its
    move mask keeps only the moves that bring it closer to a station (off a station and back
    when the wind pushed it there; it waits, with right of way, when its way is held), so it
    reaches the station with about ``b_l`` to spare and the policy learns the patrol only.
    The simulator's own rule is unchanged; off (the paper's agents, which learn the recharge)
    by default."""

    local_idleness: bool = False
    """OURS: append to the actor's vector the normalised idleness of the cell each move leads
    to (5 values, see ``core/observe.py``), so that "go where it is most idle" is learnable from
    the vector alone. Off for the paper's observation; the zoo's training turns it on."""

    n_symbols: int = 16
    """Size of the message alphabet (symbols 1..n_symbols; 0 is silence)."""
    comm: str = "learned"
    """'learned' (RIAL messages), 'intention' (symbol = intended move + 1, fixed meaning)
    or 'none' (positions only)."""
    message_timing: str = "same_step"
    """'same_step': a message phase precedes each move phase and everyone sees this step's
    symbols before moving; 'delayed': message and move are chosen together and the symbols
    are seen at the next step (classic RIAL)."""

    message_encoding: str = "scalar"
    """How positions and symbols reach the actor's grid. 'scalar' (the default, what the zoo's
    entries before 2026-12 were trained with): one channel holds both, an agent's cell showing
    (1 + symbol) / (n_symbols + 2), own positive, others negative, so neighbouring symbols
    differ by ~0.06. 'planes' (OURS, legible): channel 0 holds positions at full scale (self +1,
    others -0.5, station +0.5, obstacle -1), and n_symbols more channels hold one plane per
    symbol, +1 on the agent's own cell for its own symbol and -1 on each other agent's cell for
    theirs; every variant sees the positions alike (see ``core/observe.py``)."""

    fault_prob: float = 0.0
    """Per-step probability that each active agent suffers a hardware failure."""
    faults: tuple = ()
    """Scheduled failures: a tuple of (step, k) pairs; at that step k active agents (chosen
    at random) fail for good."""
    invalid_action: str = "raise"
    """What a masked (invalid) move does: 'raise' an error or be treated as 'stay'."""

    def __post_init__(self):
        for name, allowed in (("comm", COMM_MODES), ("message_timing", MESSAGE_TIMINGS),
                              ("message_encoding", MESSAGE_ENCODINGS), ("invalid_action", INVALID_ACTION_MODES)):
            if getattr(self, name) not in allowed:
                raise ValueError(f"{name} must be one of {allowed}, got {getattr(self, name)!r}")
        for name in BOOL_FIELDS:
            if not isinstance(getattr(self, name), (bool, np.bool_)):
                raise ValueError(f"{name} must be true or false, got {getattr(self, name)!r}")
        for name, low in INT_FIELDS.items():
            _check_int(name, getattr(self, name), low)
        for name, (low, high) in NUMBER_RANGES.items():
            _check_number(name, getattr(self, name), low, high)
        if self.c_d is not None:
            _check_number("c_d", self.c_d, 0.0, math.inf)
        for name, (low, high) in PAIR_RANGES.items():
            pair = getattr(self, name)
            if not isinstance(pair, (tuple, list)) or len(pair) != 2:
                raise ValueError(f"{name} must be a pair (low, high), got {pair!r}")
            for value in pair:
                _check_number(name, value, low, high)
            if pair[0] > pair[1]:
                raise ValueError(f"{name} must be (low, high) with low <= high, got {tuple(pair)}")
        for value in self.swap_time:
            _check_int("swap_time", value, 1)
        try:
            faults = tuple(tuple(f) for f in self.faults)
        except TypeError:
            raise ValueError(f"faults must be (step, k) pairs, got {self.faults!r}") from None
        for fault in faults:
            if len(fault) != 2:
                raise ValueError(f"faults must be (step, k) pairs, got {fault!r}")
            _check_int("faults step", fault[0], 0)
            _check_int("faults k", fault[1], 1)
        object.__setattr__(self, "faults", tuple(tuple(int(v) for v in f) for f in faults))

    @property
    def two_phase(self) -> bool:
        """True when a message phase precedes each move phase (same-step messages)."""
        return self.comm != "none" and self.message_timing == "same_step"

    @property
    def b_low(self) -> float:
        """b_l in battery units."""
        return self.b_low_frac * self.b_max

    @property
    def difference_weight(self) -> float:
        """c_d with its default 50 / max_agents applied."""
        return 50.0 / self.max_agents if self.c_d is None else self.c_d

    def to_dict(self) -> dict:
        """Plain dict (YAML/JSON friendly)."""
        return {k: (list(v) if isinstance(v, tuple) else v) for k, v in dataclasses.asdict(self).items()}


def make_config(map_name: Optional[str] = None, **overrides) -> EnvConfig:
    """Build an :class:`EnvConfig` with the paper's per-map values, then the caller's.

    Args:
        map_name: a shipped map name; its entries in MAP_OVERRIDES apply first.
        **overrides: any EnvConfig field.

    Raises:
        TypeError: an unknown parameter name (the message lists the known ones).
    """
    known = {f.name for f in dataclasses.fields(EnvConfig)}
    unknown = sorted(set(overrides) - known)
    if unknown:
        raise TypeError(f"unknown environment parameter(s) {unknown}; known: {sorted(known)}")
    values = dict(MAP_OVERRIDES.get(str(map_name).upper(), {})) if map_name else {}
    values.update({k: tuple(v) if isinstance(v, list) else v for k, v in overrides.items()})
    return EnvConfig(**values)
