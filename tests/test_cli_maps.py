"""``patrolsb3 maps`` through the real entry point."""
from PIL import Image

from patrolsb3.cli import main

from conftest import NON_SQUARE


def test_maps_lists_and_draws_every_shipped_map(capsys):
    assert main(["maps"]) == 0
    out = capsys.readouterr().out
    lines = out.splitlines()
    assert lines[0].split() == ["name", "size", "vertices", "stations", "priority_vertices"]
    assert lines[1].split() == ["A", "12x12", "123", "1", "4"]
    assert [line.split()[0] for line in lines[1:5]] == ["A", "B", "C", "D"]
    assert "\n.S..........\n" in out            # map A's second row, drawn in the legend
    for name in "ABCD":
        assert f"map {name} (" in out


def test_maps_png_writes_one_picture_per_map(tmp_path, capsys):
    assert main(["maps", "--png", str(tmp_path / "pics"), "--no-draw"]) == 0
    out = capsys.readouterr().out
    files = sorted(p.name for p in (tmp_path / "pics").iterdir())
    assert files == ["map_a.png", "map_b.png", "map_c.png", "map_d.png"]
    assert out.count("wrote ") == 4 and "map A (" not in out
    with Image.open(tmp_path / "pics" / "map_a.png") as img:
        assert img.format == "PNG"


def test_maps_of_a_file_and_an_unknown_name(tmp_path, capsys):
    path = tmp_path / "wide.txt"
    path.write_text(NON_SQUARE)
    assert main(["maps", str(path)]) == 0
    out = capsys.readouterr().out
    assert out.splitlines()[1].split() == ["wide", "3x7", "17", "1", "2"]
    assert "S..#..2\n.#.....\n...#5.." in out
    assert main(["maps", "nope"]) == 2
    err = capsys.readouterr().err
    assert "unknown map 'nope'; known maps: A, B, C, D" in err
