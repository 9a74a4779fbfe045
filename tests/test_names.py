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
