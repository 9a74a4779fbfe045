"""Learning curves of training runs (their ``curve.csv``, read by :func:`patrolsb3.runs.read_curve`):
the paper's training figure (every seed, their mean and a band) and a run's summary table."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .runs import read_curve


def trailing_mean(values: np.ndarray, window: int) -> np.ndarray:
    """Mean of the last ``window`` values at each position (fewer at the start); (N,)."""
    values = np.asarray(values, dtype=np.float64)
    csum = np.concatenate([[0.0], np.cumsum(values)])
    idx = np.arange(1, len(values) + 1)
    start = np.maximum(idx - window, 0)
    return (csum[idx] - csum[start]) / (idx - start)


def training_axis(data: dict) -> tuple[np.ndarray, np.ndarray, str]:
    """The x axis of a learning curve, and the row order along it.

    Variants are compared at equal *simulator* steps (rl-no-msg has one decision per step,
    rl-msg and rl-intention two), so the axis is the simulator steps of the training episodes
    finished so far (the cumulative ``sim_steps`` column, rows in ``timesteps`` order); a curve
    without that column falls back to agent-steps.

    Returns:
        order (N,) int row order, x (N,) float, and the axis label.
    """
    order = np.argsort(data["timesteps"], kind="stable")
    if "sim_steps" in data:
        return order, np.cumsum(data["sim_steps"][order]), "simulator steps of finished training episodes"
    return order, data["timesteps"][order], "agent-steps"


def plot_learning_curves(curves: dict, path, title: str = "", window: int = 50) -> Path:
    """The paper's training figure: episode return (cumulative team reward per episode),
    smoothed over the last ``window`` episodes, against simulator steps (:func:`training_axis`).
    A variant with one curve is one line; one with several training seeds shows every seed
    (thin, named by its folder), their mean on a common axis (thick) and a band from the lowest
    to the highest seed, up to the steps every seed reached.

    Args:
        curves: label -> path of a curve.csv, or a list of paths (one a training seed).
        path: PNG to write.
        title: figure title (e.g. the map).
        window: episodes in the trailing mean.

    Returns:
        The PNG path.
    """
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 6), dpi=100)
    xlabels = set()
    for label, paths in curves.items():
        paths = [paths] if isinstance(paths, (str, Path)) else list(paths)
        lines = []                                             # (x (N,), smoothed reward (N,), seed name)
        for csv_path in paths:
            data = read_curve(csv_path)
            if not data:
                continue
            order, x, xlabel = training_axis(data)
            xlabels.add(xlabel)
            lines.append((x, trailing_mean(data["reward"][order], window), Path(csv_path).parent.name))
        if not lines:
            continue
        if len(lines) == 1:
            ax.plot(lines[0][0], lines[0][1], label=label)
            continue
        color = ax.plot([], [])[0].get_color()
        for x, y, seed in lines:
            ax.plot(x, y, color=color, linewidth=0.6, alpha=0.45, label=f"{label} {seed}")
        end = min(x[-1] for x, _, _ in lines)
        grid = np.linspace(max(x[0] for x, _, _ in lines), end, 200)                     # (200,)
        on_grid = np.array([np.interp(grid, x, y) for x, y, _ in lines])                 # (seeds, 200)
        ax.fill_between(grid, on_grid.min(axis=0), on_grid.max(axis=0), color=color, alpha=0.15)
        ax.plot(grid, on_grid.mean(axis=0), color=color, linewidth=2.2,
                label=f"{label}: mean of {len(lines)} seeds (band: lowest to highest)")
    ax.set_xlabel(" / ".join(sorted(xlabels)) or "agent-steps")
    ax.set_ylabel(f"episode reward (mean of last {window})")
    ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, ncol=2, loc="upper center", bbox_to_anchor=(0.5, -0.14))   # below: it hides no data
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path)
    plt.close(fig)
    return path


def curve_summary(curve_csv, fraction: float = 0.25) -> dict:
    """How a training run went, from its ``curve.csv`` (one row per finished episode): the mean
    team reward, the share of episodes with a battery failure ("bf") and the mean idleness over
    the first and the last ``fraction`` of its episodes, the episodes and the last timesteps.

    Raises:
        ValueError: a curve without episodes (names the file).
    """
    columns = read_curve(curve_csv)                           # {column: (N,) float}
    if not columns:
        raise ValueError(f"{curve_csv}: no finished training episode yet")
    n = len(columns["timesteps"])
    k = max(1, round(n * fraction))
    out = {"timesteps": int(columns["timesteps"][-1]), "episodes": n}
    for label, part in (("first", slice(0, k)), ("last", slice(n - k, n))):
        out[f"reward_{label}"] = float(columns["reward"][part].mean())
        out[f"bf_{label}"] = float((columns["battery_failures"][part] > 0).mean())
        out[f"idleness_{label}"] = float(columns["mean_idleness"][part].mean())
    return out


def curve_table(curves: dict) -> str:
    """Markdown table of :func:`curve_summary` for ``{name: curve.csv path}``."""
    lines = ["| run | agent-steps | episodes | reward first / last quarter | battery failure share "
             "first / last | mean idleness first / last |", "|---|---|---|---|---|---|"]
    for name, path in curves.items():
        s = curve_summary(path)
        lines.append(f"| {name} | {s['timesteps']:,} | {s['episodes']} | {s['reward_first']:.0f} / "
                     f"{s['reward_last']:.0f} | {s['bf_first']:.2f} / {s['bf_last']:.2f} | "
                     f"{s['idleness_first']:.0f} / {s['idleness_last']:.0f} |")
    return "\n".join(lines)
