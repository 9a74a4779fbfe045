"""patrolsb3.core.maps: parsing, validation, static tables, and every malformed-map error."""
import numpy as np
import pytest

from patrolsb3.core.maps import (DOWN, LEFT, OBSTACLE, RIGHT, STATION, STAY, UP, VERTEX, MapError,
                                 available_maps, load_map, parse_map)

from conftest import NON_SQUARE


def test_shipped_maps_are_the_four_of_the_spec():
    assert available_maps() == ["A", "B", "C", "D"]
    for name in available_maps():
        spec = load_map(name)
        assert spec.name == name
        assert spec.shape == (12, 12)
        assert len(spec.stations) == 1
        # every free cell reachable from every other one
        assert (spec.dist >= 0).all()
        # the text drawing parses back to the same map
        again = parse_map(spec.to_text())
        assert np.array_equal(again.kinds, spec.kinds)
        assert np.array_equal(again.priority, spec.priority)


def test_load_map_is_case_insensitive_and_accepts_a_spec():
    spec = load_map("a")
    assert spec.name == "A"
    assert load_map(spec) is spec


def test_non_square_tables(non_square_map):
    spec = non_square_map
    assert spec.shape == (3, 7)
    assert spec.kinds[0, 3] == OBSTACLE and spec.kinds[1, 1] == OBSTACLE and spec.kinds[2, 3] == OBSTACLE
    assert spec.kinds[0, 0] == STATION
    assert spec.kinds[1, 6] == VERTEX
    assert spec.priority[0, 6] == 2 and spec.priority[2, 4] == 5
    assert spec.station == 0
    assert spec.n_vertices == 21 - 3 - 1
    # row-major numbering: cell = row * 7 + col
    assert list(spec.rowcol(np.array([6, 13, 18]))[0]) == [0, 1, 2]
    assert list(spec.rowcol(np.array([6, 13, 18]))[1]) == [6, 6, 4]
    assert spec.vertex_of_cell[0] == -1 and spec.vertex_of_cell[3] == -1
    assert spec.vertex_of_cell[1] == 0 and spec.vertex_of_cell[4] == 2
    assert spec.rate[spec.vertex_of_cell[6]] == 3.0
    assert spec.rate[spec.vertex_of_cell[2 * 7 + 4]] == 6.0
    assert spec.rate[spec.vertex_of_cell[1]] == 1.0
    # neighbours: from (1, 2) Up -> (0, 2), Down -> (2, 2), Left is an obstacle, Right -> (1, 3)
    c = 1 * 7 + 2
    assert list(spec.neighbour[c]) == [2, 16, c, 10, c]
    assert list(spec.move_ok[c]) == [True, True, False, True, True]
    # the corner (0, 6): Up and Right leave the grid
    assert list(spec.move_ok[6]) == [False, True, True, False, True]


def test_bfs_distances_and_first_actions(non_square_map):
    spec = non_square_map
    station, far = 0, 2 * 7 + 6
    # S(0,0) -> (0,1) -> (0,2) -> (1,2) -> (1,3) -> (1,4) -> (1,5) -> (1,6) -> (2,6) = 8 moves
    assert spec.cell_distance(station, far) == 8
    assert spec.cell_distance(far, station) == 8
    assert spec.cell_distance(station, station) == 0
    # (0,4) to (0,2): around the obstacle at (0,3): down, left, left, up = 4
    assert spec.cell_distance(4, 2) == 4
    assert spec.first_action(station, far) == RIGHT
    assert spec.first_action(4, 2) == DOWN
    assert spec.first_action(far, station) in (UP, LEFT)
    assert spec.first_action(far, far) == STAY
    # following first actions always reaches the goal in exactly dist moves
    for a in spec.free_cells:
        for b in spec.free_cells:
            here, n = int(a), 0
            while here != b:
                here = int(spec.neighbour[here, spec.first_action(here, b)])
                n += 1
                assert n <= spec.cell_distance(a, b)
            assert n == spec.cell_distance(a, b)


def test_comments_and_surrounding_blank_lines_are_ignored():
    spec = parse_map("# a comment\n\nS.\n#.\n..\n\n# trailing comment\n")
    assert spec.shape == (3, 2)
    assert spec.kinds[1, 0] == OBSTACLE  # '#.' is a row, not a comment


def write(tmp_path, text, name="bad.txt"):
    path = tmp_path / name
    path.write_text(text)
    return path


def assert_map_error(tmp_path, text, line, column, words):
    path = write(tmp_path, text)
    with pytest.raises(MapError) as err:
        load_map(path)
    message = str(err.value)
    assert str(path) in message
    assert f"line {line}, column {column}" in message
    assert words in message


def test_ragged_rows(tmp_path):
    assert_map_error(tmp_path, "S...\n...\n....\n", 2, 4, "ragged row of 3 cells, expected 4")


def test_ragged_rows_longer(tmp_path):
    assert_map_error(tmp_path, "# header\nS..\n....\n", 3, 4, "ragged row of 4 cells, expected 3")


def test_unknown_character(tmp_path):
    assert_map_error(tmp_path, "S..\n.x.\n...\n", 2, 2, "unknown character 'x'")


def test_space_inside_a_row_is_an_unknown_character(tmp_path):
    assert_map_error(tmp_path, "S..\n. .\n", 2, 2, "unknown character ' '")


def test_no_station(tmp_path):
    assert_map_error(tmp_path, "# no S here\n...\n.1.\n", 2, 1, "no charging station")


def test_unreachable_free_cells(tmp_path):
    # (2, 4) is walled off from the station
    assert_map_error(tmp_path, "S..##\n...#.\n...#.\n", 2, 5, "not reachable from the charging station")


def test_empty_file(tmp_path):
    assert_map_error(tmp_path, "", 1, 1, "empty map")


def test_file_of_comments_only_is_empty(tmp_path):
    assert_map_error(tmp_path, "# only\n# comments\n\n", 1, 1, "empty map")


def test_blank_line_inside_the_grid(tmp_path):
    assert_map_error(tmp_path, "S..\n...\n\n...\n", 3, 1, "blank line inside the grid")


def test_map_without_vertices(tmp_path):
    assert_map_error(tmp_path, "S#\n##\n", 1, 1, "no vertex")


def test_missing_file_is_named(tmp_path):
    path = tmp_path / "nowhere.txt"
    with pytest.raises(MapError, match="nowhere.txt: map file not found"):
        load_map(path)


def test_unknown_map_name_lists_the_known_ones():
    with pytest.raises(MapError) as err:
        load_map("Z")
    assert "unknown map 'Z'" in str(err.value)
    assert "known maps: A, B, C, D" in str(err.value)


def test_load_map_from_a_file(tmp_path):
    path = write(tmp_path, NON_SQUARE, name="mine.txt")
    spec = load_map(str(path))
    assert spec.name == "mine"
    assert spec.source == str(path)
    assert spec.shape == (3, 7)


def test_a_shipped_map_loaded_by_path_keeps_its_letter_and_paper_values():
    from patrolsb3.core import make_config
    from patrolsb3.core.maps import MAPS_DIR
    spec = load_map(str(MAPS_DIR / "map_b.txt"))
    assert spec.name == "B"
    assert make_config(spec.name).c_pbb == 0.5


def test_nearest_station_steps_and_first_move():
    spec = parse_map("S.#\n..#\n...\n#.S")
    cells = np.array([[0, 1, 4, 7]])                     # (0,0) station, (0,1), (1,1), (2,1)
    steps, first = spec.nearest_station(cells)
    assert steps.tolist() == [[0, 1, 2, 2]]
    # ties go to the first action in order: (1,1) Up before Left, (2,1) Down before Right
    assert first.tolist() == [[STAY, LEFT, UP, DOWN]]


def test_a_map_over_the_size_limit_is_refused_at_once():
    import time

    from patrolsb3.core.maps import MAX_FREE_CELLS
    side = int(MAX_FREE_CELLS ** 0.5) + 2                      # just over the limit
    text = "\n".join(["S" + "." * (side - 1)] + ["." * side] * (side - 1))
    start = time.perf_counter()
    with pytest.raises(MapError, match=f"the limit is {MAX_FREE_CELLS:,}"):
        parse_map(text, name="huge")
    assert time.perf_counter() - start < 2.0                  # refused before any table is built


@pytest.mark.slow
def test_a_100_by_100_map_loads():
    text = "\n".join(["S" + "." * 99] + ["." * 100] * 99)
    spec = parse_map(text, name="big")
    assert spec.dist.shape == (10_000, 10_000) and spec.cell_distance(0, 9999) == 198
