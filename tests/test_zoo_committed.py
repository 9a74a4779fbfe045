"""The committed zoo, entry by entry: every entry loads, acts on its map for a few steps with
legal actions, and its files agree with its config.yml (map, variant, env version, budget,
evaluation). The unit tests use a zoo of their own (conftest's ``tiny_zoo``); this module is the
one place that reads the committed entries, so retraining the zoo changes no unit test's input."""
from pathlib import Path

import numpy as np
import pytest

from patrolsb3 import zoo
from patrolsb3.core import make_config
from patrolsb3.core.config import ENV_VERSION
from patrolsb3.evaluate import run_episodes

ZOO = Path(__file__).resolve().parents[1] / "zoo"
ENTRIES = zoo.list_entries(ZOO) if ZOO.is_dir() else []


@pytest.mark.skipif(not ENTRIES, reason="no committed zoo beside the tests (an installed package)")
@pytest.mark.parametrize("entry", ENTRIES, ids=lambda e: str(Path(e["path"]).relative_to(ZOO)))
def test_a_committed_entry_loads_acts_and_matches_its_config(entry):
    folder = Path(entry["path"])
    config = entry["config"]
    assert config["env_version"] == ENV_VERSION
    assert folder.parts[-2 if entry["seed"] is not None else -1] == config["variant"]
    assert config["budget"]["timesteps"] > 0
    policy = zoo.load_entry(folder)
    assert policy.spec.name == config["map"] and list(policy.spec.shape) == config["map_shape"]
    cfg = make_config(config["map"], **{**policy.env_settings(), "episode_steps": 10})
    figures = run_episodes(policy, policy.spec, cfg, 2, 1, seed=0)        # raises on an illegal action
    assert np.isfinite(figures["avg_idleness"]).all()
    if entry["eval"] is not None:
        sizes = [r["n_agents"] for r in entry["eval"]["results"]]
        assert sizes == list(range(1, len(sizes) + 1))
        assert all(r["strategy"].startswith("zoo:" + config["variant"]) for r in entry["eval"]["results"])
