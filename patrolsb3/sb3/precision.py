"""Training precision: fp32, or bf16 mixed precision where the CPU computes bf16 natively.

``precision`` (a hyperparameter; ``--precision`` on train, sweep and bench train) takes

* ``fp32``: every computation in float32 (what every zoo entry was trained with);
* ``bf16``: the networks' trunks (convolutions, Dense stack, LSTM) run under
  ``torch.autocast(dtype=torch.bfloat16)`` in the rollout's forward and in the update's forward
  and backward; the heads (logits, value), the distributions, losses, advantages, value targets,
  the weights, their gradients and Adam's state stay float32 (autocast keeps weights in fp32
  and casts copies; the trunk's output is cast back to fp32 before the heads);
* ``auto`` (the default): ``bf16`` on a CPU with native bf16 arithmetic (x86 ``avx512_bf16``
  or ``amx_bf16``, Arm ``bf16``), ``fp32`` elsewhere, GPUs included (the equivalence runs of
  docs/experiments/2026-12-07-afternoon.md were made on a CPU).

Prediction (``policy.predict``: evaluation, the zoo, the heuristics' comparisons) is always
fp32, whatever trained the weights: a checkpoint acts the same whichever precision trained it.
"""
from __future__ import annotations

import contextlib
import platform
import sys
from functools import lru_cache
from pathlib import Path

PRECISIONS = ("auto", "fp32", "bf16")
"""What ``precision`` takes."""

NATIVE_BF16_FLAGS = ("avx512_bf16", "amx_bf16", "bf16")
"""/proc/cpuinfo flags of native bf16 arithmetic (x86: AVX512-BF16, AMX-BF16; Arm: FEAT_BF16)."""


@lru_cache(maxsize=1)
def cpu_info() -> dict:
    """{"name": the CPU's model name, "native_bf16": whether it computes bf16 natively,
    "bf16_flags": the flags that say so}, read from /proc/cpuinfo (Linux); elsewhere the
    platform's processor name and no native bf16."""
    path = Path("/proc/cpuinfo")
    name, flags = platform.processor() or platform.machine(), set()
    if path.is_file():
        for line in path.read_text(errors="replace").splitlines():
            key, _, value = line.partition(":")
            key = key.strip().lower()
            if key == "model name" and name in ("", platform.machine(), platform.processor()):
                name = value.strip()
            elif key in ("flags", "features"):
                flags.update(value.split())
    found = sorted(f for f in NATIVE_BF16_FLAGS if f in flags)
    return {"name": name, "native_bf16": bool(found), "bf16_flags": found}


def resolve_precision(precision: str, device: str = "cpu") -> str:
    """The precision a run trains with: ``fp32`` or ``bf16``.

    Args:
        precision: ``auto``, ``fp32`` or ``bf16``.
        device: the torch device type the networks train on ("cpu" or "cuda").

    Raises:
        ValueError: a value not in :data:`PRECISIONS`, or ``bf16`` on a CUDA device without bf16.
    """
    if precision not in PRECISIONS:
        raise ValueError(f"precision must be one of {', '.join(PRECISIONS)}, got {precision!r}")
    device = str(device).split(":")[0]
    if precision == "auto":
        return "bf16" if device == "cpu" and cpu_info()["native_bf16"] else "fp32"
    if precision == "bf16" and device == "cuda":
        import torch
        if not torch.cuda.is_bf16_supported():
            raise ValueError("precision bf16: this CUDA device has no bf16 (use fp32)")
    return precision


def resumed_precision(recorded: str, asked: str, device: str = "cpu", started: str | None = None) -> tuple[str, str]:
    """The precision a resumed run goes on in, and why it changed ("" when it did not).

    A run keeps the precision it trained with last, with two exceptions that follow the machine
    (bf16 and fp32 learn alike: docs/training.md, "Precision"):

    * a bf16 run resumed where bf16 is not native (a CPU without ``avx512_bf16`` /
      ``amx_bf16`` / Arm ``bf16``) goes on in fp32 unless ``bf16`` is asked for explicitly.
      Emulated bf16 is several times slower than fp32 (on an AMD EPYC without AVX512-BF16, one
      rollout and update of issue 43's E2 took more than 415 CPU seconds in emulated bf16,
      against 160-200 in fp32);
    * a run that started in bf16 and went on in fp32 for that reason goes back to bf16 where
      bf16 is native again, unless ``fp32`` is asked for explicitly (on an AMD EPYC with
      AVX512-BF16, bf16 halves the update: docs/benchmarks.md).

    Args:
        recorded: the precision the run trained with last (config.yml: its hyperparams'
            ``precision``, or the latest ``precision_changes`` entry).
        asked: this call's ``precision`` hyperparameter (``auto``, ``fp32`` or ``bf16``).
        device: the torch device type the networks train on.
        started: the precision the run started with (config.yml's hyperparams), None if unknown.
    """
    device = str(device).split(":")[0]
    native = device == "cuda" or cpu_info()["native_bf16"]
    if recorded == "bf16" and not native and asked != "bf16":
        return "fp32", "this machine has no native bf16 (emulated bf16 is several times slower; bf16 and fp32 learn alike)"
    if recorded == "fp32" and started == "bf16" and native and asked != "fp32":
        return "bf16", "this machine has native bf16: back to the bf16 the run started in (bf16 and fp32 learn alike)"
    return recorded, ""


def warned_if_emulated(precision: str, device_type: str) -> str:
    """``precision``, after a note on stderr when it is bf16 on a CPU without native bf16 (asked
    for explicitly: torch emulates it, several times slower than fp32)."""
    if precision == "bf16" and str(device_type).startswith("cpu") and not cpu_info()["native_bf16"]:
        print("precision bf16: this CPU has no native bf16, so torch emulates it, several times slower "
              "than fp32 (precision auto picks fp32 here)", file=sys.stderr)
    return precision


def autocast(precision: str, device_type: str):
    """The context the networks' trunks run in: bf16 autocast for ``bf16``, nothing for ``fp32``.

    Args:
        precision: a resolved precision (``fp32`` or ``bf16``).
        device_type: "cpu" or "cuda".
    """
    if precision != "bf16":
        return contextlib.nullcontext()
    import torch
    return torch.autocast(device_type=device_type, dtype=torch.bfloat16)
