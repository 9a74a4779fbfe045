"""The listening figure rises when a policy is trained to listen (slow: two short training runs).

On a small room (2-3 agents, learned messages in planes, full batteries), an untrained policy's
moves barely depend on the symbols it receives (the listening KL is ~1e-8 nats); after a short
run with the positive-listening bonus they do, far beyond what the same run without it gives.
"""
import pytest

from patrolsb3.listening import listening
from patrolsb3.sb3.hyperparams import merge
from patrolsb3.sb3.recipes import recipe
from patrolsb3.sb3.train import train
from patrolsb3.zoo import load_checkpoint

ROOM = "S.....\n..#...\n...5..\n......\n"

pytestmark = pytest.mark.slow


def short_run(tmp_path, timesteps, **extra):
    room = tmp_path / "room.txt"
    room.write_text(ROOM)
    hp = merge(recipe("zoo-stage1"), {"curriculum": False, "n_steps": 64, "batch_size": 1024,
                                      "env": {"max_agents": 3}, **extra})
    name = "_".join(f"{k}{v}" for k, v in extra.items()) or "plain"
    run = train(map=str(room), variant="rl-msg", timesteps=timesteps, out=tmp_path, seed=0,
                run_id=f"{name}_{timesteps}", hyperparams=hp, eval_freq=0, progress_bar=False,
                checkpoint_freq=10**9, device="cpu")
    return listening(load_checkpoint(run / "model.zip"), n_agents=2, episodes=4, steps=200, seed=1000)


def test_listening_rises_with_the_listening_bonus(tmp_path):
    untrained = short_run(tmp_path, 1024, listen_coef=0.5)
    plain = short_run(tmp_path, 60_000)
    listens = short_run(tmp_path, 60_000, listen_coef=0.5)
    assert untrained["kl_nats"] < 1e-4
    assert listens["kl_nats"] > 10 * max(plain["kl_nats"], 1e-3)
    assert listens["greedy_changed"] > 0.05
