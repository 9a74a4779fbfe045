"""patrolsb3.sb3.cpu_time: a run measures its own CPU time, across resumes and warm starts."""
import csv

import yaml

from patrolsb3 import zoo
from patrolsb3.core import parse_map
from patrolsb3.sb3.cpu_time import CPU_TIME_FILE, cpu_hours_of, cpu_seconds_at, read_rows, restart_at
from patrolsb3.sb3.train import train

ROOM = parse_map("S.....\n......\n......\n......", name="room")


def tiny_hp(**extra):
    return {"n_steps": 10, "n_minibatches": 2, "n_envs": 8, "eval_freq": 0, "checkpoint_freq": 400,
            "env": {"episode_steps": 5}, "policy_kwargs": {"dense_sizes": [32, 16], "lstm_hidden_size": 8},
            **extra}


def test_a_run_records_its_cpu_time_and_a_resume_continues_it(tmp_path):
    run = train(map=ROOM, timesteps=800, out=tmp_path, hyperparams=tiny_hp(), progress_bar=False)
    rows = read_rows(run)
    steps = [t for t, _ in rows]
    assert steps[0] == 0 and steps[-1] == 800 and steps == sorted(steps)
    seconds = [s for _, s in rows]
    assert seconds == sorted(seconds) and seconds[-1] > 0
    at_end = seconds[-1]
    # rows past the checkpoint a resume starts from are cut, and the count goes on from there
    with (run / CPU_TIME_FILE).open("a", newline="") as f:
        csv.writer(f).writerow([1200, 999.0])                       # a run killed past its checkpoint
    train(map=ROOM, timesteps=1600, out=tmp_path, hyperparams=tiny_hp(), resume=True, progress_bar=False)
    resumed = read_rows(run)
    assert all(s < 999.0 for _, s in resumed)
    assert [t for t, _ in resumed] == sorted(t for t, _ in resumed) and resumed[-1][0] == 1600
    assert cpu_seconds_at(run, 800) == at_end and resumed[-1][1] > at_end
    assert cpu_hours_of(run / "model.zip") == resumed[-1][1] / 3600
    assert cpu_hours_of(run / "checkpoints" / "model_800_steps.zip") == at_end / 3600


def test_warm_starts_add_up_and_export_records_the_measure(tmp_path):
    source = train(map=ROOM, timesteps=400, out=tmp_path, hyperparams=tiny_hp(), progress_bar=False)
    first = cpu_hours_of(source / "model.zip")
    run = train(map=ROOM, timesteps=400, out=tmp_path, run_id="stage2", init_from=source,
                hyperparams=tiny_hp(curriculum=False), progress_bar=False)
    assert yaml.safe_load((run / "config.yml").read_text())["init_from"]["cpu_hours"] == first
    total = cpu_hours_of(run / "model.zip")
    assert total == first + read_rows(run)[-1][1] / 3600 and total > first
    folder = zoo.export(run, zoo_dir=tmp_path / "zoo")
    budget = yaml.safe_load((folder / "config.yml").read_text())["budget"]
    assert budget["cpu_hours"] == round(total, 3) and budget["cpu_hours_source"].startswith("measured")
    assert (folder / CPU_TIME_FILE).is_file()
    given = zoo.export(run, zoo_dir=tmp_path / "zoo2", budget={"cpu_hours": 2.5})
    budget = yaml.safe_load((given / "config.yml").read_text())["budget"]
    assert budget["cpu_hours"] == 2.5 and budget["cpu_hours_source"].startswith("given")


def test_a_chain_with_an_unmeasured_stage_has_no_figure(tmp_path):
    source = train(map=ROOM, timesteps=400, out=tmp_path, hyperparams=tiny_hp(), progress_bar=False)
    (source / CPU_TIME_FILE).unlink()                               # a run older than the record
    assert cpu_hours_of(source / "model.zip") is None
    run = train(map=ROOM, timesteps=400, out=tmp_path, run_id="stage2", init_from=source,
                hyperparams=tiny_hp(curriculum=False), progress_bar=False)
    assert cpu_hours_of(run / "model.zip") is None
    budget = yaml.safe_load((zoo.export(run, zoo_dir=tmp_path / "zoo") / "config.yml").read_text())["budget"]
    assert "cpu_hours" not in budget


def test_restart_at_gives_the_seconds_at_the_checkpoint_after_the_cut(tmp_path):
    from patrolsb3.runs import RunFolder
    (tmp_path / CPU_TIME_FILE).write_text("timesteps,cpu_seconds\n0,0.0\n400,10.0\n800,20.0\n1200,30.0\n")
    RunFolder(tmp_path).cut_back_to(800)
    assert read_rows(tmp_path) == [(0, 0.0), (400, 10.0), (800, 20.0)]
    assert restart_at(tmp_path, 800) == 20.0
    assert restart_at(tmp_path / "nothing", 800) == 0.0


def test_a_stage_started_from_a_run_kept_as_a_policy_counts_that_runs_budget(tmp_path):
    from patrolsb3.sb3.maskable_recurrent_ppo import MaskableRecurrentPPO
    source = train(map=ROOM, timesteps=400, out=tmp_path, hyperparams=tiny_hp(), progress_bar=False)
    steps, seconds = read_rows(source)[-1]
    model = MaskableRecurrentPPO.load(str(source / "model.zip"), device="cpu")
    model.policy.save(str(source / "model.zip"))                    # kept as a policy only
    run = train(map=ROOM, timesteps=400, out=tmp_path, run_id="stage2", init_from=source,
                hyperparams=tiny_hp(curriculum=False), progress_bar=False)
    init_from = yaml.safe_load((run / "config.yml").read_text())["init_from"]
    assert init_from["timesteps"] == steps == 400 and init_from["cpu_hours"] == seconds / 3600
    assert cpu_hours_of(run / "model.zip") == seconds / 3600 + read_rows(run)[-1][1] / 3600
