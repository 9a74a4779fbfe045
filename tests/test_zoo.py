"""The zoo: export of a run (policy only), loading with its checks, acting on the batched state."""
import json
import shutil
import zipfile
from pathlib import Path

import numpy as np
import pytest
import torch
import yaml

from patrolsb3 import zoo
from patrolsb3.commands import zoo as zoo_command
from patrolsb3.core import load_map, make_config, protocol, reset_state
from patrolsb3.core.streams import STREAMS_VERSION
from patrolsb3.evaluate import run_episodes
from patrolsb3.sb3 import make_vec_env
from patrolsb3.sb3.maskable_recurrent_ppo import MaskableRecurrentPPO
from patrolsb3.outputs import read_results
from patrolsb3.sb3.train import train

torch.set_num_threads(1)
ROOM_TEXT = "S.....\n......\n..#...\n......\n"


@pytest.fixture(scope="module")
def trained(tmp_path_factory):
    """A tiny real training run on a 4 x 6 room, exported into a temporary zoo."""
    root = tmp_path_factory.mktemp("zoo")
    map_file = root / "room.txt"
    map_file.write_text(ROOM_TEXT)
    hp = {"n_steps": 16, "n_minibatches": 2, "n_envs": 2, "eval_freq": 0, "checkpoint_freq": 10**9,
          "env": {"episode_steps": 20}, "policy_kwargs": {"dense_sizes": [32, 16], "lstm_hidden_size": 8}}
    run = train(map=str(map_file), variant="rl-msg", timesteps=800, run_dir=root / "run", hyperparams=hp,
                progress_bar=False, recipe="default")
    folder = zoo.export(run, zoo_dir=root / "zoo", budget={"cpu_hours": 0.001})
    return {"root": root, "map_file": map_file, "run": run, "folder": folder}


def test_export_keeps_the_policy_only_and_records_the_budget(trained):
    folder = trained["folder"]
    assert folder == trained["root"] / "zoo" / "ROOM" / "rl-msg" / "seed0"   # paper's setting: one folder a seed
    names = zipfile.ZipFile(folder / "model.zip").namelist()
    assert not any("optimizer" in n for n in names)
    run_names = zipfile.ZipFile(trained["run"] / "model.zip").namelist()
    assert any("optimizer" in n for n in run_names)
    config = yaml.safe_load((folder / "config.yml").read_text())
    assert config["env_version"] == "patrol_v1"
    assert config["budget"]["timesteps"] >= 800 and config["budget"]["cpu_hours"] == 0.001
    assert (folder / "curve.csv").is_file() and (folder / "command.txt").is_file()


def test_a_zoo_column_says_which_recipe_its_seeds_were_trained_with(trained):
    config = yaml.safe_load((trained["folder"] / "config.yml").read_text())
    assert config["recipe"] == "default"             # train records it, export keeps it
    c_d = 50 / config["env"]["max_agents"]           # the paper's default when c_d is not set
    assert zoo.trained_with("ROOM", "rl-msg", trained["root"] / "zoo") == \
        f"default (c_d {c_d:g}, gamma {config['hyperparams']['gamma']}, 20-step episodes): seed 0"
    config.pop("recipe")
    config["env"]["c_d"] = 200.0
    assert zoo.recipe_of(config).startswith("recipe not recorded (c_d 200, ")


def test_export_of_a_stopped_run_takes_its_newest_checkpoint(trained, tmp_path, monkeypatch):
    import shutil
    run = tmp_path / "stopped"
    shutil.copytree(trained["run"], run)
    (run / "checkpoints").mkdir(exist_ok=True)
    shutil.move(run / "model.zip", run / "checkpoints" / "model_800_steps.zip")
    monkeypatch.chdir(tmp_path)          # the repository root: sources are recorded relative to it
    folder = zoo.export(run, zoo_dir=tmp_path / "zoo")
    config = yaml.safe_load((folder / "config.yml").read_text())
    assert config["source_model"] == "stopped/checkpoints/model_800_steps.zip"   # no path of this machine
    assert config["source_run"] == "stopped"
    shutil.rmtree(run / "checkpoints")
    with pytest.raises(zoo.ZooError, match="no model.zip and no checkpoint"):
        zoo.export(run, zoo_dir=tmp_path / "zoo")


def test_export_of_a_warm_started_run_counts_both_stages(trained, tmp_path):
    hp = {"n_steps": 16, "n_minibatches": 2, "n_envs": 2, "eval_freq": 0, "checkpoint_freq": 10**9,
          "env": {"episode_steps": 20}, "policy_kwargs": {"dense_sizes": [32, 16], "lstm_hidden_size": 8}}
    # from the zoo entry (policy only): its budget is read from the entry's config.yml
    run = train(map=str(trained["map_file"]), variant="rl-msg", timesteps=320, run_dir=tmp_path / "warm",
                hyperparams=hp, init_from=trained["folder"], progress_bar=False)
    first = yaml.safe_load((trained["folder"] / "config.yml").read_text())["budget"]["timesteps"]
    folder = zoo.export(run, zoo_dir=tmp_path / "zoo")
    budget = yaml.safe_load((folder / "config.yml").read_text())["budget"]
    assert budget["timesteps_this_run"] == 320 and budget["timesteps"] == 320 + first


def test_zoo_policy_acts_like_the_trained_model(trained):
    policy = zoo.load("ROOM", "rl-msg", zoo_dir=trained["root"] / "zoo", spec=trained["map_file"])
    model = MaskableRecurrentPPO.load(str(trained["run"] / "model.zip"), device="cpu")
    spec = load_map(trained["map_file"])
    cfg = make_config(None, episode_steps=50)
    sim = reset_state(spec, cfg, [2, 3], n_envs=2, seed=1)
    actions, memory = policy.predict(sim, state=None, episode_start=np.ones(2, bool))
    # the same two phases through the training model
    E, A = sim.pos.shape
    silent = sim.copy()
    silent.messages[:] = 0
    decision = protocol.decide(spec, policy.cfg, silent, protocol.MESSAGE_PHASE)
    first, state = model.predict(decision.flat(policy.layout).reshape(E * A, -1), state=None,
                                 episode_start=np.ones(E * A, bool), deterministic=True,
                                 action_masks=decision.masks.reshape(E * A, -1))
    symbols = np.where(sim.status == 0, first[:, 0].reshape(E, A) + 1, 0)
    np.testing.assert_array_equal(actions[..., 0], symbols)
    shown = sim.copy()
    shown.messages = symbols
    decision = protocol.decide(spec, policy.cfg, shown, protocol.MOVE_PHASE)
    second, _ = model.predict(decision.flat(policy.layout).reshape(E * A, -1), state=state,
                              episode_start=np.zeros(E * A, bool), deterministic=True,
                              action_masks=decision.masks.reshape(E * A, -1))
    np.testing.assert_array_equal(actions[..., 1], second[:, 1].reshape(E, A))
    assert (actions[..., 1][sim.status != 0] == 4).all()


def test_zoo_policy_runs_strict_episodes_and_writes_eval(trained):
    policy = zoo.load("ROOM", "rl-msg", zoo_dir=trained["root"] / "zoo", spec=trained["map_file"])
    spec = load_map(trained["map_file"])
    cfg = make_config(None, episode_steps=60, invalid_action="raise")
    result = run_episodes(policy, spec, cfg, np.array([1, 2, 3]), 3, seed=0)
    assert result["avg_idleness"].shape == (3,)
    assert np.all(result["avg_idleness"] > 0)


def test_write_eval_on_every_team_size(trained):
    from patrolsb3.zoo.evaluation import write_zoo_eval
    path = write_zoo_eval(trained["folder"], episodes=2, steps=30, progress=False)
    data = json.loads(path.read_text())
    assert [r["n_agents"] for r in data["results"]] == [1, 2, 3, 4, 5]
    assert data["steps"] == 30 and data["episodes"] == 2
    assert all(r["summary"]["avg_idleness"]["mean"] > 0 for r in data["results"])
    assert data["results"][2]["bounds"]["v_over_k"] == pytest.approx(22 / 3)
    zoo_dir = trained["root"] / "zoo"
    hit = zoo.cached_result("ROOM", "rl-msg", 3, episodes=2, steps=30, seed=0, zoo_dir=zoo_dir)
    np.testing.assert_equal(hit, read_results(data["results"])[2])     # null (no swap) read back as NaN
    assert "NaN" not in path.read_text()                                 # strict JSON on disk
    assert zoo.cached_result("ROOM", "rl-msg", 3, episodes=2, steps=31, seed=0, zoo_dir=zoo_dir) is None
    assert zoo.cached_result("ROOM", "rl-no-msg", 3, episodes=2, steps=30, seed=0, zoo_dir=zoo_dir) is None
    assert zoo.cached_result("ROOM", "rl-msg", 3, episodes=2, steps=30, seed=0, zoo_dir=zoo_dir,
                             deterministic=False) is None       # another action mode
    assert data["deterministic"] is True and data["results"][2]["deterministic"] is True


def test_sampled_actions_are_seeded_and_differ_from_greedy(trained):
    policy = zoo.load("ROOM", "rl-msg", zoo_dir=trained["root"] / "zoo", spec=trained["map_file"])
    spec = load_map(trained["map_file"])
    cfg = make_config(None, episode_steps=60, invalid_action="raise")   # strict: sampled moves are legal

    def idleness(deterministic, seed):
        return run_episodes(policy, spec, cfg, 3, 4, seed=seed, deterministic=deterministic)["avg_idleness"]

    np.testing.assert_array_equal(idleness(False, 1), idleness(False, 1))
    assert not np.array_equal(idleness(False, 1), idleness(False, 2))
    assert not np.array_equal(idleness(False, 1), idleness(True, 1))


def test_refusals_name_the_problem(trained, tmp_path):
    zoo_dir = trained["root"] / "zoo"
    with pytest.raises(zoo.ZooError, match="unknown variant"):
        zoo.load("ROOM", "rl-telepathy", zoo_dir=zoo_dir)
    with pytest.raises(zoo.ZooError, match="the zoo has: ROOM/rl-msg"):
        zoo.load("A", "rl-msg", zoo_dir=zoo_dir)
    with pytest.raises(zoo.ZooError, match=r"trained on a \(4, 6\) map"):
        zoo.load("ROOM", "rl-msg", zoo_dir=zoo_dir, spec="A")
    # another env version
    other = tmp_path / "zoo" / "ROOM" / "rl-msg" / "seed0"
    other.mkdir(parents=True)
    for name in ("model.zip", "config.yml"):
        (other / name).write_bytes((trained["folder"] / name).read_bytes())
    config = yaml.safe_load((other / "config.yml").read_text())
    config["env_version"] = "patrol_v0"
    (other / "config.yml").write_text(yaml.safe_dump(config))
    with pytest.raises(zoo.ZooError, match="env version 'patrol_v0'"):
        zoo.load("ROOM", "rl-msg", zoo_dir=tmp_path / "zoo", spec=trained["map_file"])
    # a broken model file
    config["env_version"] = "patrol_v1"
    (other / "config.yml").write_text(yaml.safe_dump(config))
    (other / "model.zip").write_bytes(b"not a zip")
    with pytest.raises(zoo.ZooError, match="empty, cut or corrupt"):
        zoo.load("ROOM", "rl-msg", zoo_dir=tmp_path / "zoo", spec=trained["map_file"])


def test_the_local_idleness_layout_travels_with_the_checkpoint(trained, tmp_path):
    # the vec env's rows carry the local idleness
    vec = make_vec_env(map="B", agents=[3], variant="rl-no-msg", seed=3, local_idleness=True)
    obs = vec.reset()
    assert obs.shape == (5, 2 * 12 * 12 + 20 + 15)
    # a run trained with it exports, loads and acts with it (its config.yml says so)
    hp = {"n_steps": 16, "n_minibatches": 2, "n_envs": 2, "eval_freq": 0, "checkpoint_freq": 10**9,
          "env": {"episode_steps": 20, "local_idleness": True},
          "policy_kwargs": {"dense_sizes": [32, 16], "lstm_hidden_size": 8}}
    run = train(map=str(trained["map_file"]), variant="rl-msg", timesteps=320, run_dir=tmp_path / "run",
                hyperparams=hp, progress_bar=False)
    zoo.export(run, zoo_dir=tmp_path / "zoo", budget={"cpu_hours": 0.001})
    policy = zoo.load("ROOM", "rl-msg", zoo_dir=tmp_path / "zoo", spec=trained["map_file"])
    assert policy.cfg.local_idleness
    spec = load_map(trained["map_file"])
    sim = reset_state(spec, make_config(None, episode_steps=50), [2, 3], n_envs=2, seed=1)
    actions, _ = policy.predict(sim, state=None, episode_start=np.ones(2, bool))
    assert actions.shape == (2, 5, 2)
    # the same weights under a config without it are refused, naming the layout
    path = tmp_path / "zoo" / "ROOM" / "rl-msg" / "seed0" / "config.yml"
    config = yaml.safe_load(path.read_text())
    config["env"]["local_idleness"] = False
    path.write_text(yaml.safe_dump(config))
    with pytest.raises(zoo.ZooError, match="another observation layout"):
        zoo.load("ROOM", "rl-msg", zoo_dir=tmp_path / "zoo", spec=trained["map_file"])


def test_zoo_list_prints_budget_and_headline_figures(trained, capsys):
    from patrolsb3 import cli
    from patrolsb3.commands.zoo import headline
    assert cli.main(["zoo", "list", "--zoo-dir", str(trained["root"] / "zoo")]) == 0
    out = capsys.readouterr().out
    assert "room/rl-msg" in out and "0.001 CPU h" in out and "return guard" not in out
    ok = {"max_idleness": {"mean": 12.4}, "avg_idleness": {"mean": 5.2}, "collisions": {"mean": 1.54},
          "battery_failure_rate": {"mean": 0.0}}
    failed = {**ok, "max_idleness": {"mean": float("nan")}, "avg_idleness": {"mean": float("nan")},
              "battery_failure_rate": {"mean": 1.0}}
    entry = {"eval": {"episodes": 2, "steps": 30, "results": [{"n_agents": 1, "summary": ok},
                                                               {"n_agents": 2, "summary": failed}]}}
    text = headline(entry)
    assert "n=1: MAX 12 AVG 5 col 1.5 BF 0.00" in text
    assert "n=2: MAX/AVG/col n/a (a battery failure in every episode) BF 1.00" in text and "nan" not in text


def test_a_model_trained_behind_the_return_guard_acts_behind_it(trained, tmp_path, capsys):
    import shutil
    from patrolsb3.core.masks import action_mask, return_threshold
    shutil.copytree(trained["folder"], tmp_path / "zoo" / "guarded" / "ROOM" / "rl-msg")
    path = tmp_path / "zoo" / "guarded" / "ROOM" / "rl-msg" / "config.yml"
    config = yaml.safe_load(path.read_text())
    config["env"]["return_guard"] = True
    path.write_text(yaml.safe_dump(config))
    with pytest.raises(zoo.ZooError, match="in the main zoo .*the zoo has: ROOM/rl-msg:guarded"):
        zoo.load("ROOM", "rl-msg", zoo_dir=tmp_path / "zoo", spec=trained["map_file"])   # the default is not the shield
    guarded = zoo.load("ROOM", "rl-msg", zoo_dir=tmp_path / "zoo", spec=trained["map_file"], guard=True)
    plain = zoo.load("ROOM", "rl-msg", zoo_dir=trained["root"] / "zoo", spec=trained["map_file"])
    assert guarded.cfg.return_guard and not plain.cfg.return_guard
    spec = load_map(trained["map_file"])
    cfg = make_config(None, episode_steps=50)
    sim = reset_state(spec, cfg, [4, 4], n_envs=2, seed=1)
    sim.battery[:] = return_threshold(spec, guarded.cfg)[sim.pos]                # every agent due home
    shield = action_mask(spec, sim, guarded.cfg)                                # (2, 5, 5)
    assert (shield.sum(axis=-1)[sim.active] < action_mask(spec, sim).sum(axis=-1)[sim.active]).any()
    outside = {}
    for name, policy in (("guarded", guarded), ("plain", plain)):
        policy.seed_sampling(0)
        moves = np.stack([policy.predict(sim, deterministic=False)[0][..., 1] for _ in range(20)])  # (20, 2, 5)
        chosen = np.take_along_axis(np.broadcast_to(shield, (20,) + shield.shape), moves[..., None], -1)[..., 0]
        outside[name] = int((~chosen & sim.active).sum())
    assert outside["guarded"] == 0 and outside["plain"] > 0
    from patrolsb3 import cli
    assert cli.main(["zoo", "list", "--zoo-dir", str(tmp_path / "zoo")]) == 0
    listed = capsys.readouterr().out
    assert "room/rl-msg" in listed and "behind the return guard" in listed


def test_corrupt_files_and_configs_are_refused_in_one_line(trained, tmp_path):
    import shutil

    from patrolsb3.core import MapError, load_map
    copy = tmp_path / "zoo"
    shutil.copytree(trained["root"] / "zoo", copy)
    (entry,) = [p.parent for p in copy.glob("*/*/seed*/model.zip")]
    model = entry / "model.zip"
    data = bytearray(model.read_bytes())
    data[len(data) // 2] ^= 0xFF                      # flipped bytes: the CRC check fails
    model.write_bytes(bytes(data))
    with pytest.raises(zoo.ZooError, match="empty, cut or corrupt"):
        zoo.load("ROOM", "rl-msg", zoo_dir=copy, spec=trained["map_file"])
    (entry / "config.yml").write_text("map: [unclosed\n")
    with pytest.raises(ValueError, match="not valid YAML"):
        zoo.list_entries(copy)
    with pytest.raises(zoo.ZooError, match="does not know: \\['warp_drive'\\]"):
        zoo.env_config({"env": {"warp_drive": True}})
    # an edited env version in a run's config.yml is refused by load_checkpoint
    run = tmp_path / "run"
    shutil.copytree(trained["run"], run)
    text = (run / "config.yml").read_text()
    (run / "config.yml").write_text(text.replace("env_version: patrol_v1", "env_version: patrol_v0"))
    with pytest.raises(zoo.ZooError, match="env version 'patrol_v0'"):
        zoo.load_checkpoint(run / "model.zip", spec=trained["map_file"])
    binary = tmp_path / "map.txt"
    binary.write_bytes(b"S..\n.\xff.\n")
    with pytest.raises(MapError, match=r"map.txt:2:2: not a text map"):
        load_map(binary)


def test_seeds_of_an_entry_and_the_default_chosen_by_validation(trained, tmp_path, capsys):
    import shutil

    from patrolsb3.cli import main
    copy = tmp_path / "zoo"
    shutil.copytree(trained["root"] / "zoo", copy)
    assert zoo.seeds("ROOM", "rl-msg", zoo_dir=copy) == [0]
    assert zoo.default_seed("ROOM", "rl-msg", zoo_dir=copy) == {"seed": 0, "chosen_by": "the only seed"}
    policy = zoo.load("ROOM", "rl-msg", zoo_dir=copy, spec=trained["map_file"], seed=0)
    assert policy.info["path"].endswith("seed0")
    with pytest.raises(zoo.ZooError, match="no seed 3 of ROOM/rl-msg"):
        zoo.load("ROOM", "rl-msg", zoo_dir=copy, spec=trained["map_file"], seed=3)
    # a second seed (its config says seed 1): no default until validation picks one
    shutil.copytree(copy / "ROOM" / "rl-msg" / "seed0", copy / "ROOM" / "rl-msg" / "seed1")
    path = copy / "ROOM" / "rl-msg" / "seed1" / "config.yml"
    path.write_text(path.read_text().replace("\nseed: 0\n", "\nseed: 1\n"))
    assert [e["seed"] for e in zoo.list_entries(copy)] == [0, 1]          # each seed is an entry folder
    with pytest.raises(zoo.ZooError, match="seeds \\[0, 1\\] and no default.yml; run 'patrolsb3 zoo choose ROOM rl-msg'"):
        zoo.load("ROOM", "rl-msg", zoo_dir=copy, spec=trained["map_file"])
    assert main(["zoo", "choose", "ROOM", "rl-msg", "--zoo-dir", str(copy), "--agents", "1,2",
                 "--episodes", "1", "--steps", "30"]) == 0
    out = capsys.readouterr().out
    chosen = yaml.safe_load((copy / "ROOM" / "rl-msg" / "default.yml").read_text())
    assert f"default: seed {chosen['seed']}" in out and "seed 7" in chosen["chosen_by"]
    rows = {r["seed"]: r for r in chosen["validation"]}
    same = ("failures", "bf_rate", "avg_idleness")
    assert [rows[0][k] for k in same] == [rows[1][k] for k in same] and chosen["seed"] == 0   # a tie: seed order
    assert zoo.load("ROOM", "rl-msg", zoo_dir=copy, spec=trained["map_file"]).info["path"].endswith("seed0")
    (copy / "ROOM" / "rl-msg" / "default.yml").write_text("seed: 4\n")
    with pytest.raises(zoo.ZooError, match="names seed 4, the entry has \\[0, 1\\]"):
        zoo.load("ROOM", "rl-msg", zoo_dir=copy, spec=trained["map_file"])


def test_strategy_names_select_the_shelf():
    assert zoo.parse_strategy("zoo:rl-msg") == ("rl-msg", "")
    assert zoo.parse_strategy("ZOO:RL-MSG:guarded") == ("rl-msg", "guarded")
    assert zoo.strategy_name("rl-no-msg", "guarded") == "zoo:rl-no-msg:guarded"
    for bad, why in (("zoo:rl-msg:shielded", "not a shelf of the zoo"), ("zoo:telepathy", "unknown variant"),
                     ("CR", "not a zoo strategy")):
        with pytest.raises(zoo.ZooError, match=why):
            zoo.parse_strategy(bad)


def test_an_entry_on_a_recipe_shelf_is_its_own_column_beside_the_main_zoo(trained, tmp_path, capsys):
    from patrolsb3 import cli
    from patrolsb3.zoo.cards import entry_name, load_line
    from patrolsb3.zoo.evaluation import write_zoo_eval
    root = tmp_path / "zoo"
    shutil.copytree(trained["root"] / "zoo", root)
    folder = zoo.export(trained["run"], zoo_dir=root, budget={"cpu_hours": 0.001}, shelf="paper-recipe")
    assert folder == root / "paper-recipe" / "ROOM" / "rl-msg" / "seed0"
    assert zoo.seeds("ROOM", "rl-msg", root, shelf="paper-recipe") == [0]
    assert not zoo.available("ROOM", "rl-msg", root, shelf="cd10")
    shelved = zoo.load("ROOM", "rl-msg", zoo_dir=root, spec=trained["map_file"], shelf="paper-recipe")
    assert Path(shelved.info["path"]) == folder
    assert Path(zoo.load("ROOM", "rl-msg", zoo_dir=root, spec=trained["map_file"]).info["path"]) == root / "ROOM" / "rl-msg" / "seed0"
    assert zoo.trained_with("ROOM", "rl-msg", root, shelf="paper-recipe").endswith(": seed 0")
    results = json.loads(write_zoo_eval(folder, episodes=1, steps=20, progress=False).read_text())
    assert results["strategy"] == "zoo:rl-msg:paper-recipe"                  # the eval.json says which column
    entries = {(e["shelf"], e["seed"]) for e in zoo.list_entries(root)}
    assert entries == {("", 0), ("paper-recipe", 0)}
    shelf_entry = next(e for e in zoo.list_entries(root) if e["shelf"])
    assert entry_name(shelf_entry) == "paper-recipe/room/rl-msg/seed0"              # the map as config.yml names it
    assert "shelf='paper-recipe', seed=0" in load_line(shelf_entry) and "zoo:rl-msg:paper-recipe" in load_line(shelf_entry)
    with pytest.raises(zoo.ZooError, match="--shelf guarded: .* without the return guard"):
        zoo.export_destination(trained["run"], zoo_dir=root, shelf="guarded")
    with pytest.raises(zoo.ZooError, match="--shelf 'e2': not a shelf of the zoo"):
        zoo.export_destination(trained["run"], zoo_dir=root, shelf="e2")
    with pytest.raises(zoo.ZooError, match="no zoo model .* on the shelf 'cd10'"):
        zoo.load("ROOM", "rl-msg", zoo_dir=root, shelf="cd10")
    assert cli.main(["zoo", "show", "room", "rl-msg", "--zoo-dir", str(root), "--shelf", "paper-recipe"]) == 0
    assert "paper-recipe" in json.loads(capsys.readouterr().out)["path"]
    assert cli.main(["zoo", "show", "room", "rl-msg", "--zoo-dir", str(root), "--shelf", "cd10", "--guarded"]) == 2
    assert "--guarded and --shelf cd10" in capsys.readouterr().err


def test_a_card_says_the_precision_of_each_stretch_of_training():
    from patrolsb3.zoo.cards import precision_text
    assert precision_text({"hyperparams": {}}) == "fp32"
    changed = {"hyperparams": {"precision": "bf16"},
               "precision_changes": [{"timesteps": 8800000, "precision": "fp32", "why": "no native bf16"}]}
    assert precision_text(changed) == "bf16 to 8,800,000 agent-steps, then fp32"


def test_claims_on_a_shelf_put_its_columns_in_place_of_the_main_zoos():
    from patrolsb3.commands.claims import on_shelf
    from patrolsb3.report import column_strategy
    figures = {("A", 3, name, "collisions"): name for name in
               ("CR", "zoo:rl-msg", "zoo:rl-no-msg", "zoo:rl-msg:paper-recipe", "zoo:rl-msg:guarded")}
    assert on_shelf(figures, "") == {("A", 3, n, "collisions"): n for n in ("CR", "zoo:rl-msg", "zoo:rl-no-msg")}
    assert on_shelf(figures, "paper-recipe") == {("A", 3, "CR", "collisions"): "CR",
                                                 ("A", 3, "zoo:rl-msg", "collisions"): "zoo:rl-msg:paper-recipe",
                                                 ("A", 3, "zoo:rl-no-msg", "collisions"): "zoo:rl-no-msg"}
    assert column_strategy("MSG-PAPER-RECIPE") == "zoo:rl-msg:paper-recipe"
    assert column_strategy("NOMSG-GUARDED") == "zoo:rl-no-msg:guarded" and column_strategy("SEBS") == "SEBS"


def test_config_files_are_read_through_a_schema(tmp_path):
    from patrolsb3.runs import ConfigError, read_config
    path = tmp_path / "config.yml"
    path.write_text("map: A\nvariant: rl-msg\nwarp: 9\n")
    with pytest.raises(ConfigError, match=r"does not know: \['warp'\]"):
        read_config(path)
    path.write_text("map: A\nseed: first\n")
    with pytest.raises(ConfigError, match="seed must be of type int"):
        read_config(path)


def test_zoo_eval_rewrites_eval_json_with_intervals_and_the_card_shows_them(trained, tmp_path):
    import shutil

    from patrolsb3.cli import main
    from patrolsb3.zoo.cards import card
    copy = tmp_path / "zoo"
    shutil.copytree(trained["root"] / "zoo", copy)
    assert main(["zoo", "eval", "ROOM", "rl-msg", "--zoo-dir", str(copy), "--episodes", "3", "--steps", "20"]) == 0
    entry = zoo.read_entry(copy / "ROOM" / "rl-msg" / "seed0")
    avg = entry["eval"]["results"][0]["summary"]["avg_idleness"]
    acts_under = entry["eval"]["results"][0]["policy_settings"]          # what the policy saw, recorded
    assert acts_under["message_encoding"] == entry["config"]["env"].get("message_encoding", "scalar")
    assert "ci95" in avg and len(avg["episodes"]) == 3 and np.mean(avg["episodes"]) == pytest.approx(avg["mean"])
    text = card(entry)
    assert "| 1 | " in text and " [" in text.split("| 1 | ", 1)[1].split("\n")[0]   # intervals in the table


def fake_seed_eval(folder, seed, values, episodes_kept=True, episodes=10, draws=STREAMS_VERSION):
    """A seed folder with a stand-in model and an eval.json for n = 1 whose AVG^h episodes are
    ``values`` (no per-episode figures when ``episodes_kept`` is False), evaluated under ``draws``."""
    import json
    path = folder / f"seed{seed}"
    path.mkdir(parents=True)
    (path / "model.zip").write_bytes(b"")
    metric = {"mean": float(np.mean(values)), "std": 0.0, "tests": [float(np.mean(values))],
              "ci95": [float(min(values)), float(max(values))]}
    if episodes_kept:
        metric["episodes"] = [float(v) for v in values]
    result = {"strategy": "zoo:rl-msg", "map": "A", "n_agents": 1, "episodes": episodes, "tests": 1,
              "steps": 100, "seed": 0, "faults": [], "deterministic": True,
              "summary": {"avg_idleness": metric, "clean_episodes": [len(values)]}}
    (path / "eval.json").write_text(json.dumps({"episodes": episodes, "steps": 100, "seed": 0, "tests": 1,
                                                "deterministic": True, "draws": draws, "results": [result]}))


def test_seeds_are_pooled_episode_by_episode_and_the_unusable_ones_named(tmp_path):
    folder = tmp_path / "A" / "rl-msg"
    low, high = np.linspace(10, 11, 10), np.linspace(20, 21, 10)      # seed 0 and seed 1: far apart
    fake_seed_eval(folder, 0, low)
    fake_seed_eval(folder, 1, high)
    (folder / "default.yml").write_text("seed: 0\nchosen_by: test\n")
    args = ("A", "rl-msg", 1, 10, 100, 0)
    r = zoo.pooled_result(*args, zoo_dir=tmp_path)
    s = r["summary"]["avg_idleness"]
    assert r["training_seeds"] == [0, 1] and r["unpooled_seeds"] == []
    assert s["mean"] == pytest.approx(np.concatenate([low, high]).mean())
    assert s["tests"] == pytest.approx([low.mean(), high.mean()]) and len(s["episodes"]) == 20
    assert s["units"] == [pytest.approx(list(low)), pytest.approx(list(high))]      # each seed's episodes, for pairing
    # the interval spans the two seeds' spread, far wider than either seed's own
    assert s["ci95"][0] < 16 < s["ci95"][1] and s["ci95"][1] - s["ci95"][0] > 3
    assert r["summary"]["clean_episodes"] == [10, 10]
    # a seed evaluated before per-episode figures were kept is left out, and said to be
    fake_seed_eval(folder, 2, high, episodes_kept=False)
    r = zoo.pooled_result(*args, zoo_dir=tmp_path)
    assert r["training_seeds"] == [0, 1] and r["unpooled_seeds"] == [2]
    # one usable seed: its own result unchanged; another protocol: nothing to reuse
    fake_seed_eval(tmp_path / "A" / "rl-no-msg", 0, low)
    one = zoo.pooled_result("A", "rl-no-msg", 1, 10, 100, 0, zoo_dir=tmp_path)
    assert one["summary"]["avg_idleness"]["ci95"] == [10.0, 11.0] and one["training_seeds"] == [0]
    assert zoo.pooled_result("A", "rl-msg", 1, 20, 100, 0, zoo_dir=tmp_path) is None
    # an eval.json of the draws from before paired episodes is not reused
    fake_seed_eval(tmp_path / "A" / "rl-intention", 0, low, draws=None)
    assert zoo.pooled_result("A", "rl-intention", 1, 10, 100, 0, zoo_dir=tmp_path) is None


def test_cards_gather_each_entrys_listening_and_ablation_into_a_messages_page(trained, tmp_path):
    from patrolsb3.zoo.cards import write_cards
    copy = tmp_path / "zoo"
    shutil.copytree(trained["root"] / "zoo", copy)
    entry = copy / "ROOM" / "rl-msg" / "seed0"
    (entry / "listening.json").write_text(json.dumps({
        "kl_nats": 0.1234, "greedy_changed": 0.05, "symbols_used": 7, "symbol_entropy_bits": 2.5,
        "mi_own_move_bits": 0.6, "mi_others_moves_bits": 0.1, "n_agents": 3, "episodes": 2, "steps": 50, "seed": 1000}))
    figure = {"mean": 10.0, "change": 1.0, "change_ci95": [0.5, 1.5]}          # excludes zero: starred
    level = {"mean": 9.0, "change": 0.2, "change_ci95": [-0.4, 0.8]}           # covers zero: no star
    (entry / "ablation.json").write_text(json.dumps({
        "baseline": {"avg_idleness": 9.0, "max_idleness": 20.0, "collisions": 3.0},
        "constant": {"avg_idleness": figure, "max_idleness": level, "collisions": level},
        "shuffled": {"avg_idleness": level, "max_idleness": level, "collisions": level},
        "n_agents": 3, "episodes": 2, "steps": 50, "seed": 1000}))
    out = tmp_path / "cards"
    write_cards(out, zoo_dir=copy)
    page = (out / "messages.md").read_text()
    listening_row = next(line for line in page.splitlines() if "rl-msg/seed0 | 0.123 |" in line)
    assert "7 of 16" in listening_row
    ablation_row = [line for line in page.splitlines() if "rl-msg/seed0 | +1.0 [" in line]
    assert ablation_row and ablation_row[0].count(" *") == 1           # only the interval clear of zero
    card_text = next(p for p in out.glob("*rl-msg-seed0.md")).read_text()
    assert "## What its messages carry" in card_text and "| constant | 10.0 (+1.0 [+0.5, +1.5] *)" in card_text
    assert "messages.md" in (out / "index.md").read_text()


def test_a_card_without_message_figures_has_no_messages_section(trained):
    from patrolsb3.zoo.cards import card
    entry = zoo.read_entry(trained["folder"])
    assert "What its messages carry" not in card(entry)


def test_the_export_command_refuses_an_existing_entry_and_never_leaves_old_figures_beside_a_new_model(
        trained, tmp_path, capsys, monkeypatch):
    import shutil

    from patrolsb3 import cli
    zoo_dir = tmp_path / "zoo"
    common = ["zoo", "export", str(trained["run"]), "--zoo-dir", str(zoo_dir)]
    assert cli.main(common + ["--episodes", "1", "--steps", "20"]) == 0
    entry = zoo_dir / "ROOM" / "rl-msg" / "seed0"
    (entry / "listening.json").write_text("{}")             # a figure of this model
    model = (entry / "model.zip").read_bytes()
    capsys.readouterr()
    # an existing entry: refused in one line, nothing touched
    assert cli.main(common + ["--episodes", "1", "--steps", "20"]) == 2
    err = capsys.readouterr().err.strip()
    assert "is an entry already; pass --overwrite" in err and len(err.splitlines()) == 1
    # bad arguments are refused before anything is written, --overwrite or not
    for bad in (["--episodes", "0"], ["--steps", "-5"], ["--seed", "-1"], ["--checkpoint", str(tmp_path / "none.zip")]):
        assert cli.main(common + ["--overwrite"] + bad) == 2
        assert bad[0] in capsys.readouterr().err
    # an evaluation that fails half-way (Ctrl-C) leaves the old entry whole, figures included
    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt
    monkeypatch.setattr(zoo_command, "write_zoo_eval", interrupted)
    assert cli.main(common + ["--overwrite", "--episodes", "1", "--steps", "20"]) != 0
    assert "interrupted" in capsys.readouterr().err
    assert (entry / "model.zip").read_bytes() == model and (entry / "listening.json").is_file()
    assert sorted(p.name for p in entry.parent.iterdir() if not p.name.endswith(".lock")) == ["seed0"]  # no staging left
    # a second export of the same entry while one is running is refused
    from filelock import FileLock
    with FileLock(entry.with_name(".seed0.lock")):
        assert cli.main(common + ["--overwrite", "--episodes", "1", "--steps", "20"]) == 2
        assert "is being exported by another process" in capsys.readouterr().err
    monkeypatch.undo()
    # --overwrite replaces the entry whole: the old model's figures go with it
    other = tmp_path / "other_run"
    shutil.copytree(trained["run"], other)
    assert cli.main(["zoo", "export", str(other), "--zoo-dir", str(zoo_dir), "--overwrite", "--episodes", "1",
                     "--steps", "20"]) == 0
    assert not (entry / "listening.json").exists() and (entry / "eval.json").is_file()
    assert str(other) in yaml.safe_load((entry / "config.yml").read_text())["source_run"]


def test_an_entry_of_a_map_file_that_moved_still_loads_from_its_config(tmp_path):
    """config.yml records a map file by its resolved path and, for a map not shipped, its text:
    an entry acts after the map file was moved or from another working directory."""
    map_file = tmp_path / "maps" / "room.txt"
    map_file.parent.mkdir()
    map_file.write_text(ROOM_TEXT)
    link = tmp_path / "room_link.txt"
    link.symlink_to(map_file)
    hp = {"n_steps": 16, "n_minibatches": 2, "n_envs": 2, "eval_freq": 0, "checkpoint_freq": 10**9,
          "env": {"episode_steps": 20}, "policy_kwargs": {"dense_sizes": [16], "lstm_hidden_size": 8}}
    run = train(map=str(link), variant="rl-msg", timesteps=320, run_dir=tmp_path / "run", hyperparams=hp,
                progress_bar=False)
    config = yaml.safe_load((run / "config.yml").read_text())
    assert config["map_source"] == str(map_file.resolve()) and config["map_text"].startswith("S.....")
    folder = zoo.export(run, zoo_dir=tmp_path / "zoo")
    map_file.rename(tmp_path / "elsewhere.txt")
    policy = zoo.load_entry(folder)
    assert policy.spec.shape == (4, 6) and policy.spec.to_text() == config["map_text"]


def test_no_zoo_record_names_a_folder_of_the_machine_it_was_made_on():
    """config.yml and command.txt of every shipped entry, sweep and snapshot name paths relative
    to the repository (a fresh clone elsewhere reads them the same)."""
    import re
    root = Path(__file__).resolve().parents[1] / "zoo"
    machine_path = re.compile(r"(?<![\w.])/(?:work|home|tmp|Users|root|mnt|data)/")
    offending = [str(p.relative_to(root)) for pattern in ("**/config.yml", "**/*.config.yml", "**/command.txt")
                 for p in root.glob(pattern) if machine_path.search(p.read_text())]
    assert offending == []
