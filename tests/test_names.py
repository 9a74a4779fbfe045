"""patrolsb3.names: one display name per strategy, whatever it is called on the command line or
in the paper's data files."""
from patrolsb3.names import display_name


def test_every_spelling_of_a_strategy_reads_the_same():
    for spelling in ("zoo:rl-msg", "MSG"):
        assert display_name(spelling) == "RL-MSG"
    for spelling in ("zoo:rl-no-msg", "NOMSG"):
        assert display_name(spelling) == "RL-NO-MSG"
    assert display_name("zoo:rl-intention:guarded") == display_name("INTENTION-GUARDED") == "RL-INTENTION (guarded)"
    assert display_name("SEBS") == "SEBS" and display_name("RANDOM") == "RANDOM"


def test_the_strategy_grammar_lives_here_and_imports_nothing_heavy():
    import subprocess
    import sys

    import pytest

    from patrolsb3.names import StrategyNameError, is_learned, parse_strategy, strategy_name
    assert parse_strategy("zoo:rl-msg") == ("rl-msg", False) and parse_strategy("ZOO:RL-MSG:guarded") == ("rl-msg", True)
    assert strategy_name("rl-no-msg", guard=True) == "zoo:rl-no-msg:guarded"
    assert is_learned("zoo:rl-msg") and is_learned("Zoo:rl-msg") and not is_learned("SEBS")
    for bad, match in (("SEBS", "not a zoo strategy"), ("zoo:rl-shout", "unknown variant"), ("zoo:rl-msg:x", "suffix")):
        with pytest.raises(StrategyNameError, match=match):
            parse_strategy(bad)
    code = "import sys, patrolsb3.names; print(any(m in sys.modules for m in ('torch', 'supersuit')))"
    assert subprocess.run([sys.executable, "-c", code], capture_output=True, text=True).stdout.strip() == "False"
