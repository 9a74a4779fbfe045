"""Output paths are checked before any long work: one line naming the argument and the cause."""
import pytest

from patrolsb3.cli import main


@pytest.mark.parametrize("argv_of, match", [
    (lambda t: ["evaluate", "--strategy", "CR", "--episodes", "1", "--steps", "5", "--json", str(t)], "is a folder"),
    (lambda t: ["evaluate", "--strategy", "CR", "--episodes", "1", "--steps", "5", "--json",
                str(t / "file.txt" / "x.json")], "is a file, not a folder"),
    (lambda t: ["compare", "--maps", "A", "--agents", "1", "--episodes", "1", "--steps", "5", "--out",
                str(t / "file.txt")], "is a file, not a folder"),
    (lambda t: ["render", "--out", str(t / "file.txt" / "a.gif"), "--steps", "3"], "is a file, not a folder"),
    (lambda t: ["maps", "A", "--png", str(t / "file.txt" / "png")], "is a file, not a folder"),
])
def test_bad_output_paths_fail_at_once(tmp_path, capsys, argv_of, match):
    (tmp_path / "file.txt").write_text("not a folder")
    assert main(argv_of(tmp_path)) == 2
    err = capsys.readouterr().err
    assert match in err and len(err.strip().splitlines()) == 1


def test_evaluate_json_into_a_missing_folder_is_made(tmp_path, capsys):
    target = tmp_path / "new" / "deeper" / "cr.json"
    assert main(["evaluate", "--strategy", "CR", "--episodes", "1", "--steps", "5", "--no-progress",
                 "--json", str(target)]) == 0
    assert target.is_file()


def test_evaluate_json_is_strict_json(tmp_path):
    import json
    target = tmp_path / "cr.json"
    # 5 steps: no agent swaps, so the battery at swap is undefined: null, not NaN
    assert main(["evaluate", "--strategy", "CR", "--episodes", "1", "--steps", "5", "--no-progress",
                 "--json", str(target)]) == 0
    text = target.read_text()
    assert "NaN" not in text
    json.loads(text, parse_constant=lambda c: (_ for _ in ()).throw(ValueError(c)))
