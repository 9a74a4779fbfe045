"""The message ablation: what agents hear is made constant or shuffled (their own symbol kept),
one observer at a time; a deaf policy loses nothing, a zoo entry gets paired changes with
intervals; refusals."""
import numpy as np
import pytest

from patrolsb3 import cli
from patrolsb3.ablation import CONSTANT_SYMBOL, MessageAblation, message_ablation
from patrolsb3.core import make_config, parse_map, protocol, reset_state
from patrolsb3.core.maps import STAY

ROOM = "S.....\n......\n..5...\n......"


class Recorder:
    """A stand-in for a ZooPolicy that sends symbol (slot + 1) and stays; it records the symbols
    each move phase shows, so the test can see what every observer heard."""

    def __init__(self, comm="learned"):
        self.spec = parse_map(ROOM, name="room")
        self.cfg = make_config(None, comm=comm)
        self.views = []

    def act_phase(self, sim_state, phase, lstm, starts, deterministic=True):
        E, A = sim_state.pos.shape
        if phase == protocol.MOVE_PHASE:
            self.views.append(sim_state.messages.copy())
        actions = np.zeros((E, A, 2), dtype=np.int64)
        actions[..., 0] = np.arange(A) % self.cfg.n_symbols
        actions[..., 1] = STAY
        return actions, lstm


def sim_state(policy, n_agents=3, n_envs=4):
    return reset_state(policy.spec, make_config(None), n_agents, n_envs=n_envs, seed=0)


def test_each_observer_hears_the_ablated_symbols_and_keeps_its_own():
    policy = Recorder()
    state = sim_state(policy)
    sent = protocol.symbols_of(np.broadcast_to(np.arange(5), (4, 5)), state.active)     # what was sent
    actions, _ = MessageAblation(policy, "constant").predict(state)
    assert (actions[..., 0] == sent).all() and (actions[..., 1] == STAY).all()
    assert len(policy.views) == 5                              # one move phase per observer slot
    for i, view in enumerate(policy.views[:3]):                # the 3 active observers
        others = [j for j in range(3) if j != i]
        assert (view[:, i] == sent[:, i]).all()                # its own symbol is kept
        assert (view[:, others] == CONSTANT_SYMBOL).all()
    policy.views.clear()
    MessageAblation(policy, "shuffled", seed=3).predict(state)
    heard = np.stack([policy.views[i][:, j] for i in range(3) for j in range(3) if i != j], axis=1)
    assert set(np.unique(heard)) <= set(np.unique(sent[:, :3]))      # the team's own symbols
    assert (heard != np.stack([sent[:, j] for i in range(3) for j in range(3) if i != j], axis=1)).any()


def test_refusals():
    with pytest.raises(ValueError, match="same-step messages"):
        MessageAblation(Recorder(comm="none"), "constant")
    with pytest.raises(ValueError, match="unknown message ablation 'silent'"):
        MessageAblation(Recorder(), "silent")


@pytest.mark.parametrize("variant", ["rl-msg"])
def test_a_zoo_entry_gets_paired_changes_with_intervals(variant, tiny_zoo):
    from patrolsb3 import zoo
    figures = message_ablation(zoo.load("A", variant, zoo_dir=tiny_zoo), n_agents=2, episodes=2, steps=40, seed=5)
    for mode in ("constant", "shuffled"):
        for metric, r in figures[mode].items():
            low, high = r["change_ci95"]
            assert low <= r["change"] <= high
            assert r["change"] == pytest.approx(r["mean"] - figures["baseline"][metric])
    with pytest.raises(ValueError, match="at least 2 agents"):
        message_ablation(zoo.load("A", variant, zoo_dir=tiny_zoo), n_agents=1)


def test_cli_ablation_refuses_a_variant_without_messages(capsys):
    assert cli.main(["zoo", "ablation", "A", "rl-no-msg", "--episodes", "1", "--steps", "5"]) == 2
    assert "same-step messages" in capsys.readouterr().err
