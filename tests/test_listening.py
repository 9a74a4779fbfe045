"""The listening figure: 0 for a policy that ignores what it hears, large for one that follows it;
the alphabet statistics; refusals."""
import numpy as np
import pytest

from patrolsb3.core import make_config, parse_map, protocol
from patrolsb3.core.maps import STAY
from patrolsb3.listening import listening, mutual_information_bits

ROOM = "S.....\n......\n..5...\n......"


class ScriptedPolicy:
    """A stand-in for a ZooPolicy: sends symbol (slot + 1); moves to the first legal move, or
    (``listens``) to the legal move indexed by the sum of the symbols it sees from others."""

    def __init__(self, listens: bool, comm: str = "learned"):
        self.spec = parse_map(ROOM, name="room")
        self.cfg = make_config(None, comm=comm)
        self.info = {"config": {"map": None}}
        self.listens = listens

    def act_phase(self, sim_state, phase, lstm, starts, deterministic=True):
        E, A = sim_state.pos.shape
        actions = np.zeros((E, A, 2), dtype=np.int64)
        actions[..., 0] = np.arange(A) % self.cfg.n_symbols
        actions[..., 1] = STAY
        return actions, lstm

    def move_probabilities(self, sim_state, lstm):
        masks = protocol.decide(self.spec, self.cfg, sim_state, protocol.MOVE_PHASE).masks[..., -5:]
        E, A = sim_state.pos.shape
        heard = sim_state.messages.sum(axis=1, keepdims=True) - sim_state.messages      # (E, A)
        probs = np.zeros((E, A, 5))
        for e in range(E):
            for i in range(A):
                legal = np.flatnonzero(masks[e, i])
                pick = legal[heard[e, i] % len(legal)] if self.listens else legal[0]
                probs[e, i, pick] = 1.0
        return probs, lstm


def test_a_deaf_policy_scores_zero_and_a_listening_one_does_not():
    deaf = listening(ScriptedPolicy(listens=False), n_agents=3, episodes=2, steps=20)
    assert deaf["kl_nats"] == 0.0 and deaf["greedy_changed"] == 0.0 and deaf["decisions"] > 20
    heard = listening(ScriptedPolicy(listens=True), n_agents=3, episodes=2, steps=20)
    assert heard["greedy_changed"] > 0.3 and heard["kl_nats"] > 1.0
    assert deaf["symbols_used"] == 3 and 1.0 < deaf["symbol_entropy_bits"] <= np.log2(3) + 1e-9


def test_refusals():
    with pytest.raises(ValueError, match="same-step messages"):
        listening(ScriptedPolicy(listens=True, comm="none"))
    with pytest.raises(ValueError, match="at least 2 agents"):
        listening(ScriptedPolicy(listens=True), n_agents=1)


def test_mutual_information():
    x = np.array([0, 1, 2, 3] * 50)
    assert mutual_information_bits(x, x) == pytest.approx(2.0)
    rng = np.random.default_rng(0)
    assert mutual_information_bits(rng.integers(0, 4, 20000), rng.integers(0, 4, 20000)) < 0.01
