"""The patrolling simulator: numpy only (no PettingZoo, no torch), batched over episodes."""
from .config import ENV_VERSION, EnvConfig, make_config
from .maps import ACTION_NAMES, MapError, MapSpec, available_maps, load_map, parse_map
from .masks import action_mask
from .observe import actor_observation, critic_state
from .state import ABSENT, ACTIVE, FAILED, SWAPPING, State, reset_state
from .step import InvalidActionError, StepInfo, step

__all__ = ["ENV_VERSION", "EnvConfig", "make_config", "ACTION_NAMES", "MapError", "MapSpec",
           "available_maps", "load_map", "parse_map", "action_mask", "actor_observation",
           "critic_state", "ABSENT", "ACTIVE", "FAILED", "SWAPPING", "State", "reset_state",
           "InvalidActionError", "StepInfo", "step"]
