"""Parameter-shared SB3 training: the SuperSuit vector env with masks, the variants, the
curriculum. Names added by the trainer modules are imported lazily (on first access)."""
from .curriculum import CURRICULUM, CurriculumCallback, curriculum_stage, lr_schedule
from .variants import VARIANTS
from .vec_env import PatrolVecEnv, make_vec_env

__all__ = ["CURRICULUM", "CurriculumCallback", "PatrolVecEnv", "VARIANTS", "curriculum_stage",
           "lr_schedule", "make_vec_env"]

# name -> module of the trainer's public names; imported on first access so that this package
# imports even while those modules are being written (and stays cheap to import).
_LAZY = {
    "MaskableRecurrentPPO": "maskable_recurrent_ppo",
    "ALGORITHMS": "algorithms",
    "evaluate": "evaluation",
    "train": "train",
}


def __getattr__(name):
    if name in _LAZY:
        import importlib
        return getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
