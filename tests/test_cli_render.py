"""``patrolsb3 render`` through the real entry point (short runs)."""
from PIL import Image

from patrolsb3.cli import main


def test_render_writes_a_gif_of_every_step(tmp_path, capsys):
    out = tmp_path / "run.gif"
    frame = tmp_path / "last.png"
    assert main(["render", "--map", "C", "--agents", "2", "--steps", "12", "--out", str(out),
                 "--strategy", "CR", "--seed", "3", "--tile", "8", "--frame", str(frame)]) == 0
    with Image.open(out) as gif:
        assert gif.n_frames == 13                  # the start and every step
        assert gif.size == (12 * 8, 12 * 8 + 18)
    with Image.open(frame) as png:
        assert png.size == (12 * 8, 12 * 8 + 18)
    text = capsys.readouterr().out
    assert "13 frames" in text and "map C, 2 agents, CR, seed 3, 12 steps" in text


def test_render_keeps_one_frame_every_n_steps(tmp_path):
    out = tmp_path / "run.gif"
    assert main(["render", "--agents", "3", "--steps", "20", "--every", "5", "--out", str(out),
                 "--tile", "6"]) == 0
    with Image.open(out) as gif:
        assert gif.n_frames == 5


def test_render_refuses_bad_input(tmp_path, capsys):
    assert main(["render", "--strategy", "NOPE", "--steps", "2", "--out", str(tmp_path / "x.gif")]) == 2
    assert "unknown strategy 'NOPE'" in capsys.readouterr().err
    assert main(["render", "--agents", "9", "--steps", "2", "--out", str(tmp_path / "x.gif")]) == 2
    assert "n_agents=9 is larger than max_agents=5" in capsys.readouterr().err
