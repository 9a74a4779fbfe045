"""patrolsb3: multi-agent drone patrolling (the paper's model) with SB3 training, heuristics
and a model zoo."""
from .core import ENV_VERSION, EnvConfig, MapError, available_maps, load_map, make_config
from .env import PatrolParallelEnv, env, parallel_env

__version__ = "0.1.0"
__all__ = ["ENV_VERSION", "EnvConfig", "MapError", "available_maps", "load_map", "make_config",
           "PatrolParallelEnv", "env", "parallel_env", "__version__"]
