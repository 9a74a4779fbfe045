"""The command line as a whole: every sub-command's --help prints (argparse expands '%' in help
strings, so a bare '95 %' crashes `patrolsb3 zoo --help` with a TypeError)."""
import argparse

import pytest

from patrolsb3.cli import build_parser, main


def _command_paths(parser, path=()):
    """Every sub-command path of the parser, e.g. ('zoo', 'eval'), depth first."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield path + (name,)
                yield from _command_paths(sub, path + (name,))


PATHS = list(_command_paths(build_parser()))


def test_every_command_is_found():
    assert ("zoo",) in PATHS and ("zoo", "eval") in PATHS and ("claims",) in PATHS


@pytest.mark.parametrize("path", [()] + PATHS, ids=lambda p: " ".join(p) or "patrolsb3")
def test_help_prints(path, capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(list(path) + ["--help"])
    assert exit_info.value.code == 0
    assert "usage: patrolsb3" in capsys.readouterr().out
