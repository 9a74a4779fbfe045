"""Training algorithms by name: what class, what policy, whether it is recurrent and masked."""
from __future__ import annotations

import dataclasses

from .maskable_recurrent_ppo import MaskableRecurrentPPO
from .policy import PatrolMaskablePolicy, PatrolRecurrentPolicy


@dataclasses.dataclass(frozen=True)
class AlgorithmSpec:
    """How to build one algorithm.

    Attributes:
        name: registry name.
        recurrent: keeps an LSTM state (predict takes state and episode_start).
        masked: samples under the env's action masks (strict env); otherwise the env is
            built with ``strict=False`` so masked moves act as Stay.
        policy_keys: the policy_kwargs this algorithm's policy understands.
    """

    name: str
    recurrent: bool
    masked: bool
    policy_keys: tuple

    def classes(self):
        """(algorithm class, policy class), imported on demand (torch is heavy)."""
        from sb3_contrib import MaskablePPO, RecurrentPPO

        return {"MaskableRecurrentPPO": (MaskableRecurrentPPO, PatrolRecurrentPolicy),
                "MaskablePPO": (MaskablePPO, PatrolMaskablePolicy),
                "RecurrentPPO": (RecurrentPPO, PatrolRecurrentPolicy)}[self.name]


_COMMON = ("conv_channels", "dense_sizes", "ortho_init", "activation_fn")
_RECURRENT = _COMMON + ("lstm_hidden_size", "n_lstm_layers", "enable_critic_lstm")

ALGORITHMS = {
    "MaskableRecurrentPPO": AlgorithmSpec("MaskableRecurrentPPO", recurrent=True, masked=True, policy_keys=_RECURRENT),
    "MaskablePPO": AlgorithmSpec("MaskablePPO", recurrent=False, masked=True, policy_keys=_COMMON),
    "RecurrentPPO": AlgorithmSpec("RecurrentPPO", recurrent=True, masked=False, policy_keys=_RECURRENT),
}
"""Name -> spec. MaskableRecurrentPPO is ours (the paper's method); the two others are
sb3-contrib's, with our networks."""

DEFAULT_ALGORITHM = "MaskableRecurrentPPO"


def get_algorithm(name: str) -> AlgorithmSpec:
    """The spec of an algorithm name.

    Raises:
        ValueError: an unknown name (the message lists the known ones).
    """
    if name not in ALGORITHMS:
        raise ValueError(f"unknown algorithm {name!r}; known algorithms: {sorted(ALGORITHMS)}")
    return ALGORITHMS[name]


DEVICES = ("auto", "cpu", "cuda")
"""What ``--device`` takes: auto = cuda when torch sees a GPU, else cpu."""


def torch_device(name: str) -> str:
    """The torch device a ``--device`` value means.

    Raises:
        ValueError: a value not in :data:`DEVICES`, or "cuda" where torch sees no GPU.
    """
    if name not in DEVICES:
        raise ValueError(f"--device must be one of {', '.join(DEVICES)}, got {name!r}")
    import torch
    if name == "auto":
        return "cuda" if torch.cuda.is_available() else "cpu"
    if name == "cuda" and not torch.cuda.is_available():
        raise ValueError("--device cuda: torch sees no CUDA device here (use --device cpu or auto)")
    return name
