"""patrolsb3.runs: the run folder's one owner (paths, checkpoints, config, atomic CSV blocks,
the cut back on resume)."""
import csv
import os
import signal
import subprocess
import sys
import textwrap

import pytest

from patrolsb3.runs import ConfigError, RunFolder, append_csv_rows, write_atomically


def test_paths_and_names_of_a_run_folder(tmp_path):
    run = RunFolder(tmp_path / "run")
    assert run.checkpoint_file(400) == tmp_path / "run" / "checkpoints" / "model_400_steps.zip"
    assert run.statistics_file(400).name == "model_vecnormalize_400_steps.pkl"
    assert RunFolder.of_model(run.checkpoint_file(400)) == run
    assert RunFolder.of_model(run.model_file) == run
    assert not run.has_files()
    run.create()
    assert run.checkpoints_dir.is_dir() and run.has_files()


def test_checkpoints_sort_by_steps_and_the_newest_valid_one_is_taken(tmp_path):
    import zipfile
    run = RunFolder(tmp_path)
    run.create()
    for steps in (800, 400, 1200):
        with zipfile.ZipFile(run.checkpoint_file(steps), "w") as archive:
            archive.writestr("data", "{}")
    run.checkpoint_file(1600).write_bytes(b"")                      # a write cut by a kill
    assert [p.name for p in run.checkpoints()] == [f"model_{s}_steps.zip" for s in (400, 800, 1200, 1600)]
    skipped = []
    assert run.newest_checkpoint(skipped) == run.checkpoint_file(1200)
    assert skipped == [run.checkpoint_file(1600)]
    assert run.newest_model() == run.checkpoint_file(1200)          # no model.zip: a stopped run


def _stopped_run(path, steps) -> RunFolder:
    """A run folder with a valid checkpoint and its statistics for each of ``steps``, no model.zip."""
    import zipfile
    run = RunFolder(path)
    run.create()
    for step in steps:
        with zipfile.ZipFile(run.checkpoint_file(step), "w") as archive:
            archive.writestr("data", "{}")
        run.statistics_file(step).write_bytes(b"stats %d" % step)
    return run


def test_a_snapshot_holds_the_newest_valid_checkpoint_with_its_statistics_and_records(tmp_path):
    run = _stopped_run(tmp_path / "run", steps=(400, 800))
    run.checkpoint_file(1200).write_bytes(b"")                      # cut by a kill: passed over
    run.config_file.write_text("map: A\n")
    run.curve_file.write_text("timesteps\n400\n800\n")
    run.tensorboard_dir.mkdir()
    copied = run.snapshot(tmp_path / "snap")
    snap = RunFolder(tmp_path / "snap")
    assert copied == snap.checkpoint_file(800)
    assert sorted(p.name for p in snap.checkpoints_dir.iterdir()) == ["model_800_steps.zip",
                                                                      "model_vecnormalize_800_steps.pkl"]
    assert snap.statistics_file(800).read_bytes() == b"stats 800"
    assert sorted(p.name for p in snap.path.iterdir()) == ["checkpoints", "config.yml", "curve.csv"]
    assert snap.newest_checkpoint() == snap.checkpoint_file(800)
    run.statistics_file(800).unlink()
    with pytest.raises(FileNotFoundError, match="model_vecnormalize_800_steps.pkl"):
        run.snapshot(tmp_path / "snap2")
    assert not (tmp_path / "snap2").exists()                        # refused before any copy
    run.config_file.write_text("map: A\nhyperparams: {normalize_reward: false}\n")    # no statistics to carry
    assert run.snapshot(tmp_path / "snap2") == RunFolder(tmp_path / "snap2").checkpoint_file(800)
    with pytest.raises(FileNotFoundError, match="no valid checkpoint"):
        RunFolder(tmp_path / "empty").snapshot(tmp_path / "snap3")


def test_a_snapshot_keeps_the_newest_k_valid_checkpoints_when_asked(tmp_path):
    run = _stopped_run(tmp_path / "run", steps=(400, 800, 1200, 1600))
    run.checkpoint_file(2000).write_bytes(b"")                      # cut by a kill: passed over
    copied = run.snapshot(tmp_path / "snap", keep=3)
    snap = RunFolder(tmp_path / "snap")
    assert copied == snap.checkpoint_file(1600)
    assert [p.name for p in snap.checkpoints()] == [f"model_{s}_steps.zip" for s in (800, 1200, 1600)]
    assert all(snap.statistics_file(s).read_bytes() == b"stats %d" % s for s in (800, 1200, 1600))
    run.snapshot(tmp_path / "all", keep=10)                         # more than there are: all of them
    assert len(RunFolder(tmp_path / "all").checkpoints()) == 4
    run.statistics_file(800).unlink()
    with pytest.raises(FileNotFoundError, match="model_vecnormalize_800_steps.pkl"):
        run.snapshot(tmp_path / "snap2", keep=3)
    assert not (tmp_path / "snap2").exists()                        # refused before any copy
    run.config_file.write_text("map: A\nhyperparams: {normalize_reward: false}\n")    # no statistics to carry
    assert run.snapshot(tmp_path / "snap2") == RunFolder(tmp_path / "snap2").checkpoint_file(1600)
    milestone = run.snapshot(tmp_path / "milestone", milestones=(400, 1200, 5000))   # 5000: not there
    assert [p.name for p in RunFolder(tmp_path / "milestone").checkpoints()] == \
        [f"model_{s}_steps.zip" for s in (400, 1200, 1600)] and milestone.name == "model_1600_steps.zip"
    for bad in (0, -1, 1.5, True):
        with pytest.raises(ValueError, match="keep: "):
            run.snapshot(tmp_path / "snap3", keep=bad)
    assert not (tmp_path / "snap3").exists()


def test_a_finished_run_is_not_snapshot_since_the_snapshot_would_drop_its_checkpoints(tmp_path):
    import zipfile
    run = _stopped_run(tmp_path / "run", steps=(400, 800))
    run.snapshot(tmp_path / "stopped")                              # a stopped run: fine
    with zipfile.ZipFile(run.model_file, "w") as archive:           # the run finishes
        archive.writestr("data", "{}")
    with pytest.raises(FileExistsError, match=r"finished \(model.zip\).*finish_paper_run"):
        run.snapshot(tmp_path / "finished")
    assert not (tmp_path / "finished").exists()                     # refused before any copy


def test_a_finished_run_is_snapshot_with_its_final_model_and_the_checkpoint_validation_chose(tmp_path):
    import zipfile
    run = _stopped_run(tmp_path / "run", steps=(400, 800, 1200, 1600))
    run.config_file.write_text("map: A\n")
    run.curve_file.write_text("timesteps\n1600\n")
    with zipfile.ZipFile(run.model_file, "w") as archive:           # the run finishes at 1,700
        archive.writestr("data", '{"num_timesteps": 1700}')
    copied = run.snapshot(tmp_path / "snap", chosen=run.checkpoint_file(800), milestones=(400,))
    snap = RunFolder(tmp_path / "snap")
    assert copied == snap.checkpoint_file(800)
    assert [p.name for p in snap.checkpoints()] == ["model_400_steps.zip", "model_800_steps.zip"]   # not the newest
    assert snap.statistics_file(800).read_bytes() == b"stats 800"
    assert snap.model_file.read_bytes() == run.model_file.read_bytes()
    assert sorted(p.name for p in snap.path.iterdir()) == ["checkpoints", "config.yml", "curve.csv", "model.zip"]
    assert run.snapshot(tmp_path / "final", chosen=run.model_file) == RunFolder(tmp_path / "final").model_file
    assert RunFolder(tmp_path / "final").checkpoints() == []        # the final model chosen: no checkpoint needed
    run.checkpoint_file(1200).write_bytes(b"")                      # cut: not a checkpoint validation could choose
    for bad in (run.checkpoint_file(1200), run.checkpoint_file(5000), tmp_path / "elsewhere" / "model.zip"):
        with pytest.raises(ValueError, match="chosen: .* is not a valid checkpoint of"):
            run.snapshot(tmp_path / "bad", chosen=bad)
    assert not (tmp_path / "bad").exists()                          # refused before any copy
    stopped = _stopped_run(tmp_path / "stopped", steps=(400, 800, 1200))
    kept = RunFolder(tmp_path / "snap_stopped")
    stopped.snapshot(kept.path, chosen=stopped.checkpoint_file(400))   # a stopped run: the newest, and the chosen one
    assert [p.name for p in kept.checkpoints()] == ["model_400_steps.zip", "model_1200_steps.zip"]
    assert not kept.model_file.exists()


def test_config_is_written_and_read_through_the_schema(tmp_path):
    run = RunFolder(tmp_path)
    run.write_config({"map": "A", "seed": 3})
    assert run.read_config() == {"map": "A", "seed": 3}
    with pytest.raises(ConfigError, match="settings this code does not know: \\['colour'\\]"):
        run.write_config({"map": "A", "colour": "red"})
    run.config_file.write_text("map: [A\n")
    with pytest.raises(ConfigError, match="config.yml: not valid YAML"):
        run.read_config()
    assert RunFolder(tmp_path / "none").read_config() == {}


def test_command_lines_are_appended(tmp_path):
    run = RunFolder(tmp_path)
    run.record_command("patrolsb3 train --map A")
    run.record_command("patrolsb3 train --map A --resume\n")
    assert run.command_file.read_text() == "patrolsb3 train --map A\npatrolsb3 train --map A --resume\n"


def test_csv_blocks_are_appended_whole_and_cut_back_on_resume(tmp_path):
    run = RunFolder(tmp_path)
    fields = ("timesteps", "reward")
    append_csv_rows(run.curve_file, fields, [])                   # the header alone
    assert run.curve_file.read_text().splitlines() == ["timesteps,reward"]
    append_csv_rows(run.curve_file, fields, [{"timesteps": 400, "reward": 1.0}, {"timesteps": 800, "reward": 2.0}])
    append_csv_rows(run.curve_file, fields, [{"timesteps": 1200, "reward": 3.0, "extra": "left out"}])
    append_csv_rows(run.eval_file, fields, [{"timesteps": 800, "reward": 5.0}, {"timesteps": 1600, "reward": 6.0}])
    with run.curve_file.open("a") as f:
        f.write("16")                                              # a line cut by a kill (an old run)
    run.cut_back_to(800)
    with run.curve_file.open() as f:
        assert [r["timesteps"] for r in csv.DictReader(f)] == ["400", "800"]
    with run.eval_file.open() as f:
        assert [r["timesteps"] for r in csv.DictReader(f)] == ["800"]
    assert not (tmp_path / ".partial").exists()


def test_a_kill_during_a_block_append_leaves_the_file_whole(tmp_path):
    """SIGKILL while a big block is being appended: the file holds every old row and either the
    whole block or none of it (the block is written beside it and renamed)."""
    path = tmp_path / "curve.csv"
    append_csv_rows(path, ("timesteps", "x"), [{"timesteps": i, "x": 0} for i in range(10)])
    script = textwrap.dedent(f"""
        import os, signal
        from patrolsb3 import runs
        real = runs.write_atomically
        def killed_midway(path, write):
            def partial_then_kill(partial):
                write(partial)
                os.kill(os.getpid(), signal.SIGKILL)     # the block is written, not yet renamed
            return real(path, partial_then_kill)
        runs.write_atomically = killed_midway
        runs.append_csv_rows({str(path)!r}, ("timesteps", "x"), [{{"timesteps": i, "x": 1}} for i in range(10, 5000)])
    """)
    proc = subprocess.run([sys.executable, "-c", script])
    assert proc.returncode == -signal.SIGKILL
    with path.open() as f:
        rows = list(csv.DictReader(f))
    assert [int(r["timesteps"]) for r in rows] == list(range(10))
    append_csv_rows(path, ("timesteps", "x"), [{"timesteps": 10, "x": 1}])   # the next write goes through
    with path.open() as f:
        assert len(list(csv.DictReader(f))) == 11


def test_write_atomically_leaves_the_old_file_when_the_writer_fails(tmp_path):
    path = tmp_path / "config.yml"
    path.write_text("old\n")

    def broken(partial):
        partial.write_text("half")
        raise OSError("disk full")
    with pytest.raises(OSError):
        write_atomically(path, broken)
    assert path.read_text() == "old\n"
    assert os.listdir(tmp_path) in (["config.yml"], sorted(["config.yml", ".partial"]), [".partial", "config.yml"])


def test_recorded_path_is_relative_under_the_working_folder_and_absolute_outside(tmp_path, monkeypatch):
    from patrolsb3.runs import recorded_path
    inside = tmp_path / "repo" / "runs" / "x" / "model.zip"
    inside.parent.mkdir(parents=True)
    monkeypatch.chdir(tmp_path / "repo")
    assert recorded_path(inside) == "runs/x/model.zip"
    assert recorded_path("runs/x") == "runs/x"
    assert recorded_path(tmp_path / "elsewhere") == str((tmp_path / "elsewhere").resolve())


def test_a_worktree_whose_runs_folder_links_elsewhere_still_records_runs_relative(tmp_path, monkeypatch):
    from patrolsb3.runs import recorded_path
    (tmp_path / "main" / "runs" / "e2").mkdir(parents=True)
    (tmp_path / "worktree").mkdir()
    (tmp_path / "worktree" / "runs").symlink_to(tmp_path / "main" / "runs")      # runs/ shared with the checkout
    monkeypatch.chdir(tmp_path / "worktree")
    assert recorded_path("runs/e2/tb") == "runs/e2/tb"
    assert recorded_path(tmp_path / "worktree" / "runs" / "e2") == "runs/e2"


def test_a_snapshot_carries_no_absolute_tensorboard_folder_inside_its_checkpoint(tmp_path, monkeypatch):
    import json
    import zipfile
    monkeypatch.chdir(tmp_path)
    run = _stopped_run(tmp_path / "runs" / "e2", steps=(400,))
    with zipfile.ZipFile(run.checkpoint_file(400), "w") as archive:      # what SB3 writes, and a weight file
        archive.writestr("data", json.dumps({"tensorboard_log": str(tmp_path / "runs" / "e2" / "tb"), "gamma": 0.95}))
        archive.writestr("policy.pth", b"\x00\x01weights")
    copied = run.snapshot(tmp_path / "snap")
    with zipfile.ZipFile(copied) as archive:
        assert json.loads(archive.read("data")) == {"tensorboard_log": "runs/e2/tb", "gamma": 0.95}
        assert archive.read("policy.pth") == b"\x00\x01weights"
    with zipfile.ZipFile(run.checkpoint_file(400)) as archive:           # the run's own file is left as it was
        assert json.loads(archive.read("data"))["tensorboard_log"].startswith(str(tmp_path))
