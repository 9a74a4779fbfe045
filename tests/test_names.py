"""patrolsb3.names: one display name per strategy, whatever it is called on the command line or
in the paper's data files."""
from patrolsb3.names import display_name


def test_every_spelling_of_a_strategy_reads_the_same():
    for spelling in ("zoo:rl-msg", "MSG"):
        assert display_name(spelling) == "RL-MSG"
    for spelling in ("zoo:rl-no-msg", "NOMSG"):
        assert display_name(spelling) == "RL-NO-MSG"
    assert display_name("zoo:rl-intention:guarded") == display_name("INTENTION-GUARDED") == "RL-INTENTION (guarded)"
    assert display_name("zoo:rl-msg:paper-recipe") == display_name("MSG-PAPER-RECIPE") == "RL-MSG (paper recipe)"
    assert display_name("zoo:rl-msg:cd10") == display_name("MSG-CD10") == "RL-MSG (c_d 10)"
    assert display_name("SEBS") == "SEBS" and display_name("RANDOM") == "RANDOM"


def test_the_strategy_grammar_lives_here_and_imports_nothing_heavy():
    import subprocess
    import sys

    import pytest

    from patrolsb3.names import StrategyNameError, is_learned, parse_strategy, strategy_name
    assert parse_strategy("zoo:rl-msg") == ("rl-msg", "") and parse_strategy("ZOO:RL-MSG:guarded") == ("rl-msg", "guarded")
    assert parse_strategy("zoo:rl-msg:Paper-Recipe") == ("rl-msg", "paper-recipe")
    assert strategy_name("rl-no-msg", "guarded") == "zoo:rl-no-msg:guarded" and strategy_name("rl-msg") == "zoo:rl-msg"
    assert is_learned("zoo:rl-msg") and is_learned("Zoo:rl-msg") and not is_learned("SEBS")
    for bad, match in (("SEBS", "not a zoo strategy"), ("zoo:rl-shout", "unknown variant"), ("zoo:rl-msg:x", "not a shelf"),
                       ("zoo:rl-msg:", "empty shelf")):
        with pytest.raises(StrategyNameError, match=match):
            parse_strategy(bad)
    code = "import sys, patrolsb3.names; print(any(m in sys.modules for m in ('torch', 'supersuit')))"
    assert subprocess.run([sys.executable, "-c", code], capture_output=True, text=True).stdout.strip() == "False"


def test_a_commands_shelf_options_name_one_shelf():
    import pytest

    from patrolsb3.names import StrategyNameError, shelf_option
    assert shelf_option("", False) == "" and shelf_option("", True) == "guarded"
    assert shelf_option("CD10", False) == "cd10" and shelf_option("guarded", True) == "guarded"
    with pytest.raises(StrategyNameError, match="--guarded and --shelf paper-recipe"):
        shelf_option("paper-recipe", True)
    with pytest.raises(StrategyNameError, match="--shelf 'e9': not a shelf of the zoo; known: guarded, paper-recipe"):
        shelf_option("e9", False)
