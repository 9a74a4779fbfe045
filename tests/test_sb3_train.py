"""train(): run folder, --resume (step count, curriculum, curve), clear errors, algorithms by
name, and a learning run on a corridor that beats RANDOM."""
import csv

import numpy as np
import pytest
import torch as th
import yaml

from patrolsb3.core import parse_map
from patrolsb3.runs import RunFolder
from patrolsb3.sb3 import make_vec_env
from patrolsb3.sb3.evaluation import RandomMaskedPolicy, evaluate
from patrolsb3.sb3.hyperparams import parse_set, per_phase, schedule
from patrolsb3.sb3.cpu_time import cpu_hours_of
from patrolsb3.sb3.maskable_recurrent_ppo import MaskableRecurrentPPO
from patrolsb3.sb3.train import curriculum_teams, mixed_episodes, train


th.set_num_threads(1)
ROOM = parse_map("S.....\n......\n......\n......", name="room")
CORRIDOR = parse_map("S.......", name="corridor")
SMALL_NET = {"dense_sizes": [32, 32], "lstm_hidden_size": 16}


def tiny_hp(**extra):
    hp = {"n_steps": 10, "n_minibatches": 2, "eval_freq": 0, "checkpoint_freq": 400,
          "env": {"episode_steps": 5}, "policy_kwargs": dict(SMALL_NET)}
    hp.update(extra)
    return hp


def read_curve(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def test_run_folder_contents(tmp_path):
    run = train(map=ROOM, timesteps=800, out=tmp_path, hyperparams=tiny_hp(eval_freq=400, eval_episode_steps=3),
                progress_bar=False)
    assert run == tmp_path / "room" / "rl-msg" / "MaskableRecurrentPPO_seed0"
    for name in ("model.zip", "config.yml", "command.txt", "curve.csv", "eval.csv"):
        assert (run / name).is_file(), name
    assert any((run / "tb").rglob("events.out.tfevents*"))
    config = yaml.safe_load((run / "config.yml").read_text())
    assert config["map"] == "room" and config["map_shape"] == [4, 6] and config["versions"]["env_version"]
    assert config["hyperparams"]["gamma"] == 0.95 and config["env"]["episode_steps"] == 5
    eval_rows = read_curve(run / "eval.csv")
    assert sorted({int(r["n_agents"]) for r in eval_rows}) == [1, 2, 3, 4, 5]


def test_resume_continues_steps_curriculum_and_curve(tmp_path):
    # 40 rows x 10 env steps per rollout = 400 timesteps; episodes of 5 sim steps = 10 env steps.
    run = train(map=ROOM, timesteps=400, out=tmp_path, hyperparams=tiny_hp(), progress_bar=False)
    first_rows = len(read_curve(run / "curve.csv"))
    assert RunFolder(run).newest_checkpoint().name == "model_400_steps.zip"
    # total 2000: at 400 the progress is 0.2 -> stage 1 (teams 1,1,1,1,2,2,3,3), not stage 0
    train(map=ROOM, timesteps=2000, out=tmp_path, hyperparams=tiny_hp(), resume=True, progress_bar=False)
    model = MaskableRecurrentPPO.load(run / "model.zip", device="cpu")
    assert model.num_timesteps == 2000
    assert RunFolder(run).newest_checkpoint().name == "model_2000_steps.zip"
    rows = read_curve(run / "curve.csv")
    assert len(rows) > first_rows
    resumed_first = [r for r in rows[first_rows:] if int(r["timesteps"]) == 800]
    assert {int(r["n_agents"]) for r in resumed_first} == {1, 2, 3}      # stage 1's teams right away
    assert len((run / "command.txt").read_text().splitlines()) == 2


def test_resume_errors(tmp_path):
    with pytest.raises(FileNotFoundError, match="checkpoints"):
        train(map=ROOM, timesteps=400, out=tmp_path, hyperparams=tiny_hp(), resume=True, progress_bar=False)
    run = train(map=ROOM, timesteps=400, out=tmp_path, hyperparams=tiny_hp(), progress_bar=False)
    with pytest.raises(ValueError, match="--resume"):
        train(map=ROOM, timesteps=400, out=tmp_path, hyperparams=tiny_hp(), progress_bar=False)
    other = parse_map("S.....\n......\n......\n.....#", name="room")
    with pytest.raises(ValueError, match="map_shape|env"):
        train(map=parse_map("S......\n.......\n.......\n.......", name="room"), timesteps=800, run_dir=run,
              hyperparams=tiny_hp(), resume=True, progress_bar=False)
    config = yaml.safe_load((run / "config.yml").read_text())
    config["versions"]["env_version"] = "patrol_v0"
    (run / "config.yml").write_text(yaml.safe_dump(config))
    with pytest.raises(ValueError, match="env version"):
        train(map=other, timesteps=800, run_dir=run, hyperparams=tiny_hp(), resume=True, progress_bar=False)


@pytest.mark.parametrize("kwargs,match", [({"algo": "PPO2"}, "known algorithms"),
                                          ({"variant": "rl-telepathy"}, "known variants"),
                                          ({"hyperparams": {"gama": 0.9}}, "unknown hyperparameter")])
def test_bad_names_list_the_known_ones(tmp_path, kwargs, match):
    with pytest.raises(ValueError, match=match):
        train(map=ROOM, timesteps=400, out=tmp_path, progress_bar=False, **kwargs)


@pytest.mark.parametrize("algo", ["MaskablePPO", "RecurrentPPO"])
def test_other_algorithms_by_name(tmp_path, algo):
    policy_kwargs = SMALL_NET if algo == "RecurrentPPO" else {"dense_sizes": [32, 32]}
    run = train(map=ROOM, timesteps=400, out=tmp_path, algo=algo, progress_bar=False,
                hyperparams=tiny_hp(policy_kwargs=policy_kwargs, eval_freq=400, eval_episode_steps=3))
    assert (run / "model.zip").is_file() and (run / "eval.csv").is_file()
    assert yaml.safe_load((run / "config.yml").read_text())["algo"] == algo


def test_hyperparameter_helpers():
    assert parse_set(["n_steps=128", "policy_kwargs.lstm_hidden_size=64", "env.episode_steps=10"]) == \
        {"n_steps": 128, "policy_kwargs": {"lstm_hidden_size": 64}, "env": {"episode_steps": 10}}
    lr = schedule("drop_2e-4_1e-4")
    assert lr(1.0) == 2e-4 and lr(0.34) == 2e-4 and lr(0.33) == 1e-4
    assert schedule("lin_1e-3")(0.5) == pytest.approx(5e-4)
    with pytest.raises(ValueError, match="lin_"):
        schedule("cosine")
    assert per_phase(0.95, 2) ** 2 == pytest.approx(0.95)
    assert curriculum_teams(2, 5)[-1] == [1, 5] and curriculum_teams(8, 3)[-1] == [1, 1, 1, 1, 2, 3, 3, 3]


def test_learns_to_beat_random_on_a_corridor(tmp_path):
    env_kwargs = {"max_agents": 1, "episode_steps": 30, "p_dyn_max": 0.0}
    # 24,000 steps: trained/random was 0.40-0.52 over seeds 0-3 (sb3 2.9.2, an Intel host); at
    # 12,000 it was 0.60-0.82. On an AMD EPYC host (2026-12-06, same packages) seed 0 did not
    # learn (1.05) while seeds 1 and 2 reached 0.49 and 0.53: one seed's run depends on the CPU's
    # float kernels, so the test asks the median of three seeds to beat random by 20 %
    env = make_vec_env(CORRIDOR, agents=[1] * 8, variant="rl-no-msg", seed=5, **env_kwargs)
    random = np.mean([r["mean_idleness"] for r in evaluate(RandomMaskedPolicy(seed=1), env)])
    ratios = []   # trained / random mean idleness, one per training seed
    for seed in (0, 1, 2):
        run = train(map=CORRIDOR, variant="rl-no-msg", timesteps=24000, run_dir=tmp_path / f"r{seed}",
                    seed=seed, progress_bar=False,
                    hyperparams={"n_envs": 4, "curriculum": False, "n_steps": 60, "n_minibatches": 4,
                                 "n_epochs": 4, "learning_rate": 1e-3, "eval_freq": 0, "env": env_kwargs,
                                 "policy_kwargs": {"dense_sizes": [64, 64], "lstm_hidden_size": 32}})
        model = MaskableRecurrentPPO.load(run / "model.zip", device="cpu")
        ratios.append(np.mean([r["mean_idleness"] for r in evaluate(model, env)]) / random)
    assert np.median(ratios) < 0.8, ratios


def test_reward_normalisation_saves_and_resumes_its_statistics(tmp_path):
    from stable_baselines3.common.vec_env import VecNormalize

    from patrolsb3.sb3.train import normalized_rewards
    VECNORMALIZE_FILE = RunFolder.STATISTICS
    run = train(map=ROOM, timesteps=400, out=tmp_path, hyperparams=tiny_hp(normalize_reward=True),
                progress_bar=False)
    stats_file = run / "checkpoints" / VECNORMALIZE_FILE.format(400)
    assert stats_file.is_file()
    saved = VecNormalize.load(str(stats_file), make_vec_env(ROOM, agents=[1] * 8, seed=0))
    assert not saved.norm_obs and saved.norm_reward
    assert saved.ret_rms.count > 100           # updated at every env step
    # resume loads those statistics instead of starting fresh ones
    resumed = normalized_rewards(make_vec_env(ROOM, agents=[1] * 8, seed=0), RunFolder(run).newest_checkpoint(), gamma=0.9)
    assert resumed.ret_rms.count == saved.ret_rms.count
    train(map=ROOM, timesteps=800, out=tmp_path, hyperparams=tiny_hp(normalize_reward=True), resume=True,
          progress_bar=False)
    assert (run / "checkpoints" / VECNORMALIZE_FILE.format(800)).is_file()


def test_init_from_starts_a_new_run_from_the_weights(tmp_path):
    source = train(map=ROOM, timesteps=400, out=tmp_path, hyperparams=tiny_hp(), progress_bar=False)
    src_weights = MaskableRecurrentPPO.load(source / "model.zip", device="cpu").policy.state_dict()
    # lr 1e-50 (0 is refused; this is below float32's smallest number, so no weight moves) and no
    # curriculum: the warm-started run must keep exactly the source's weights
    run = train(map=ROOM, timesteps=400, out=tmp_path, run_id="warm", init_from=source, progress_bar=False,
                hyperparams=tiny_hp(learning_rate=1e-50, curriculum=False))
    model = MaskableRecurrentPPO.load(run / "model.zip", device="cpu")
    assert model.num_timesteps == 400                                   # a fresh step count
    for name, value in model.policy.state_dict().items():
        assert th.equal(value, src_weights[name]), name
    config = yaml.safe_load((run / "config.yml").read_text())
    assert config["init_from"] == {"path": str(source / "model.zip"), "timesteps": 400,
                                   "cpu_hours": cpu_hours_of(source / "model.zip")}
    # a third stage started from the second counts both earlier runs
    third = train(map=ROOM, timesteps=400, out=tmp_path, run_id="third", init_from=run, progress_bar=False,
                  hyperparams=tiny_hp(curriculum=False))
    assert yaml.safe_load((third / "config.yml").read_text())["init_from"]["timesteps"] == 800
    # a fresh run from random weights differs from the source
    fresh = train(map=ROOM, timesteps=400, out=tmp_path, run_id="fresh", seed=3, progress_bar=False,
                  hyperparams=tiny_hp(learning_rate=1e-50))
    fresh_weights = MaskableRecurrentPPO.load(fresh / "model.zip", device="cpu").policy.state_dict()
    assert any(not th.equal(v, src_weights[k]) for k, v in fresh_weights.items())
    # a run stopped early (no model.zip): its newest checkpoint
    (source / "model.zip").unlink()
    stopped = train(map=ROOM, timesteps=400, out=tmp_path, run_id="from-stopped", init_from=source,
                    progress_bar=False, hyperparams=tiny_hp())
    checkpoint = source / "checkpoints" / "model_400_steps.zip"
    assert yaml.safe_load((stopped / "config.yml").read_text())["init_from"] == {
        "path": str(checkpoint), "timesteps": 400, "cpu_hours": cpu_hours_of(checkpoint)}


def test_init_from_errors(tmp_path):
    with pytest.raises(FileNotFoundError, match="--init-from"):
        train(map=ROOM, timesteps=400, out=tmp_path, init_from=tmp_path / "nothing", progress_bar=False,
              hyperparams=tiny_hp())
    source = train(map=ROOM, timesteps=400, out=tmp_path, hyperparams=tiny_hp(), progress_bar=False)
    with pytest.raises(ValueError, match="only one"):
        train(map=ROOM, timesteps=400, run_dir=source, init_from=source, resume=True, progress_bar=False,
              hyperparams=tiny_hp())
    big = parse_map("S.......\n........\n........\n........", name="big")
    with pytest.raises(ValueError, match="does not match"):
        train(map=big, timesteps=400, out=tmp_path, init_from=source, progress_bar=False, hyperparams=tiny_hp())
    junk = tmp_path / "junk.zip"
    junk.write_bytes(b"not a zip")
    with pytest.raises(ValueError, match="cannot be loaded"):
        train(map=ROOM, timesteps=400, out=tmp_path, run_id="j", init_from=junk, progress_bar=False,
              hyperparams=tiny_hp())


def test_interrupted_run_saves_a_checkpoint_and_the_cli_says_how_to_resume(tmp_path, monkeypatch, capsys):
    original_learn = MaskableRecurrentPPO.learn

    def learn_then_interrupt(self, total_timesteps, **kwargs):   # Ctrl-C after one rollout
        original_learn(self, 400, **kwargs)
        raise KeyboardInterrupt

    monkeypatch.setattr(MaskableRecurrentPPO, "learn", learn_then_interrupt)
    with pytest.raises(KeyboardInterrupt):
        train(map=ROOM, timesteps=2000, out=tmp_path, hyperparams=tiny_hp(), progress_bar=False)
    run = tmp_path / "room" / "rl-msg" / "MaskableRecurrentPPO_seed0"
    assert RunFolder(run).newest_checkpoint().name == "model_400_steps.zip" and not (run / "model.zip").exists()

    from patrolsb3 import cli
    from patrolsb3.commands import train as train_command

    def interrupted(args):
        raise KeyboardInterrupt
    monkeypatch.setattr(train_command, "run", interrupted)
    assert cli.main(["train", "--map", "A"]) == 130
    assert "interrupted (a checkpoint was saved; continue with --resume)" in capsys.readouterr().err


def test_mix_runs_some_parallel_episodes_with_other_env_settings(tmp_path):
    hp = tiny_hp(n_envs=4, curriculum=False, mix={"episodes": 2, "env": {"episode_steps": 3}})
    run = train(map=ROOM, variant="rl-no-msg", timesteps=400, out=tmp_path, hyperparams=hp, progress_bar=False)
    lengths = {int(r["sim_steps"]) for r in read_curve(run / "curve.csv")}
    assert lengths == {3, 5}                                # the mixed episodes and the others
    assert yaml.safe_load((run / "config.yml").read_text())["hyperparams"]["mix"]["episodes"] == 2
    assert mixed_episodes({"mix": {"episodes": [0, 2], "env": {"episode_steps": 3}}}, 4) == {
        0: {"episode_steps": 3}, 2: {"episode_steps": 3}}
    for bad, match in (({"episodes": 5, "env": {"episode_steps": 3}}, "4 parallel episodes"),
                       ({"episodes": [1, 4], "env": {"episode_steps": 3}}, "4 parallel episodes"),
                       ({"env": {"episode_steps": 3}}, "mix must be"),
                       ({"episodes": 1, "env": {"comm": "none"}}, "comm")):
        with pytest.raises((ValueError, TypeError), match=match):
            train(map=ROOM, variant="rl-msg", timesteps=400, out=tmp_path, run_id="bad",
                  hyperparams=tiny_hp(n_envs=4, mix=bad), progress_bar=False)
        assert not (tmp_path / "room" / "rl-msg" / "bad").exists()    # fix it and run the same command


def test_resume_passes_over_empty_and_corrupt_checkpoints(tmp_path, capsys):
    """A run killed while writing a checkpoint leaves an empty or cut file; one with flipped
    bytes fails its CRC: --resume (and zoo export / validate) use the newest valid one, say
    which they passed over, and the writes themselves go through a temporary name."""
    from patrolsb3.zoo.validation import run_checkpoints
    from patrolsb3.runs import is_valid_model_file
    run = train(map=ROOM, timesteps=800, out=tmp_path, hyperparams=tiny_hp(), progress_bar=False)
    good = RunFolder(run).newest_checkpoint()
    assert good.name == "model_800_steps.zip" and is_valid_model_file(good)
    assert not list((run / "checkpoints").glob(".*partial*"))          # no temporary file left
    (run / "checkpoints" / "model_1200_steps.zip").write_bytes(b"")    # killed at the start of a write
    flipped = bytearray(good.read_bytes())
    flipped[len(flipped) // 2] ^= 0xFF
    (run / "checkpoints" / "model_1600_steps.zip").write_bytes(bytes(flipped))
    cut = good.read_bytes()[: len(flipped) // 3]
    (run / "checkpoints" / "model_2000_steps.zip").write_bytes(cut)
    skipped = []
    assert RunFolder(run).newest_checkpoint(skipped) == good
    assert [p.name for p in skipped] == ["model_2000_steps.zip", "model_1600_steps.zip", "model_1200_steps.zip"]
    assert good in run_checkpoints(run) and not any(p.name == "model_1600_steps.zip" for p in run_checkpoints(run))
    train(map=ROOM, timesteps=2400, out=tmp_path, hyperparams=tiny_hp(), resume=True, progress_bar=False)
    err = capsys.readouterr().err
    assert "skipped" in err and "model_1600_steps.zip" in err
    assert MaskableRecurrentPPO.load(run / "model.zip", device="cpu").num_timesteps == 2400


def test_a_run_on_a_shipped_map_records_no_path_of_this_machine(tmp_path):
    run = train(map="A", timesteps=400, out=tmp_path, hyperparams=tiny_hp(n_envs=1), progress_bar=False)
    config = yaml.safe_load((run / "config.yml").read_text())
    assert config["map_source"] == "maps/map_a.txt" and "map_text" not in config


@pytest.mark.parametrize("setting, match", [
    ("n_steps=0", "n_steps must be a whole number >= 2"), ("n_epochs=0", "n_epochs"),
    ("batch_size=-4", "batch_size"), ("n_minibatches=0", "n_minibatches"),
    ("learning_rate=fast", "learning_rate"), ("checkpoint_freq=0", "checkpoint_freq"),
    ("n_epochs=[1,2", "not valid YAML"), ("gamma=x", "gamma must be a number"),
    ("gamma=1.5", "gamma must be between 0 and 1, got 1.5"), ("gae_lambda=-0.1", "gae_lambda must be between 0 and 1"),
    ("clip_range=-0.2", "clip_range must be above 0"), ("clip_range=0", "clip_range must be above 0"),
    ("max_grad_norm=0", "max_grad_norm must be above 0"), ("vf_coef=-1", "vf_coef must be at least 0"),
    ("ent_coef=-0.01", "ent_coef must be at least 0"), ("learning_rate=0", "learning_rate must be above 0"),
    ("learning_rate=drop_2e-4_0", "learning_rate must be above 0"), ("precision=half", "precision must be one of")])
def test_bad_settings_are_refused_before_a_run_folder_exists(tmp_path, capsys, setting, match):
    from patrolsb3.cli import main
    assert main(["train", "--map", "A", "--timesteps", "400", "--out", str(tmp_path), "--set", setting]) == 2
    err = capsys.readouterr().err
    assert match in err and len(err.strip().splitlines()) == 1
    assert not any(tmp_path.iterdir())


def test_tiny_rollouts_train_without_nan(tmp_path):
    run = train(map=ROOM, timesteps=400, out=tmp_path, hyperparams=tiny_hp(n_steps=4, n_minibatches=50),
                progress_bar=False)
    model = MaskableRecurrentPPO.load(run / "model.zip", device="cpu")
    assert all(th.isfinite(p).all() for p in model.policy.parameters())


def test_resume_trims_the_curve_and_eval_to_the_checkpoint_and_reads_a_cut_cpu_line(tmp_path):
    """A run killed after its checkpoint left curve/eval rows past it and a cut cpu_time line:
    --resume drops them, so the curve's steps never go back and no step appears twice."""
    run = train(map=ROOM, timesteps=800, out=tmp_path, hyperparams=tiny_hp(eval_freq=400, eval_episode_steps=3,
                                                                            checkpoint_freq=400),
                progress_bar=False)
    (run / "checkpoints" / "model_800_steps.zip").unlink()              # the kill came before this checkpoint
    (run / "model.zip").unlink()
    with (run / "curve.csv").open("a") as f:
        f.write("9999,1,0.0,1,1,0,0,5\n1000,2,0.")                     # a stretch past the checkpoint, a cut line
    with (run / "cpu_time.csv").open("a") as f:
        f.write("12")
    train(map=ROOM, timesteps=1200, out=tmp_path, hyperparams=tiny_hp(eval_freq=400, eval_episode_steps=3,
                                                                       checkpoint_freq=400),
          resume=True, progress_bar=False)
    steps = [int(r["timesteps"]) for r in read_curve(run / "curve.csv")]
    assert steps == sorted(steps) and 9999 not in steps and max(steps) <= 1200
    evals = [(int(r["timesteps"]), r["n_agents"]) for r in read_curve(run / "eval.csv")]
    assert len(evals) == len(set(evals))


def test_resume_refuses_other_settings_and_a_missing_config(tmp_path, capsys):
    run = train(map=ROOM, timesteps=400, out=tmp_path, hyperparams=tiny_hp(), progress_bar=False)
    for kwargs, match in [({"hyperparams": tiny_hp(n_steps=20)}, "trained with n_steps=10, this run asks for 20"),
                          ({"hyperparams": tiny_hp(), "seed": 5}, "trained with seed=0, this run asks for 5"),
                          ({"hyperparams": tiny_hp(env={"episode_steps": 6})}, "differs from this run's in episode_steps")]:
        with pytest.raises(ValueError, match=match):
            train(map=ROOM, timesteps=800, run_dir=run, resume=True, progress_bar=False, **kwargs)
    # the bookkeeping may change: checkpoint_freq, eval_freq, threads, the target
    train(map=ROOM, timesteps=800, run_dir=run, resume=True, progress_bar=False,
          hyperparams=tiny_hp(checkpoint_freq=800, torch_threads=1))
    assert RunFolder(run).read_config()["hyperparams"]["n_steps"] == 10
    # a target already reached says so and trains nothing
    train(map=ROOM, timesteps=400, run_dir=run, resume=True, progress_bar=False, hyperparams=tiny_hp())
    assert "already at 800 agent-steps, at or past the 400 asked for; nothing to train" in capsys.readouterr().err
    (run / "config.yml").unlink()
    with pytest.raises(FileNotFoundError, match="config.yml is missing"):
        train(map=ROOM, timesteps=1200, run_dir=run, resume=True, progress_bar=False, hyperparams=tiny_hp())


def test_a_run_folder_is_written_by_one_process_at_a_time(tmp_path, capsys):
    run = train(map=ROOM, timesteps=400, out=tmp_path, hyperparams=tiny_hp(), progress_bar=False)
    curve = (run / "curve.csv").read_text()
    held = RunFolder(run).lock()                 # as another process running --resume would
    try:
        with pytest.raises(ValueError, match="is being written by another process"):
            train(map=ROOM, timesteps=800, run_dir=run, hyperparams=tiny_hp(), resume=True, progress_bar=False)
    finally:
        held.release()
    assert (run / "curve.csv").read_text() == curve       # nothing written while it was held
    train(map=ROOM, timesteps=800, run_dir=run, hyperparams=tiny_hp(), resume=True, progress_bar=False)
    assert RunFolder(run).has_files() and not RunFolder(tmp_path / "empty").has_files()


def test_init_from_is_recorded_relative_to_the_working_directory(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    source = train(map=ROOM, timesteps=400, out="runs", hyperparams=tiny_hp(), progress_bar=False)
    run = train(map=ROOM, timesteps=400, out="runs", run_id="warm", init_from=(tmp_path / source).resolve(),
                progress_bar=False, hyperparams=tiny_hp())
    recorded = yaml.safe_load((tmp_path / run / "config.yml").read_text())["init_from"]["path"]
    assert recorded == str(source / "model.zip") and not recorded.startswith("/")


def test_config_records_the_env_the_run_trained_in(tmp_path):
    """RecurrentPPO has no masks: its env acts a masked move as Stay, and config.yml says so."""
    run = train(map=ROOM, timesteps=400, out=tmp_path, algo="RecurrentPPO", hyperparams=tiny_hp(),
                progress_bar=False)
    assert RunFolder(run).read_config()["env"]["invalid_action"] == "stay"
    masked = train(map=ROOM, timesteps=400, out=tmp_path, run_id="masked", hyperparams=tiny_hp(), progress_bar=False)
    assert RunFolder(masked).read_config()["env"]["invalid_action"] == "raise"
