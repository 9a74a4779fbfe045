"""The example scripts run for real (tiny budgets), as a user would start them."""
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def test_train_map_a_example_runs_both_stages_resumes_and_refuses_bad_input(tmp_path):
    script = [sys.executable, str(ROOT / "examples" / "train_map_a.py"), "--timesteps", "20000",
              "--out", str(tmp_path), "--run-id", "tiny", "--set", "n_steps=16",
              "policy_kwargs.dense_sizes=[32,16]", "policy_kwargs.lstm_hidden_size=8"]
    proc = subprocess.run(script, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-2000:]
    for stage in ("stage1", "stage2"):
        run = tmp_path / stage / "A" / "rl-msg" / "tiny"
        for name in ("model.zip", "config.yml", "command.txt", "curve.csv"):
            assert (run / name).is_file(), (stage, name)
        assert "examples/train_map_a.py" in (run / "command.txt").read_text()
    assert "init_from" in (tmp_path / "stage2" / "A" / "rl-msg" / "tiny" / "config.yml").read_text()
    # stage 2's 1,500-step episodes do not end in 16,000 agent-steps: curve.csv has its header and a line says so
    assert "no episode finished" in proc.stderr
    assert (tmp_path / "stage2" / "A" / "rl-msg" / "tiny" / "curve.csv").read_text().startswith("timesteps,")
    again = subprocess.run(script[:3] + ["24000"] + script[4:] + ["--resume"], capture_output=True, text=True,
                           timeout=600)
    assert again.returncode == 0, again.stderr[-2000:]
    bad = subprocess.run(script + ["n_epochs=lots"], capture_output=True, text=True, timeout=300)
    assert bad.returncode == 2 and bad.stderr.startswith("train_map_a.py: error:") and "Traceback" not in bad.stderr


def test_zoo_in_pettingzoo_example_prints_metrics_and_writes_a_gif(tmp_path):
    gif = tmp_path / "episode.gif"
    proc = subprocess.run([sys.executable, str(ROOT / "examples" / "zoo_in_pettingzoo.py"), "--steps", "20",
                           "--gif", str(gif)], capture_output=True, text=True, timeout=300, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert "zoo:rl-msg: AVG^h" in proc.stdout and "CR: AVG^h" in proc.stdout
    assert gif.stat().st_size > 1000


def test_compare_map_a_example_writes_the_report(tmp_path):
    proc = subprocess.run([sys.executable, str(ROOT / "examples" / "compare_map_a.py"), "--agents", "1-2",
                           "--episodes", "1", "--steps", "30", "--out", str(tmp_path / "cmp")],
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert (tmp_path / "cmp" / "report.md").is_file() and (tmp_path / "cmp" / "A.png").is_file()
    report = (tmp_path / "cmp" / "report.md").read_text()
    assert "map A, zoo:rl-msg: the paper's setting (no return guard); training seed 0" in report
    assert "computed now" in report and "behind the return guard" not in report
