"""Parameter-shared SB3 training: the SuperSuit vector env with masks, the variants, the
curriculum, the algorithms (MaskableRecurrentPPO among them); the trainer is :func:`patrolsb3.sb3.train.train`."""
from .algorithms import ALGORITHMS
from .curriculum import CURRICULUM, CurriculumCallback, curriculum_stage, lr_schedule
from .evaluation import evaluate
from .maskable_recurrent_ppo import MaskableRecurrentPPO
from .variants import VARIANTS
from .vec_env import PatrolVecEnv, make_vec_env

__all__ = ["ALGORITHMS", "CURRICULUM", "CurriculumCallback", "MaskableRecurrentPPO", "PatrolVecEnv", "VARIANTS",
           "curriculum_stage", "evaluate", "lr_schedule", "make_vec_env"]
