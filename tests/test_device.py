"""--device auto|cpu|cuda: what each value means, a clear refusal where torch has no GPU, and
(only where CUDA exists) a short training and a zoo policy on the GPU."""
import numpy as np
import pytest
import torch

from patrolsb3.cli import main
from patrolsb3.sb3.algorithms import torch_device

HAS_CUDA = torch.cuda.is_available()
NEEDS_CUDA = pytest.mark.skipif(not HAS_CUDA, reason="needs a CUDA GPU (CI and the dev machine are CPU-only)")


def test_device_values():
    assert torch_device("cpu") == "cpu"
    assert torch_device("auto") == ("cuda" if HAS_CUDA else "cpu")
    with pytest.raises(ValueError, match="--device must be one of auto, cpu, cuda, got 'tpu'"):
        torch_device("tpu")


@pytest.mark.skipif(HAS_CUDA, reason="checks the refusal on a machine without a GPU")
@pytest.mark.parametrize("argv", [
    ["train", "--device", "cuda", "--timesteps", "10"],
    ["bench", "train", "--device", "cuda", "--quick"],
    ["evaluate", "--strategy", "CR", "--device", "cuda", "--episodes", "1", "--steps", "5"],
])
def test_cuda_without_a_gpu_is_one_line_before_any_work(argv, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert "torch sees no CUDA device" in err and len(err.splitlines()) == 1
    assert not any(tmp_path.iterdir())      # no run folder left behind


@NEEDS_CUDA
def test_training_and_a_zoo_policy_on_the_gpu(tmp_path):
    from patrolsb3 import zoo
    from patrolsb3.core import make_config, parse_map, reset_state
    from patrolsb3.sb3.train import train

    room = "S....\n.....\n..5..\n....."
    (tmp_path / "room.txt").write_text(room)
    hp = {"n_steps": 16, "batch_size": 64, "n_envs": 2, "eval_freq": 0, "checkpoint_freq": 10**9,
          "env": {"episode_steps": 20}, "policy_kwargs": {"dense_sizes": [32, 16], "lstm_hidden_size": 8}}
    run = train(map=str(tmp_path / "room.txt"), variant="rl-msg", timesteps=640, run_dir=tmp_path / "run",
                hyperparams=hp, progress_bar=False, device="cuda")
    folder = zoo.export(run, zoo_dir=tmp_path / "zoo")
    spec = parse_map(room, name=folder.parent.name)
    on_gpu = zoo.load(folder.parent.name, "rl-msg", zoo_dir=tmp_path / "zoo", spec=spec, device="cuda")
    on_cpu = zoo.load(folder.parent.name, "rl-msg", zoo_dir=tmp_path / "zoo", spec=spec, device="cpu")
    assert on_gpu.policy.device.type == "cuda"
    sim = reset_state(spec, make_config(None), [2, 3], n_envs=2, seed=0)
    a_gpu, _ = on_gpu.predict(sim)
    a_cpu, _ = on_cpu.predict(sim)
    assert np.mean(a_gpu == a_cpu) > 0.9       # greedy actions agree up to float ties


@NEEDS_CUDA
@pytest.mark.parametrize("precision", ["auto", "bf16"])
def test_training_on_the_gpu_in_each_precision(tmp_path, precision):
    """auto is fp32 on a GPU; bf16 trains there too where the GPU has it; both record it."""
    from patrolsb3.runs import RunFolder
    from patrolsb3.sb3.train import train
    if precision == "bf16" and not torch.cuda.is_bf16_supported():
        pytest.skip("this GPU has no bf16")
    room = "S....\n.....\n..5..\n....."
    (tmp_path / "room.txt").write_text(room)
    hp = {"n_steps": 16, "batch_size": 64, "n_envs": 2, "eval_freq": 0, "checkpoint_freq": 10**9,
          "precision": precision, "env": {"episode_steps": 20},
          "policy_kwargs": {"dense_sizes": [32, 16], "lstm_hidden_size": 8}}
    run = train(map=str(tmp_path / "room.txt"), variant="rl-msg", timesteps=640, run_dir=tmp_path / "run",
                hyperparams=hp, progress_bar=False, device="cuda")
    assert RunFolder(run).read_config()["hyperparams"]["precision"] == ("fp32" if precision == "auto" else "bf16")
