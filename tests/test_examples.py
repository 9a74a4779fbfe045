"""The example scripts run for real (tiny budgets), as a user would start them."""
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def test_train_map_a_example_trains_and_writes_a_run_folder(tmp_path):
    proc = subprocess.run([sys.executable, str(ROOT / "examples" / "train_map_a.py"), "--timesteps", "1000",
                           "--out", str(tmp_path)], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    run = tmp_path / "A" / "rl-msg" / "MaskableRecurrentPPO_seed0"
    for name in ("model.zip", "config.yml", "command.txt"):
        assert (run / name).is_file(), name
    assert "examples/train_map_a.py" in (run / "command.txt").read_text()


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
