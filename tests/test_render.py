"""patrolsb3.render: frames, GIFs, map pictures and heat maps."""
import numpy as np
import pytest
from PIL import Image, ImageSequence

import patrolsb3
from patrolsb3.core.state import SWAPPING
from patrolsb3.render import (EMPTY_RGB, FOOTER, OBSTACLE_RGB, STATION_RGB, draw_map_png,
                              plot_idleness_heatmap, render_frame, save_gif)

from conftest import deterministic_config, place

T = 10   # tile size used in these tests


def centre(r, c, tile=T):
    return r * tile + tile // 2, c * tile + tile // 2


def corner(r, c, tile=T):
    """A pixel inside the tile, away from the disc, the digits and the grid line."""
    return r * tile + tile - 2, c * tile + 2


@pytest.fixture
def scene(non_square_map):
    spec = non_square_map            # "S..#..2" / ".#....." / "...#5.."
    cfg = deterministic_config(max_agents=3)
    state = place(spec, cfg, [(1, 4), (2, 6)], battery=[50.0, 550.0])
    return spec, cfg, state


def test_frame_shape_dtype_and_orientation(scene):
    spec, cfg, state = scene
    frame = render_frame(spec, cfg, state, tile=T)
    assert frame.shape == (3 * T + FOOTER, 7 * T, 3) and frame.dtype == np.uint8
    assert tuple(frame[corner(0, 3)]) == OBSTACLE_RGB
    assert tuple(frame[corner(2, 3)]) == OBSTACLE_RGB
    assert tuple(frame[corner(0, 0)]) == STATION_RGB
    assert tuple(frame[corner(0, 1)]) == EMPTY_RGB          # visited, idleness 0


def test_agent_pixel_differs_from_the_empty_cell(scene):
    spec, cfg, state = scene
    frame = render_frame(spec, cfg, state, tile=T)
    empty = tuple(frame[centre(1, 2)])
    assert empty == EMPTY_RGB
    assert tuple(frame[centre(1, 4)]) != empty
    assert tuple(frame[centre(2, 6)]) != empty
    assert tuple(frame[centre(1, 4)]) != tuple(frame[centre(2, 6)])   # one colour per slot
    state.pos[0, 0] = 1 * 7 + 2
    moved = render_frame(spec, cfg, state, tile=T)
    assert tuple(moved[centre(1, 2)]) != empty and tuple(moved[centre(1, 4)]) == EMPTY_RGB


def test_idleness_heat_and_never_visited(scene):
    spec, cfg, state = scene
    state.idle[0, spec.vertex_of_cell[1 * 7 + 2]] = 150.0
    state.visited[0, spec.vertex_of_cell[2 * 7 + 0]] = False
    frame = render_frame(spec, cfg, state, tile=T)
    warm, hot = frame[corner(1, 2)].astype(int), frame[corner(2, 0)].astype(int)
    assert tuple(warm) != EMPTY_RGB and tuple(hot) != EMPTY_RGB
    assert hot[0] > hot[2] + 100                             # never visited: red
    assert warm[1] > hot[1]                                  # less idle: lighter


def test_battery_bar_and_swapping_agent_are_drawn(scene):
    spec, cfg, state = scene
    state.status[0, 1] = SWAPPING
    state.pos[0, 1] = spec.station
    frame = render_frame(spec, cfg, state, tile=32)
    station = frame[:32, :32].reshape(-1, 3)
    assert (np.abs(station.astype(int) - STATION_RGB).sum(axis=1) > 60).sum() > 20   # outline
    low_bar = frame[32:64, 4 * 32:5 * 32].reshape(-1, 3).astype(int)
    assert ((low_bar[:, 0] > 200) & (low_bar[:, 1] < 80)).any()   # battery 50 < b_l: red bar


def test_env_rgb_array_render():
    env = patrolsb3.parallel_env("B", n_agents=2, seed=0, render_mode="rgb_array")
    env.reset()
    frame = env.render()
    assert frame.shape == (12 * 32 + FOOTER, 12 * 32, 3) and frame.dtype == np.uint8
    with pytest.raises(ValueError, match="render_mode"):
        patrolsb3.parallel_env("B", n_agents=2).render()


def test_bad_env_index_is_refused(scene):
    spec, cfg, state = scene
    with pytest.raises(ValueError, match="env_index=1 outside the batch of 1 episodes"):
        render_frame(spec, cfg, state, env_index=1)


def test_gif_has_every_frame(scene, tmp_path):
    spec, cfg, state = scene
    frames = []
    for k in range(4):
        state.pos[0, 0] = 1 * 7 + 2 + k
        state.t[0] = k
        frames.append(render_frame(spec, cfg, state, tile=T))
    path = save_gif(frames, tmp_path / "out" / "run.gif", fps=5)
    with Image.open(path) as gif:
        decoded = [np.asarray(f.convert("RGB")) for f in ImageSequence.Iterator(gif)]
        assert gif.info["duration"] == 200
    assert len(decoded) == 4
    assert decoded[0].shape == frames[0].shape
    assert tuple(decoded[3][centre(1, 5)]) == tuple(frames[3][centre(1, 5)])
    with pytest.raises(ValueError, match="at least one frame"):
        save_gif([], tmp_path / "none.gif")


def test_map_picture_and_heat_map_files(non_square_map, tmp_path):
    spec = non_square_map
    path = draw_map_png(spec, tmp_path / "map.png")
    with Image.open(path) as img:
        assert img.format == "PNG" and img.size[0] > 7 * 32
    values = np.arange(spec.n_vertices, dtype=float)
    path = plot_idleness_heatmap(spec, values, tmp_path / "heat.png")
    with Image.open(path) as img:
        assert img.format == "PNG"
    with pytest.raises(ValueError, match=r"one value per vertex, shape \(17,\)"):
        plot_idleness_heatmap(spec, values[:-1], tmp_path / "bad.png")


def test_human_mode_reuses_one_window(monkeypatch):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    monkeypatch.setattr(plt, "pause", lambda interval: None)
    env = patrolsb3.parallel_env("A", n_agents=1, seed=0, render_mode="human")
    env.reset()
    assert env.render() is None
    fig, image = env._viewer
    env.step({"drone_0": (0, 4)})
    env.render()
    assert env._viewer[0] is fig
    assert np.array_equal(image.get_array(), render_frame(env.spec_map, env.cfg, env.core_state))
    plt.close(fig)
