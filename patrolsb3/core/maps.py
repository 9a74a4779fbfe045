"""Text maps: parsing, validation and the static tables the simulator needs.

Legend (one character per cell)::

    #      obstacle
    .      vertex of priority 0
    1 - 9  vertex of priority 1 .. 9
    S      charging station (not a vertex: it has no idleness)

Lines that start with ``"# "`` (a hash followed by a space) are comments; a map row never
contains a space, so a row of walls such as ``"####"`` is never mistaken for a comment.
Blank lines before and after the grid are ignored; a blank line inside the grid is an
error. The grid is 4-connected; every free cell must be reachable from the station.

Cells are numbered row-major: ``cell = row * W + col``. Vertices (free cells that are not
a station) are numbered ``0 .. V-1`` in the same row-major order.
"""
from __future__ import annotations

import dataclasses
import functools
from pathlib import Path

import numpy as np

OBSTACLE, VERTEX, STATION = 0, 1, 2
LEGEND = {"#": OBSTACLE, ".": VERTEX, "S": STATION, **{str(d): VERTEX for d in range(1, 10)}}

# Actions, in the paper's order. MOVES[a] is the (d_row, d_col) of action a.
ACTION_NAMES = ("Up", "Down", "Left", "Right", "Stay")
UP, DOWN, LEFT, RIGHT, STAY = range(5)
MOVES = np.array([[-1, 0], [1, 0], [0, -1], [0, 1], [0, 0]], dtype=np.int64)  # (5, 2)

def _shipped_maps_dir() -> Path:
    """The shipped maps: ``patrolsb3/maps/`` in an installed wheel, else the checkout's
    top-level ``maps/`` (setup.cfg maps one onto the other)."""
    package = Path(__file__).resolve().parent.parent
    installed = package / "maps"
    return installed if installed.is_dir() else package.parent / "maps"


MAPS_DIR = _shipped_maps_dir()

MAX_FREE_CELLS = 10_000
"""Largest map accepted, in free cells (a 100 x 100 open map: ~0.5 GB of distance tables, about
10-20 s to build on one core); a larger one is refused at once."""


class MapError(ValueError):
    """A map file or map name that cannot be used; the message names the file, line and column."""


@dataclasses.dataclass(frozen=True, eq=False)
class MapSpec:
    """A parsed, validated map with every static table the simulator uses.

    Attributes:
        name: short name ("A") or the file stem.
        source: path of the file it came from (or "<string>").
        kinds: (H, W) int8, OBSTACLE / VERTEX / STATION per cell.
        priority: (H, W) int8, 0..9 on vertices, 0 elsewhere.
        stations: (n_stations,) int64 cell indices of the charging stations.
        vertex_cells: (V,) int64 cell index of each vertex.
        vertex_of_cell: (H*W,) int64 vertex index of a cell, -1 for obstacles and stations.
        rate: (V,) float64 idleness growth per step, 1 + priority.
        neighbour: (H*W, 5) int64 cell reached by each action; the cell itself when the
            move leaves the grid or enters an obstacle.
        move_ok: (H*W, 5) bool, the static part of the action mask (in bounds, no obstacle).
        free_cells: (F,) int64 cell indices of all free cells (vertices and stations).
        free_index: (H*W,) int64 index into free_cells, -1 for obstacles.
        dist: (F, F) int32 shortest-path length (moves) between free cells.
        next_action: (F, F) int8 first action of a shortest path from one free cell to
            another (STAY on the diagonal).
    """

    name: str
    source: str
    kinds: np.ndarray
    priority: np.ndarray
    stations: np.ndarray
    vertex_cells: np.ndarray
    vertex_of_cell: np.ndarray
    rate: np.ndarray
    neighbour: np.ndarray
    move_ok: np.ndarray
    free_cells: np.ndarray
    free_index: np.ndarray
    dist: np.ndarray
    next_action: np.ndarray

    @property
    def shape(self) -> tuple[int, int]:
        """(H, W) of the grid."""
        return self.kinds.shape

    @property
    def n_vertices(self) -> int:
        """Number of vertices V (free cells that are not stations)."""
        return len(self.vertex_cells)

    @property
    def station(self) -> int:
        """Cell index of the first charging station."""
        return int(self.stations[0])

    @functools.cached_property
    def steps_home(self) -> np.ndarray:
        """(H*W,) int32 shortest-path steps from each free cell to its nearest station (0 on a
        station and on obstacles)."""
        steps = np.zeros(self.kinds.size, dtype=np.int32)
        steps[self.free_cells] = self.nearest_station(self.free_cells)[0]
        return steps

    @functools.cached_property
    def home_move(self) -> np.ndarray:
        """(H*W,) int8 first move of a shortest path from each free cell to its nearest station
        (STAY on a station and on obstacles): :meth:`nearest_station` as a table."""
        moves = np.full(self.kinds.size, STAY, dtype=np.int8)
        moves[self.free_cells] = self.nearest_station(self.free_cells)[1]
        return moves

    def cell_distance(self, a, b) -> np.ndarray:
        """Shortest-path length between cell indices ``a`` and ``b`` (broadcasting arrays)."""
        return self.dist[self.free_index[a], self.free_index[b]]

    def first_action(self, a, b) -> np.ndarray:
        """First action of a shortest path from cell ``a`` to cell ``b`` (broadcasting arrays)."""
        return self.next_action[self.free_index[a], self.free_index[b]]

    def nearest_station(self, cells) -> tuple[np.ndarray, np.ndarray]:
        """Shortest-path steps to the nearest station and the first move of such a path.

        Args:
            cells: cell indices of free cells, any shape S.

        Returns:
            steps (S) int32 (0 on a station) and first move (S) int8 (STAY on a station).
        """
        here = self.free_index[np.asarray(cells)]                               # (S)
        station_free = self.free_index[self.stations]                            # (n_stations,)
        to_station = self.dist[here[..., None], station_free]                    # (S, n_stations)
        nearest = np.argmin(to_station, axis=-1)                                 # (S)
        steps = np.take_along_axis(to_station, nearest[..., None], axis=-1)[..., 0]
        return steps, self.next_action[here, station_free[nearest]]

    def rowcol(self, cells) -> tuple[np.ndarray, np.ndarray]:
        """Row and column arrays of cell indices."""
        return np.divmod(np.asarray(cells), self.shape[1])

    def to_text(self) -> str:
        """The map in the file legend, one row per line (what ``patrolsb3 maps`` prints)."""
        rows = []
        for r in range(self.shape[0]):
            row = ""
            for c in range(self.shape[1]):
                k = self.kinds[r, c]
                if k == OBSTACLE:
                    row += "#"
                elif k == STATION:
                    row += "S"
                else:
                    p = int(self.priority[r, c])
                    row += str(p) if p else "."
            rows.append(row)
        return "\n".join(rows)


def parse_map(text: str, name: str = "custom", source: str = "<string>") -> MapSpec:
    """Parse map text into a validated :class:`MapSpec`.

    Args:
        text: the map in the legend of this module.
        name: name to give the map.
        source: file name used in error messages.

    Returns:
        The parsed map.

    Raises:
        MapError: ragged rows, an unknown character, no station, free cells unreachable from
            the station, or no grid at all; the message names the file, line and column.
    """
    rows: list[tuple[int, str]] = []  # (1-based line number, row text)
    trailing_blank = None
    for lineno, raw in enumerate(text.splitlines(), start=1):
        line = raw.rstrip("\r\n").rstrip()
        if line.startswith("# "):
            continue
        if not line:
            if rows and trailing_blank is None:
                trailing_blank = lineno
            continue
        if trailing_blank is not None:
            raise MapError(f"{source}: line {trailing_blank}, column 1: blank line inside the grid")
        rows.append((lineno, line))
    if not rows:
        raise MapError(f"{source}: line 1, column 1: empty map (no grid rows)")
    width = len(rows[0][1])
    for lineno, line in rows:
        if len(line) != width:
            col = min(len(line), width) + 1
            raise MapError(
                f"{source}: line {lineno}, column {col}: ragged row of {len(line)} cells, "
                f"expected {width} like line {rows[0][0]}")
        for col, ch in enumerate(line, start=1):
            if ch not in LEGEND:
                raise MapError(
                    f"{source}: line {lineno}, column {col}: unknown character {ch!r} "
                    f"(legend: # obstacle, . vertex, 1-9 priority vertex, S station)")
    height = len(rows)
    kinds = np.array([[LEGEND[ch] for ch in line] for _, line in rows], dtype=np.int8)  # (H, W)
    priority = np.array([[int(ch) if ch.isdigit() else 0 for ch in line] for _, line in rows],
                        dtype=np.int8)  # (H, W)
    stations = np.flatnonzero(kinds.ravel() == STATION).astype(np.int64)
    if len(stations) == 0:
        raise MapError(f"{source}: line {rows[0][0]}, column 1: no charging station 'S' in the map")

    n_cells = height * width
    flat = kinds.ravel()
    r, c = np.divmod(np.arange(n_cells), width)
    nr = r[:, None] + MOVES[None, :, 0]
    nc = c[:, None] + MOVES[None, :, 1]
    inside = (nr >= 0) & (nr < height) & (nc >= 0) & (nc < width)
    target = np.where(inside, nr * width + nc, np.arange(n_cells)[:, None])
    move_ok = inside & (flat[target] != OBSTACLE) & (flat[:, None] != OBSTACLE)
    move_ok[:, 4] = flat != OBSTACLE
    neighbour = np.where(move_ok, target, np.arange(n_cells)[:, None]).astype(np.int64)  # (H*W, 5)

    free_cells = np.flatnonzero(flat != OBSTACLE).astype(np.int64)
    free_index = np.full(n_cells, -1, dtype=np.int64)
    free_index[free_cells] = np.arange(len(free_cells))
    if len(free_cells) > MAX_FREE_CELLS:
        raise MapError(f"{source}: {len(free_cells):,} free cells; the limit is {MAX_FREE_CELLS:,} (the "
                       f"all-pairs distance tables take 5 bytes per pair of free cells: "
                       f"{5 * len(free_cells) ** 2 / 1e9:.1f} GB here)")
    dist, next_action = _all_pairs_bfs(free_cells, free_index, neighbour, move_ok)

    unreachable = dist[free_index[stations[0]]] < 0
    if unreachable.any():
        cell = int(free_cells[np.argmax(unreachable)])
        rr, cc = divmod(cell, width)
        raise MapError(f"{source}: line {rows[rr][0]}, column {cc + 1}: free cell not reachable "
                       f"from the charging station (free cells must be connected)")

    vertex_cells = np.flatnonzero(flat == VERTEX).astype(np.int64)
    if len(vertex_cells) == 0:
        raise MapError(f"{source}: line {rows[0][0]}, column 1: the map has no vertex to patrol")
    vertex_of_cell = np.full(n_cells, -1, dtype=np.int64)
    vertex_of_cell[vertex_cells] = np.arange(len(vertex_cells))
    rate = 1.0 + priority.ravel()[vertex_cells].astype(np.float64)
    for arr in (kinds, priority, stations, vertex_cells, vertex_of_cell, rate, neighbour, move_ok,
                free_cells, free_index, dist, next_action):
        arr.setflags(write=False)
    return MapSpec(name=name, source=source, kinds=kinds, priority=priority, stations=stations,
                   vertex_cells=vertex_cells, vertex_of_cell=vertex_of_cell, rate=rate,
                   neighbour=neighbour, move_ok=move_ok, free_cells=free_cells,
                   free_index=free_index, dist=dist, next_action=next_action)


def _all_pairs_bfs(free_cells, free_index, neighbour, move_ok):
    """Shortest paths between all free cells (scipy's breadth-first search over the grid graph, in
    chunks of sources). Returns dist (F, F) int32 (-1 unreachable) and the first action of a
    shortest path next_action (F, F) int8 (ties broken by action order)."""
    from scipy.sparse import csr_matrix
    from scipy.sparse.csgraph import shortest_path
    n_free = len(free_cells)
    src, dst = [], []
    for a in range(4):
        ok = move_ok[free_cells, a]
        src.append(np.flatnonzero(ok))
        dst.append(free_index[neighbour[free_cells[ok], a]])
    src, dst = np.concatenate(src), np.concatenate(dst)
    graph = csr_matrix((np.ones(len(src), dtype=np.int8), (src, dst)), shape=(n_free, n_free))
    dist = np.empty((n_free, n_free), dtype=np.int32)
    chunk = max(1, 2_000_000 // max(n_free, 1))                # ~16 MB of float64 per chunk
    for start in range(0, n_free, chunk):
        rows = shortest_path(graph, method="D", directed=True, unweighted=True,
                             indices=np.arange(start, min(start + chunk, n_free)))
        dist[start:start + len(rows)] = np.where(np.isinf(rows), -1, rows).astype(np.int32)
    # first action from a toward b = an action whose neighbour n has dist[n, b] == dist[a, b] - 1
    next_action = np.full((n_free, n_free), 4, dtype=np.int8)
    nb_free = free_index[neighbour[free_cells]]  # (F, 5) free index of each neighbour
    big = np.iinfo(np.int32).max
    best = np.full((n_free, n_free), big, dtype=np.int32)
    for a in range(3, -1, -1):  # later actions first so that the lowest action index wins ties
        ok = move_ok[free_cells, a]
        d_nb = np.where(ok[:, None], dist[nb_free[:, a]], big)
        d_nb[d_nb < 0] = big
        better = d_nb <= best
        np.copyto(best, d_nb, where=better)
        next_action[better & (d_nb < dist)] = a
        del d_nb, better
    np.fill_diagonal(next_action, 4)
    next_action[dist < 0] = 4
    return dist, next_action


def source_label(spec: MapSpec) -> str:
    """Where a map came from, for config files and output: ``maps/map_<x>.txt`` for a shipped
    map (no path of this machine), else the file it was loaded from with every link and relative
    part resolved (so that it still names the file from another working directory), or the
    source as given when it is not a file (``<string>``)."""
    source = Path(str(spec.source))
    if source.is_file() and source.resolve().parent == MAPS_DIR.resolve():
        return f"maps/{source.name}"
    return str(source.resolve()) if source.is_file() else str(spec.source)


def is_shipped(spec: MapSpec) -> bool:
    """True for a map of the package's ``maps/`` folder."""
    return source_label(spec).startswith("maps/")


def available_maps() -> list[str]:
    """Names of the maps shipped in ``maps/`` ("A", "B", ...)."""
    return sorted(p.stem[4:].upper() for p in MAPS_DIR.glob("map_*.txt"))


def load_map(name_or_path) -> MapSpec:
    """Load a shipped map by name ("A" .. "D") or any map file by path.

    Args:
        name_or_path: a shipped map name (case-insensitive), a path to a ``.txt`` file, or a
            :class:`MapSpec` (returned unchanged).

    Returns:
        The parsed map.

    Raises:
        MapError: unknown map name (the message lists the known ones), missing file, or a
            malformed file.
    """
    if isinstance(name_or_path, MapSpec):
        return name_or_path
    text_name = str(name_or_path)
    path = Path(text_name)
    if path.suffix == ".txt" or path.exists() or "/" in text_name:
        if not path.is_file():
            raise MapError(f"{text_name}: map file not found")
        shipped = path.resolve().parent == MAPS_DIR and path.stem.startswith("map_")
        name = path.stem[4:].upper() if shipped else path.stem
        return parse_map(_read_text(path), name=name, source=str(path))
    candidate = MAPS_DIR / f"map_{text_name.lower()}.txt"
    if not candidate.is_file():
        raise MapError(f"unknown map {text_name!r}; known maps: {', '.join(available_maps())} "
                       f"(or give a path to a .txt map file)")
    return parse_map(_read_text(candidate), name=text_name.upper(), source=str(candidate))


def _read_text(path: Path) -> str:
    """A map file's text; a binary or non-UTF-8 file is a MapError naming the file, line and column."""
    data = path.read_bytes()
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data[:exc.start].count(b"\n") + 1
        column = exc.start - (data.rfind(b"\n", 0, exc.start) + 1) + 1
        raise MapError(f"{path}:{line}:{column}: not a text map (byte 0x{data[exc.start]:02x} is not "
                       f"UTF-8)") from None
