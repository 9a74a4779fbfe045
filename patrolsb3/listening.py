"""What a trained policy's messages carry: how much its moves depend on the symbols it receives,
and how it uses its alphabet.

The ``listening`` figure: run the policy on a team, and at every move phase compare its move
distribution given the symbols the others actually sent with the distribution given random
symbols in their place (uniform over the alphabet, a fresh draw per observer; the observer's
own symbol and its recurrent state are kept). Reported over the decisions of active agents with
more than one legal move: the mean KL divergence (nats) from the true-symbol distribution to the
randomised one, and the share of decisions whose most likely move changes. A policy that ignores
what it hears scores 0 on both.

Alongside: the symbols used (share of the alphabet with > 1 % of the messages), the entropy of
the symbols sent (bits), and the mutual information (bits, plug-in estimate) between an agent's
symbol and its own next move, and between it and the other agents' next moves.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from .core import protocol
from .core.config import make_config
from .core.maps import STAY
from .core.state import reset_state


def _entropy_bits(counts: np.ndarray) -> float:
    p = counts[counts > 0] / counts.sum()
    return float(-(p * np.log2(p)).sum()) if len(p) else 0.0


def mutual_information_bits(x: np.ndarray, y: np.ndarray) -> float:
    """Plug-in mutual information (bits) of two integer samples of equal length."""
    if len(x) == 0:
        return 0.0
    joint = np.zeros((int(x.max()) + 1, int(y.max()) + 1))
    np.add.at(joint, (x, y), 1.0)
    return _entropy_bits(joint.sum(1)) + _entropy_bits(joint.sum(0)) - _entropy_bits(joint.ravel())


def with_received_symbols(state, received: np.ndarray, observer: int):
    """A copy of ``state`` in which every slot but ``observer`` shows ``received`` (E, A)."""
    messages = np.where(np.arange(state.pos.shape[1]) == observer, state.messages, received)
    return dataclasses.replace(state, messages=np.where(state.active, messages, 0))


def listening(policy, n_agents: int = 3, episodes: int = 8, steps: int = 500, seed: int = 1000) -> dict:
    """The listening figure and the alphabet statistics of a zoo policy (module docstring).

    Args:
        policy: a :class:`patrolsb3.zoo.ZooPolicy` with same-step messages (rl-msg, rl-intention).
        n_agents: team size (at least 2: someone must speak to be heard).
        episodes: parallel episodes.
        steps: simulator steps of each (greedy moves, the evaluation's settings).
        seed: seed of the episodes and of the random symbols (not the evaluation's 0).

    Returns:
        {"kl_nats", "greedy_changed", "decisions", "symbols_used", "symbol_entropy_bits",
        "mi_own_move_bits", "mi_others_moves_bits", "n_agents", "episodes", "steps", "seed"}.

    Raises:
        ValueError: a policy without same-step messages, or fewer than 2 agents.
    """
    cfg = policy.cfg
    if not cfg.two_phase:
        raise ValueError(f"listening needs a policy with same-step messages (comm 'learned' or "
                         f"'intention'); this one has comm={cfg.comm!r}, timing={cfg.message_timing!r}")
    if int(n_agents) < 2:
        raise ValueError(f"listening needs a team of at least 2 agents, got n_agents={n_agents}")
    spec = policy.spec
    env_cfg = make_config(policy.info["config"].get("map"), **{**cfg.to_dict(), "episode_steps": int(steps),
                                                                 "invalid_action": "raise"})
    state = reset_state(spec, env_cfg, n_agents, n_envs=episodes, seed=seed)
    rng = np.random.default_rng(seed + 1)
    E, A = state.pos.shape
    lstm, starts = None, np.ones(E * A, dtype=bool)
    kl, changed = [], []
    sent, own_next, others_next = [], [], []
    for _ in range(int(steps)):
        active = state.active
        silent = dataclasses.replace(state, messages=np.zeros_like(state.messages))
        chosen, lstm = policy.act_phase(silent, protocol.MESSAGE_PHASE, lstm, starts, deterministic=True)
        symbols = protocol.symbols_of(chosen[..., 0], active)                    # (E, A)
        shown = dataclasses.replace(state, messages=symbols)
        probs, after = policy.move_probabilities(shown, lstm)                    # (E, A, 5)
        moves_legal = protocol.decide(spec, env_cfg, shown, protocol.MOVE_PHASE).masks[..., -5:]
        heard = np.zeros_like(probs)
        for i in range(A):          # each observer hears random symbols from the others
            received = rng.integers(1, cfg.n_symbols + 1, size=(E, A))
            p, _ = policy.move_probabilities(with_received_symbols(shown, received, i), lstm)
            heard[:, i] = p[:, i]
        choice = active & (moves_legal.sum(-1) > 1)                              # (E, A) real decisions
        eps = 1e-12
        kl.append((probs * (np.log(probs + eps) - np.log(heard + eps))).sum(-1)[choice])
        changed.append((probs.argmax(-1) != heard.argmax(-1))[choice])
        moves = np.where(active, probs.argmax(-1), STAY)
        speaking = active & (symbols > 0)
        sent.append(symbols[speaking])
        own_next.append(moves[speaking])
        code = (moves * 5 ** np.arange(A)).sum(axis=1, keepdims=True)            # (E, 1) every move
        others = code - moves * 5 ** np.arange(A)                                # (E, A) all but one's
        others_next.append(others[speaking])
        actions = np.stack([np.zeros_like(moves), moves], axis=-1)
        protocol.apply_actions(spec, env_cfg, shown, protocol.MOVE_PHASE, actions)
        state = dataclasses.replace(shown, messages=np.zeros_like(shown.messages))
        lstm, starts = after, np.zeros(E * A, dtype=bool)
    kl, changed = np.concatenate(kl), np.concatenate(changed)
    sent, own_next, others_next = np.concatenate(sent), np.concatenate(own_next), np.concatenate(others_next)
    counts = np.bincount(sent, minlength=cfg.n_symbols + 1)[1:]
    return {"kl_nats": float(kl.mean()) if len(kl) else 0.0,
            "greedy_changed": float(changed.mean()) if len(changed) else 0.0,
            "decisions": int(len(kl)),
            "symbols_used": int((counts > 0.01 * max(counts.sum(), 1)).sum()),
            "symbol_entropy_bits": _entropy_bits(counts.astype(float)),
            "mi_own_move_bits": mutual_information_bits(sent, own_next),
            "mi_others_moves_bits": mutual_information_bits(sent, others_next),
            "n_agents": int(n_agents), "episodes": int(episodes), "steps": int(steps), "seed": int(seed)}
