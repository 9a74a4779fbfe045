"""The message ablation at evaluation: does a team patrol worse when it cannot trust what it hears?

A zoo policy with same-step messages (rl-msg, rl-intention) is evaluated three times on the
same episodes (same seed, greedy moves): as trained, with every received symbol replaced by one
constant symbol, and with the team's symbols shuffled between its agents (each agent hears the
symbols that were sent, attributed to the wrong senders). Each agent's own symbol and its
recurrent state are left alone; only what it hears changes, one observer at a time (the move
phase is run once per observer, as in :mod:`patrolsb3.listening`). The change of AVG^h, MAX^h
and collisions is reported per episode pair (same seed, same start) with a 95 % bootstrap
interval of the mean change (:func:`patrolsb3.stats.mean_interval`): an interval that holds 0
says the messages carry nothing the team's patrol needs.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from .core import protocol
from .evaluate import run_episodes
from .listening import with_received_symbols
from .stats import mean_interval
from .zoo import evaluation_config

MODES = ("constant", "shuffled")
CONSTANT_SYMBOL = 1
"""The symbol every received message becomes in the 'constant' ablation."""
METRICS = ("avg_idleness", "max_idleness", "collisions")


class MessageAblation:
    """A zoo policy whose agents hear ablated messages (module docstring).

    Args:
        policy: a :class:`patrolsb3.zoo.ZooPolicy` with same-step messages.
        mode: "constant" or "shuffled".
        seed: seed of the shuffles.

    Raises:
        ValueError: an unknown mode or a policy without same-step messages.
    """

    def __init__(self, policy, mode: str, seed: int = 0):
        if mode not in MODES:
            raise ValueError(f"unknown message ablation {mode!r}; known: {', '.join(MODES)}")
        if not policy.cfg.two_phase:
            raise ValueError(f"the message ablation needs a policy with same-step messages (rl-msg, "
                             f"rl-intention); this one has comm={policy.cfg.comm!r}")
        self.policy, self.mode = policy, mode
        self.spec, self.cfg = policy.spec, policy.cfg
        self.rng = np.random.default_rng(seed)

    def received(self, symbols: np.ndarray, active: np.ndarray) -> np.ndarray:
        """(E, A) the symbols the others are heard to send."""
        if self.mode == "constant":
            return np.where(active, CONSTANT_SYMBOL, 0)
        out = symbols.copy()
        for e in range(symbols.shape[0]):
            speakers = np.flatnonzero(active[e])
            out[e, speakers] = symbols[e, self.rng.permutation(speakers)]
        return out

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        """As :meth:`patrolsb3.zoo.ZooPolicy.predict`, each agent hearing ablated symbols."""
        sim = observation
        E, A = sim.pos.shape
        if episode_start is None:
            episode_start = np.full(E, state is None)
        starts = np.repeat(np.asarray(episode_start, dtype=bool), A)
        silent = dataclasses.replace(sim, messages=np.zeros_like(sim.messages))
        chosen, lstm = self.policy.act_phase(silent, protocol.MESSAGE_PHASE, state, starts, deterministic)
        symbols = protocol.symbols_of(chosen[..., 0], sim.active)                  # (E, A) sent
        shown = dataclasses.replace(sim, messages=symbols)
        heard = self.received(symbols, sim.active)
        moves = np.zeros((E, A), dtype=np.int64)
        new_state = None
        no_start = np.zeros_like(starts)
        for i in range(A):                 # observer i hears the ablated symbols, keeps its own
            view = with_received_symbols(shown, heard, i)
            actions, after = self.policy.act_phase(view, protocol.MOVE_PHASE, lstm, no_start, deterministic)
            moves[:, i] = actions[:, i, 1]
            if after is not None:
                rows = np.arange(E) * A + i                                         # row of (e, i)
                if new_state is None:
                    new_state = tuple(np.array(x, copy=True) for x in after)
                for mine, theirs in zip(new_state, after):
                    mine[:, rows] = np.asarray(theirs)[:, rows]
        return np.stack([symbols, moves], axis=-1).astype(np.int64), new_state

    def seed_sampling(self, seed: int) -> None:
        self.policy.seed_sampling(seed)


def message_ablation(policy, n_agents: int = 3, episodes: int = 10, steps: int = 2000, seed: int = 1000) -> dict:
    """The three evaluations and the paired changes (module docstring).

    Args:
        policy: a zoo policy with same-step messages.
        n_agents: team size (at least 2).
        episodes: episodes (each evaluated three times from the same start).
        steps: simulator steps per episode.
        seed: seed of the episodes and the shuffles (not the evaluation's 0).

    Returns:
        {"baseline": {metric: mean}, "constant"/"shuffled": {metric: {"mean", "change",
        "change_ci95"}}, "n_agents", "episodes", "steps", "seed"}; metrics over every episode
        (failed ones included: the ablation must not hide a team that runs dry).
    """
    if int(n_agents) < 2:
        raise ValueError(f"the message ablation needs a team of at least 2 agents, got n_agents={n_agents}")
    MessageAblation(policy, "constant")                    # the same checks before any work
    cfg = evaluation_config(policy, steps)
    figures = {}
    for mode in (None, *MODES):
        actor = policy if mode is None else MessageAblation(policy, mode, seed)
        per_episode = run_episodes(actor, policy.spec, cfg, int(n_agents), int(episodes), seed=seed)
        figures[mode] = {m: np.asarray(per_episode[m], dtype=np.float64) for m in METRICS}
    out = {"baseline": {m: float(figures[None][m].mean()) for m in METRICS}}
    for mode in MODES:
        out[mode] = {m: {"mean": float(figures[mode][m].mean()),
                         "change": float((figures[mode][m] - figures[None][m]).mean()),
                         "change_ci95": mean_interval(figures[mode][m] - figures[None][m])} for m in METRICS}
    out.update(n_agents=int(n_agents), episodes=int(episodes), steps=int(steps), seed=int(seed))
    return out


def ablation_table(name: str, result: dict) -> str:
    """A markdown table of :func:`message_ablation`: one row per mode."""
    lines = [f"Message ablation of {name} ({result['n_agents']} agents, {result['episodes']} episodes x "
             f"{result['steps']} steps, seed {result['seed']}; change = ablated - as trained, 95 % interval):",
             "", "| received | AVG^h | MAX^h | collisions |", "|---|---|---|---|",
             "| as sent | " + " | ".join(f"{result['baseline'][m]:.1f}" for m in METRICS) + " |"]
    for mode in MODES:
        cells = []
        for m in METRICS:
            r = result[mode][m]
            low, high = r["change_ci95"]
            cells.append(f"{r['mean']:.1f} ({r['change']:+.1f}, [{low:+.1f}, {high:+.1f}])")
        lines.append(f"| {mode} | " + " | ".join(cells) + " |")
    return "\n".join(lines)
