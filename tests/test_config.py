"""EnvConfig refuses values outside their meaning, in one line that names the field."""
import math

import pytest

from patrolsb3.core import make_config
from patrolsb3.core.config import EnvConfig

BAD = [
    ({"b_max": 0}, "b_max must be a finite number > 0"),
    ({"b_max": -5.0}, "b_max"),
    ({"b_max": math.inf}, "b_max"),
    ({"b_max": math.nan}, "b_max"),
    ({"c_norm": 0.0}, "c_norm must be a finite number > 0"),
    ({"init_battery": (0.5, 1.2)}, "init_battery"),
    ({"init_battery": (-0.1, 0.5)}, "init_battery"),
    ({"init_battery": (0.9, 0.5)}, "low <= high"),
    ({"drain": (-1.0, 1.0)}, "drain must be a finite number >= 0"),
    ({"p_dyn_max": 1.5}, "p_dyn_max must be a finite number in \\[0, 1\\]"),
    ({"fault_prob": -0.1}, "fault_prob"),
    ({"b_low_frac": 2.0}, "b_low_frac"),
    ({"episode_steps": 2.5}, "episode_steps must be a whole number"),
    ({"episode_steps": 0}, "episode_steps"),
    ({"max_agents": True}, "max_agents must be a whole number"),
    ({"max_agents": "3"}, "max_agents"),
    ({"return_guard": "no"}, "return_guard must be true or false"),
    ({"local_idleness": 1}, "local_idleness"),
    ({"swap_time": (3.5, 8)}, "swap_time must be a whole number"),
    ({"swap_time": (0, 8)}, "swap_time"),
    ({"c_d": -1.0}, "c_d"),
    ({"c_pb": "a lot"}, "c_pb must be a number"),
    ({"faults": ((10,),)}, "faults must be \\(step, k\\) pairs"),
    ({"faults": ((10, 0),)}, "faults k"),
    ({"comm": "telepathy"}, "comm must be one of"),
]


@pytest.mark.parametrize("overrides, match", BAD)
def test_nonsense_is_refused_naming_the_field(overrides, match):
    with pytest.raises(ValueError, match=match) as info:
        make_config(**overrides)
    assert "\n" not in str(info.value)


def test_the_defaults_and_the_paper_maps_are_accepted():
    assert EnvConfig().b_max == 550.0
    for name in "ABCD":
        make_config(name)
    assert make_config(init_battery=[0.15, 1.0], faults=[[100, 1]]).faults == ((100, 1),)
