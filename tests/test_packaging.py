"""A package that installs: the wheel holds every package, the maps and the hyperparameters; an
installed copy used from another folder loads and draws the shipped maps, and says in one line
where it looked for the zoo."""
import os
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


@pytest.fixture(scope="module")
def wheel(tmp_path_factory):
    out = tmp_path_factory.mktemp("wheel")
    subprocess.run([sys.executable, "-m", "pip", "wheel", str(ROOT), "--no-deps", "-q", "-w", str(out)],
                   check=True, capture_output=True)
    (path,) = out.glob("patrolsb3-*.whl")
    return path


def test_the_wheel_holds_every_package_map_and_hyperparameter_file(wheel):
    names = set(zipfile.ZipFile(wheel).namelist())
    packages = sorted(p.parent.relative_to(ROOT).as_posix() for p in (ROOT / "patrolsb3").rglob("__init__.py"))
    for package in packages:
        assert f"{package}/__init__.py" in names, f"{package} is missing from setup.cfg's packages"
    for path in (ROOT / "maps").glob("map_*.txt"):
        assert f"patrolsb3/maps/{path.name}" in names
    assert "patrolsb3/hyperparams/default.yml" in names
    assert not any(n.startswith(("tests/", "zoo/")) for n in names)


def test_an_installed_copy_loads_and_draws_the_maps_from_another_folder(wheel, tmp_path):
    site = tmp_path / "site"
    subprocess.run([sys.executable, "-m", "pip", "install", "--no-deps", "-q", "--target", str(site), str(wheel)],
                   check=True, capture_output=True)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    env = {**os.environ, "PYTHONPATH": str(site), "MPLBACKEND": "Agg"}
    env.pop("PATROLSB3_ZOO", None)
    code = ("import patrolsb3, pathlib; from patrolsb3.core import load_map, available_maps; "
            "print(pathlib.Path(patrolsb3.__file__).parent); print(','.join(available_maps())); "
            "print(load_map('C').shape)")
    out = subprocess.run([sys.executable, "-c", code], cwd=elsewhere, env=env, check=True,
                         capture_output=True, text=True).stdout.split("\n")
    assert out[0] == str(site / "patrolsb3")
    assert out[1] == "A,B,C,D" and out[2] == "(12, 12)"
    drawn = subprocess.run([sys.executable, "-c", "from patrolsb3.cli import main; raise SystemExit(main())",
                            "maps", "A", "--png", str(elsewhere / "png")], cwd=elsewhere, env=env,
                           capture_output=True, text=True)
    assert drawn.returncode == 0, drawn.stderr
    assert (elsewhere / "png" / "map_a.png").stat().st_size > 1000
    # no zoo beside an installed package: one line that says where it looked and what to do
    missing = subprocess.run([sys.executable, "-c", "from patrolsb3 import zoo; zoo.load('A', 'rl-msg')"],
                             cwd=elsewhere, env=env, capture_output=True, text=True)
    assert missing.returncode != 0 and "no zoo found" in missing.stderr and "PATROLSB3_ZOO" in missing.stderr
    found = subprocess.run([sys.executable, "-c", "from patrolsb3 import zoo; print(zoo.available('A', 'rl-msg'))"],
                           cwd=elsewhere, env={**env, "PATROLSB3_ZOO": str(ROOT / "zoo")},
                           capture_output=True, text=True)
    assert found.stdout.strip() == "True"


def test_version_and_the_files_a_release_needs(capsys):
    import patrolsb3
    from patrolsb3.cli import main
    with pytest.raises(SystemExit) as stop:
        main(["--version"])
    assert stop.value.code == 0 and capsys.readouterr().out.strip() == f"patrolsb3 {patrolsb3.__version__}"
    assert "MIT License" in (ROOT / "LICENSE").read_text()
    import yaml
    citation = yaml.safe_load((ROOT / "CITATION.cff").read_text())
    assert citation["cff-version"] == "1.2.0" and citation["version"] == patrolsb3.__version__
    assert "Learning to Communicate and Cooperate" in citation["preferred-citation"]["title"]
    assert (ROOT / "CHANGELOG.md").read_text().startswith("# Changelog")
