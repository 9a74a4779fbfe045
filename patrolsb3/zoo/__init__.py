"""The model zoo: trained checkpoints, loadable in one line (``patrolsb3.zoo.load("A", "rl-msg")``).

One job a module:

- :mod:`~patrolsb3.zoo.folders`: where the zoo is, the entry and seed folders of both settings
  (the paper's, and behind the return guard), reading an entry's files;
- :mod:`~patrolsb3.zoo.policy`: the :class:`ZooPolicy` adapter, a model acting like a heuristic
  (SB3's ``predict()`` on the batched simulator ``State``), and loading entries and checkpoints;
- :mod:`~patrolsb3.zoo.curation`: putting a training run into the zoo (``zoo export``);
- :mod:`~patrolsb3.zoo.validation`: choosing a checkpoint or an entry's default seed by
  validation (``zoo validate``, ``zoo choose``; it runs episodes, so import it by name);
- :mod:`~patrolsb3.zoo.results`: an entry's stored figures, one seed's or pooled over seeds, and
  the recipe its seeds were trained with;
- :mod:`~patrolsb3.zoo.cards`: the model cards (``zoo cards``; import it by name).

The strategy names (``zoo:<variant>``, ``zoo:<variant>:guarded``) and the variants live in
:mod:`patrolsb3.names`; the names of an entry's files in :class:`patrolsb3.runs.RunFolder`.
"""
from ..names import GUARDED, VARIANT_NAMES, strategy_name
from .curation import export, export_destination, replace_entry
from .folders import (
    DEFAULT_FILE,
    ZOO_DIR,
    ZOO_ENV,
    ZooError,
    available,
    default_seed,
    entry_dir,
    existing_entry_dir,
    list_entries,
    parse_strategy,
    read_entry,
    seed_curves,
    seeds,
    training_map,
    use_zoo_dir,
    variant_folder,
    zoo_root,
)
from .policy import ZooPolicy, checked_map, env_config, evaluation_config, load, load_checkpoint, load_entry
from .results import cached_result, pooled_result, recipe_of, trained_with

__all__ = ["DEFAULT_FILE", "GUARDED", "VARIANT_NAMES", "ZOO_DIR", "ZOO_ENV", "ZooError", "ZooPolicy",
           "available", "cached_result", "checked_map", "default_seed", "entry_dir", "env_config",
           "evaluation_config", "existing_entry_dir", "export", "export_destination", "list_entries", "load",
           "load_checkpoint", "load_entry", "parse_strategy", "pooled_result", "read_entry", "recipe_of",
           "replace_entry", "seed_curves", "seeds", "strategy_name", "trained_with", "training_map", "use_zoo_dir",
           "variant_folder", "zoo_root"]
