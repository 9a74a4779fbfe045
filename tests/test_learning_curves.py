"""Learning curves: the trailing mean, the simulator-step axis, the figure and a run's summary."""
import numpy as np
import pytest

from patrolsb3.learning_curves import curve_summary, curve_table, plot_learning_curves, trailing_mean, training_axis
from patrolsb3.runs import read_curve


def test_trailing_mean_by_hand():
    np.testing.assert_allclose(trailing_mean([1, 2, 3, 4, 5], 2), [1, 1.5, 2.5, 3.5, 4.5])
    np.testing.assert_allclose(trailing_mean([4, 0, 2], 50), [4, 2, 2])


def test_learning_curve_figure_is_written(tmp_path):
    csv_path = tmp_path / "curve.csv"
    csv_path.write_text("timesteps,n_agents,reward\n100,1,-5\n200,2,-3\n300,2,-1\n")
    assert read_curve(csv_path)["reward"].tolist() == [-5, -3, -1]
    out = plot_learning_curves({"rl-msg": csv_path}, tmp_path / "lc.png", title="A")
    assert out.stat().st_size > 1000


def test_learning_curves_are_drawn_against_simulator_steps():
    # rows as episodes end (not in timesteps order); sim_steps is each episode's length
    data = {"timesteps": np.array([300.0, 100.0, 200.0]), "reward": np.array([3.0, 1.0, 2.0]),
            "sim_steps": np.array([30.0, 10.0, 20.0])}
    order, x, label = training_axis(data)
    assert order.tolist() == [1, 2, 0] and x.tolist() == [10, 30, 60] and label.startswith("simulator")
    del data["sim_steps"]
    assert training_axis(data)[1].tolist() == [100, 200, 300] and training_axis(data)[2] == "agent-steps"


def test_curve_summary_quarters(tmp_path):
    path = tmp_path / "curve.csv"
    rows = ["timesteps,n_agents,reward,mean_idleness,max_idleness,collisions,battery_failures,sim_steps"]
    for i in range(8):   # first quarter (2 episodes): failures, last quarter: none
        rows.append(f"{(i + 1) * 100},1,{-100 + 20 * i},{50 - i},99,0,{1 if i < 3 else 0},500")
    path.write_text("\n".join(rows) + "\n")
    s = curve_summary(path)
    assert s["episodes"] == 8 and s["timesteps"] == 800
    assert s["bf_first"] == 1.0 and s["bf_last"] == 0.0
    assert s["reward_first"] == -90.0 and s["reward_last"] == 30.0
    assert s["idleness_first"] == 49.5 and s["idleness_last"] == 43.5
    assert "| run1 | 800 | 8 | -90 / 30 | 1.00 / 0.00 | 50 / 44 |" in curve_table({"run1": path})
    empty = tmp_path / "empty.csv"
    empty.write_text(rows[0] + "\n")
    with pytest.raises(ValueError, match="no finished training episode"):
        curve_summary(empty)
