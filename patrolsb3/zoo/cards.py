"""Model cards of the zoo's entries (``patrolsb3 zoo cards --out docs/zoo``): one markdown page
per entry, in the spirit of the Hugging Face SB3 model cards (library, env, settings, budget,
evaluation, what its messages carry, usage), an index of them, and ``messages.md``: the
listening and ablation figures of every entry that has them, side by side."""
from __future__ import annotations

from pathlib import Path

from .. import ablation
from ..names import strategy_name
from ..outputs import read_json
from ..report import ZOO_TABLE_METRICS, mean_std
from ..runs import ZooEntry
from .folders import list_entries
from .results import recipe_of

VARIANT_TEXT = {"rl-msg": "learned 16-symbol messages (RIAL)", "rl-no-msg": "positions only, no messages",
                "rl-intention": "each agent announces its intended move (a fixed meaning)"}
PAPER_BUDGET = ("the paper's budget, as we read it: 1,500 episodes of 5,000 simulator steps, 8 in "
                "parallel, i.e. 7.5 M simulator steps of episodes (~15-18 M agent decisions with messages)")


def simulator_steps(config: dict, agent_steps: int) -> int:
    """Simulator steps of episodes behind ``agent_steps`` (SB3's count: rows x env steps), for a
    run of ``n_envs`` parallel episodes with ``max_agents`` rows each and two env steps per
    simulator step with same-step messages."""
    env = config.get("env") or {}
    rows = int((config.get("hyperparams") or {}).get("n_envs", 8)) * int(env.get("max_agents", 5))
    phases = 2 if env.get("comm", "learned") != "none" and env.get("message_timing", "same_step") == "same_step" else 1
    return int(agent_steps) // (rows * phases) * int((config.get("hyperparams") or {}).get("n_envs", 8))


def entry_name(entry: dict) -> str:
    """``A/rl-msg/seed0`` (the main zoo), ``paper-recipe/A/rl-msg/seed0`` (a shelf),
    ``guarded/A/rl-msg`` (behind the return guard)."""
    c = entry["config"]
    name = f"{c.get('map')}/{c.get('variant')}" + (f"/seed{entry['seed']}" if entry.get("seed") is not None else "")
    return f"{entry['shelf']}/{name}" if entry.get("shelf") else name


def load_line(entry: dict) -> str:
    """The line of Python that loads this entry, and its strategy name."""
    c = entry["config"]
    extra = (f", shelf={entry['shelf']!r}" if entry.get("shelf") else "") + \
        (f", seed={entry['seed']}" if entry.get("seed") is not None else "")
    return (f"policy = zoo.load({c.get('map')!r}, {c.get('variant')!r}{extra})        # evaluation: "
            f"--strategy {strategy_name(c.get('variant'), entry.get('shelf', ''))}")


METRIC_LABEL = {"avg_idleness": "AVG^h", "max_idleness": "MAX^h", "collisions": "collisions"}
ABLATION_METRICS = tuple((m, METRIC_LABEL[m]) for m in ablation.METRICS)   # what zoo ablation measures
ABLATIONS = ablation.MODES


def message_figures(entry: dict) -> tuple[dict | None, dict | None]:
    """The entry's ``listening.json`` and ``ablation.json`` (written by ``zoo listening`` and
    ``zoo ablation`` beside the model), each None where the entry has none."""
    folder = ZooEntry(entry["path"])
    found = []
    for path in (folder.listening_file, folder.ablation_file):
        name = path.name
        found.append(read_json(path, f"{name} of 'patrolsb3 zoo {name.split('.')[0]}'") if path.is_file() else None)
    return found[0], found[1]


def change_text(figure: dict) -> str:
    """``+6.1 [+3.1, +8.8] *``: an ablation's change (ablated - as trained) with its 95 %
    interval, starred when the interval excludes zero."""
    low, high = figure["change_ci95"]
    star = " *" if low > 0 or high < 0 else ""
    return f"{figure['change']:+.1f} [{low:+.1f}, {high:+.1f}]{star}"


def listening_cells(figures: dict) -> list[str]:
    """KL, greedy change, symbols, entropy and the two mutual informations of ``listening.json``."""
    return [f"{figures['kl_nats']:.3f}", f"{100 * figures['greedy_changed']:.1f} %",
            f"{figures['symbols_used']} of 16", f"{figures['symbol_entropy_bits']:.2f}",
            f"{figures['mi_own_move_bits']:.2f}", f"{figures['mi_others_moves_bits']:.2f}"]


LISTENING_HEADER = ("| listening KL (nats) | greedy move changed | symbols used | symbol entropy (bits) | "
                    "MI symbol ; own next move (bits) | MI symbol ; others' next moves (bits) |")


def messages_section(entry: dict) -> list[str]:
    """The card's "What its messages carry" section; empty when the entry has no figures."""
    listening, figures = message_figures(entry)
    lines = []
    if listening or figures:
        lines += ["## What its messages carry", ""]
    if listening:
        lines += [f"`patrolsb3 zoo listening` ({listening['n_agents']} agents, {listening['episodes']} "
                  f"episodes x {listening['steps']} steps, seed {listening['seed']}):", "",
                  LISTENING_HEADER, "|---" * 6 + "|", "| " + " | ".join(listening_cells(listening)) + " |", ""]
    if figures:
        lines += [f"`patrolsb3 zoo ablation` ({figures['n_agents']} agents, {figures['episodes']} episodes "
                  f"x {figures['steps']} steps, seed {figures['seed']}; change = ablated - as trained, "
                  f"95 % interval of the paired difference, * where it excludes zero):", "",
                  "| received | " + " | ".join(h for _, h in ABLATION_METRICS) + " |", "|---" * 4 + "|",
                  "| as sent | " + " | ".join(f"{figures['baseline'][k]:.1f}" for k, _ in ABLATION_METRICS) + " |"]
        for kind in ABLATIONS:
            lines.append(f"| {kind} | " + " | ".join(
                f"{figures[kind][k]['mean']:.1f} ({change_text(figures[kind][k])})" for k, _ in ABLATION_METRICS) + " |")
        lines.append("")
    return lines


def messages_page(entries: list[dict]) -> str:
    """``messages.md``: one row per entry with listening figures, then one per entry with an
    ablation, so that the seeds of every map can be read side by side."""
    rows = [(entry_name(e), *message_figures(e)) for e in entries]
    lines = ["# What the messages carry", "",
             "Written by `patrolsb3 zoo cards` from the `listening.json` and `ablation.json` beside each "
             "entry (`patrolsb3 zoo listening MAP VARIANT --seed-of-entry K`, `patrolsb3 zoo ablation ...`). "
             "Listening: how much an agent's move distribution changes when the symbols it receives are "
             "replaced by random ones. Ablation: the team's figures when the received symbols are a "
             "constant or shuffled between agents; change = ablated - as trained, 95 % interval of the "
             "paired difference, * where it excludes zero.", "",
             "## Listening", "", "| entry " + LISTENING_HEADER, "|---" * 7 + "|"]
    lines += [f"| {name} | " + " | ".join(listening_cells(lis)) + " |" for name, lis, _ in rows if lis]
    lines += ["", "## Ablation", "",
              "| entry | " + " | ".join(f"{kind}: {h}" for kind in ABLATIONS for _, h in ABLATION_METRICS) + " |",
              "|---" * (1 + len(ABLATIONS) * len(ABLATION_METRICS)) + "|"]
    lines += [f"| {name} | " + " | ".join(change_text(abl[kind][k]) for kind in ABLATIONS for k, _ in ABLATION_METRICS)
              + " |" for name, _, abl in rows if abl]
    return "\n".join(lines) + "\n"


def precision_text(config: dict) -> str:
    """The precision a run trained in, with each change on a resume: ``fp32``, or ``bf16 to
    8,800,000 agent-steps, then fp32``. Runs from before the setting are fp32."""
    text = str((config.get("hyperparams") or {}).get("precision", "fp32"))
    for change in config.get("precision_changes") or []:
        text += f" to {int(change['timesteps']):,} agent-steps, then {change['precision']}"
    return text


def card(entry: dict) -> str:
    """The markdown card of one entry (``patrolsb3.zoo.list_entries``' dict)."""
    c, ev = entry["config"], entry.get("eval") or {}
    env, budget = c.get("env") or {}, c.get("budget") or {}
    name = entry_name(entry)
    guarded = bool(env.get("return_guard"))
    lines = [f"# {name}", "",
             f"- **variant**: `{c.get('variant')}`, {VARIANT_TEXT.get(c.get('variant'), '')}",
             f"- **algorithm**: {c.get('algo')} (patrolsb3, Stable-Baselines3 / sb3-contrib), env "
             f"`{c.get('env_version')}`, trained {c.get('date', '?')}",
             "- **setting**: " + ("**behind the return guard** (`env.return_guard`, ours: the heuristics' "
                                   "recharge rule as a shield on the moves; not the paper's setting)"
                                   if guarded else "the paper's setting (no return guard)"),
             f"- **recipe**: {recipe_of(c)}; docs/training.md compares the recipes",
             f"- **precision**: {precision_text(c)}",
             f"- **observation**: messages `{env.get('message_encoding', 'scalar')}`, local idleness "
             f"{'on' if env.get('local_idleness') else 'off'}, difference-reward weight c_d = {env.get('c_d')}",
             f"- **budget**: {int(budget.get('timesteps', 0)):,} agent-steps (all stages), about "
             f"{simulator_steps(c, budget.get('timesteps', 0)):,} simulator steps of episodes, "
             f"{budget.get('cpu_hours', '?')} CPU hours; {PAPER_BUDGET}",
             f"- **training seed**: {c.get('seed')} (each seed is its own entry; `patrolsb3 compare` "
             f"pools the seeds of an entry)", ""]
    if ev:
        lines += ["## Evaluation", "",
                  f"{ev.get('tests')} test x {ev.get('episodes')} episodes x {ev.get('steps')} steps per "
                  f"team size, seed {ev.get('seed')}, "
                  f"{'most likely legal action' if ev.get('deterministic', True) else 'sampled actions'}; "
                  f"the 95 % bootstrap interval over episodes is in brackets where the evaluation "
                  f"stored one (evaluations before 2026-12-02 did not: rerun `patrolsb3 zoo export` "
                  f"or `patrolsb3 zoo eval MAP VARIANT` to get them).", "",
                  "| n | " + " | ".join(h for _, h, _ in ZOO_TABLE_METRICS) + " |",
                  "|---" * (1 + len(ZOO_TABLE_METRICS)) + "|"]
        for row in ev.get("results", []):
            s = row["summary"]
            cells = []
            for key, _, digits in ZOO_TABLE_METRICS:
                cells.append(mean_std(s.get(key) or {}, digits))
            lines.append(f"| {row['n_agents']} | " + " | ".join(cells) + " |")
        lines.append("")
    lines += messages_section(entry)
    lines += ["## How to load it", "", "```python", "import patrolsb3",
              "from patrolsb3 import zoo", "from patrolsb3.agents import PettingZooAgent, play_episode", "",
              load_line(entry),
              f"env = patrolsb3.parallel_env({c.get('map')!r}, n_agents=3, **policy.env_settings())",
              "print(play_episode(env, PettingZooAgent(policy, env), seed=0))", "```", ""]
    return "\n".join(lines)


def write_cards(out_dir, zoo_dir=None) -> list[Path]:
    """Write one card per zoo entry, ``index.md`` and ``messages.md`` into ``out_dir``; returns
    the paths."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    entries = list_entries(zoo_dir)
    written, index = [], ["# Model cards", "", "| entry | variant | setting | recipe | agent-steps | CPU h |",
                          "|---|---|---|---|---|---|"]
    for entry in entries:
        c = entry["config"]
        stem = entry_name(entry).replace("/", "-")
        path = out / f"{stem}.md"
        path.write_text(card(entry))
        written.append(path)
        guarded = "return guard" if (c.get("env") or {}).get("return_guard") else "paper's"
        budget = c.get("budget") or {}
        index.append(f"| [{entry_name(entry)}]({stem}.md) | {c.get('variant')} | {guarded} | {recipe_of(c)} | "
                     f"{int(budget.get('timesteps', 0)):,} | {budget.get('cpu_hours', '?')} |")
    index += ["", "What the learned messages carry, every entry side by side: [messages.md](messages.md)."]
    (out / "index.md").write_text("\n".join(index) + "\n")
    (out / "messages.md").write_text(messages_page(entries))
    return written + [out / "index.md", out / "messages.md"]
