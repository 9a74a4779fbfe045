"""Pictures of the patrolling world: RGB frames, GIF animations, map drawings, idleness heat maps.

Frames are drawn Minigrid-style: the static part of a map (tiles, obstacles, station,
priority digits) is drawn once per map and tile size and cached; each frame only tints the
vertices by their normalised idleness (the same f(i) = 1 - exp(-i / c_norm) the agents
observe, in HEAT_LEVELS bands so that consecutive frames differ in few pixels and GIFs stay
small) and draws the agents on top with pillow. Frame layout, for a map of H x W cells and
``tile`` pixels per cell::

    rows 0 .. H*tile-1          the grid
    rows H*tile .. +FOOTER-1    a status line: step, active agents, mean and max idleness

Agents are discs in their slot's colour with the symbol they show this step written inside
(nothing when silent), a battery bar under them (green above b_l, red below), several agents
on the station are drawn side by side, a swapping agent is drawn hollow, a failed one as a
grey cross where it fell. This module only reads the simulator state; no rule lives here.
"""
from __future__ import annotations

import functools
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw, ImageFont

from .core.maps import OBSTACLE, STATION, MapSpec
from .core.reward import normalised_idleness
from .core.state import ACTIVE, FAILED, SWAPPING

TILE = 32
"""Default tile size in pixels."""
FOOTER = 18
"""Height in pixels of the status line under the grid."""
HEAT_LEVELS = 12
"""Number of colour bands of the idleness heat map (f in [0, 1])."""

EMPTY_RGB = (245, 245, 245)        # a vertex never idle (f = 0)
OBSTACLE_RGB = (60, 60, 60)
STATION_RGB = (70, 130, 200)
GRID_LINE_RGB = (200, 200, 200)
TEXT_RGB = (20, 20, 20)
FOOTER_RGB = (255, 255, 255)
PRIORITY_RGB = (150, 90, 200)     # tint of priority vertices in map pictures
BATTERY_OK_RGB = (40, 170, 60)
BATTERY_LOW_RGB = (220, 40, 40)
AGENT_RGB = [(31, 119, 180), (255, 127, 14), (44, 160, 44), (148, 103, 189), (227, 119, 194),
             (140, 86, 75), (23, 190, 207), (188, 189, 34), (127, 127, 127), (214, 39, 40)]
"""Colour of each slot (matplotlib's tab10 without red, which the heat map uses)."""


@functools.lru_cache(maxsize=8)
def _font(size: int) -> ImageFont.ImageFont:
    return ImageFont.load_default(size=size)


@functools.lru_cache(maxsize=1)
def _heat_lut() -> np.ndarray:
    """(HEAT_LEVELS, 3) uint8 colours from EMPTY_RGB (f = 0) through yellow and orange to red
    (f = 1)."""
    from matplotlib.colors import LinearSegmentedColormap
    cmap = LinearSegmentedColormap.from_list(
        "idleness", [np.array(EMPTY_RGB) / 255, (1.0, 0.93, 0.55), (0.99, 0.6, 0.25), (0.8, 0.1, 0.1)])
    return (cmap(np.linspace(0.0, 1.0, HEAT_LEVELS))[:, :3] * 255).round().astype(np.uint8)


@functools.lru_cache(maxsize=16)
def _static_layers(spec: MapSpec, tile: int):
    """Cached drawing of everything that never changes on a map.

    Returns:
        background (H*tile, W*tile, 3) uint8 with obstacles, station and grid lines;
        vertex_pixels (H*tile, W*tile) bool, the pixels tinted by idleness;
        vertex_index (H*tile, W*tile) int64, the vertex under each pixel (-1 elsewhere);
        ink (H*tile, W*tile) bool, the pixels of the priority digits and the station's 'S'
        (painted after the tint so they stay readable).
    """
    H, W = spec.shape
    kinds = np.kron(spec.kinds, np.ones((tile, tile), dtype=np.int8))                 # (H*t, W*t)
    background = np.empty(kinds.shape + (3,), dtype=np.uint8)
    background[:] = EMPTY_RGB
    background[kinds == OBSTACLE] = OBSTACLE_RGB
    background[kinds == STATION] = STATION_RGB
    inner = np.zeros((tile, tile), dtype=bool)                                         # (t, t)
    inner[1:, 1:] = True
    inner_all = np.tile(inner, (H, W))
    background[~inner_all] = GRID_LINE_RGB
    vertex_pixels = (kinds != OBSTACLE) & (kinds != STATION) & inner_all
    cell_of_pixel = np.kron(np.arange(H * W).reshape(H, W), np.ones((tile, tile), dtype=np.int64))
    vertex_index = np.where(vertex_pixels, spec.vertex_of_cell[cell_of_pixel], -1)

    ink_img = Image.new("L", (W * tile, H * tile), 0)
    draw = ImageDraw.Draw(ink_img)
    small, big = _font(max(tile // 3, 8)), _font(max(tile // 2, 9))
    for r in range(H):
        for c in range(W):
            if spec.kinds[r, c] == STATION:
                draw.text(((c + 0.5) * tile, (r + 0.5) * tile), "S", fill=255, font=big, anchor="mm")
            elif spec.priority[r, c] > 0:
                draw.text((c * tile + 3, r * tile + 2), str(int(spec.priority[r, c])), fill=255,
                          font=small)
    ink = np.asarray(ink_img) > 127
    for arr in (background, vertex_pixels, vertex_index, ink):
        arr.setflags(write=False)
    return background, vertex_pixels, vertex_index, ink


def map_image(spec: MapSpec, tile: int = TILE) -> np.ndarray:
    """The static picture of a map (no agents, idleness 0).

    Returns:
        (H*tile, W*tile, 3) uint8.
    """
    background, _, _, ink = _static_layers(spec, tile)
    image = background.copy()
    _paint_ink(image, spec, ink, tile)
    return image


def _paint_ink(image: np.ndarray, spec: MapSpec, ink: np.ndarray, tile: int) -> None:
    """Paint the cached text pixels: white on the station, dark elsewhere (in place)."""
    station_px = np.kron(spec.kinds == STATION, np.ones((tile, tile), dtype=bool))   # (H*t, W*t)
    image[ink & station_px] = 255
    image[ink & ~station_px] = TEXT_RGB


def render_frame(spec: MapSpec, cfg, state, env_index: int = 0, tile: int = TILE) -> np.ndarray:
    """One RGB frame of episode ``env_index`` of a batched simulator state.

    Args:
        spec: the map.
        cfg: environment parameters (b_max, b_low, c_norm).
        state: the batched :class:`~patrolsb3.core.state.State`.
        env_index: which episode of the batch to draw.
        tile: pixels per cell.

    Returns:
        (H*tile + FOOTER, W*tile, 3) uint8.
    """
    if not 0 <= env_index < state.n_envs:
        raise ValueError(f"env_index={env_index} outside the batch of {state.n_envs} episodes")
    H, W = spec.shape
    background, vertex_pixels, vertex_index, ink = _static_layers(spec, tile)
    frame = np.empty((H * tile + FOOTER, W * tile, 3), dtype=np.uint8)
    frame[H * tile:] = FOOTER_RGB
    grid = frame[:H * tile]
    grid[:] = background
    f = normalised_idleness(state.idle[env_index], state.visited[env_index], cfg.c_norm)  # (V,)
    band = np.clip((f * HEAT_LEVELS).astype(np.int64), 0, HEAT_LEVELS - 1)                # (V,)
    heat = _heat_lut()[band]                                                                # (V, 3)
    grid[vertex_pixels] = heat[vertex_index[vertex_pixels]]
    _paint_ink(grid, spec, ink, tile)

    image = Image.fromarray(frame)
    draw = ImageDraw.Draw(image)
    _draw_agents(draw, spec, cfg, state, env_index, tile)
    active = int((state.status[env_index] == ACTIVE).sum())
    idle = state.idle[env_index]
    draw.text((4, H * tile + FOOTER // 2), f"t={int(state.t[env_index])}  active={active}  "
              f"idle mean={idle.mean():.0f} max={idle.max():.0f}", fill=TEXT_RGB,
              font=_font(max(FOOTER - 6, 8)), anchor="lm")
    return np.asarray(image)


def _draw_agents(draw: ImageDraw.ImageDraw, spec: MapSpec, cfg, state, e: int, tile: int) -> None:
    """Discs, message symbols, battery bars and failure crosses of episode ``e``."""
    W = spec.shape[1]
    status, pos = state.status[e], state.pos[e]                                   # (A,)
    shown = np.flatnonzero((status == ACTIVE) | (status == SWAPPING) | (status == FAILED))
    by_cell: dict[int, list[int]] = {}
    for k in shown:
        by_cell.setdefault(int(pos[k]), []).append(int(k))
    font = _font(max(tile // 3, 8))
    for cell, slots in by_cell.items():
        r, c = divmod(cell, W)
        n = len(slots)
        size = tile / max(1, int(np.ceil(np.sqrt(n))))      # side of each agent's sub-square
        per_row = int(round(tile / size))
        for j, k in enumerate(slots):
            x0 = c * tile + (j % per_row) * size
            y0 = r * tile + (j // per_row) * size
            colour = AGENT_RGB[k % len(AGENT_RGB)]
            pad = size * 0.15
            box = (x0 + pad, y0 + pad, x0 + size - pad, y0 + size - 2.2 * pad)
            if status[k] == FAILED:
                draw.line((box[0], box[1], box[2], box[3]), fill=(110, 110, 110), width=2)
                draw.line((box[0], box[3], box[2], box[1]), fill=(110, 110, 110), width=2)
                continue
            if status[k] == SWAPPING:
                draw.ellipse(box, outline=colour, width=2)
                continue
            draw.ellipse(box, fill=colour, outline=(0, 0, 0))
            symbol = int(state.messages[e, k])
            if symbol > 0 and size >= 16:
                draw.text(((box[0] + box[2]) / 2, (box[1] + box[3]) / 2), str(symbol),
                          fill=(255, 255, 255), font=font, anchor="mm")
            level = float(np.clip(state.battery[e, k] / cfg.b_max, 0.0, 1.0))
            bar_y = y0 + size - 1.8 * pad
            bar_h = max(2.0, pad)
            draw.rectangle((box[0], bar_y, box[2], bar_y + bar_h), fill=(255, 255, 255),
                           outline=(0, 0, 0))
            bar_colour = BATTERY_OK_RGB if state.battery[e, k] > cfg.b_low else BATTERY_LOW_RGB
            draw.rectangle((box[0], bar_y, box[0] + (box[2] - box[0]) * level, bar_y + bar_h),
                           fill=bar_colour)


def show_frame(frame: np.ndarray, viewer=None):
    """Show a frame in a matplotlib window (the env's ``render_mode='human'``).

    Args:
        frame: (H_px, W_px, 3) uint8.
        viewer: what the previous call returned, or None to open a window.

    Returns:
        The viewer to pass to the next call.
    """
    import matplotlib.pyplot as plt
    if viewer is None:
        fig, ax = plt.subplots()
        ax.set_axis_off()
        viewer = (fig, ax.imshow(frame))
        plt.show(block=False)
    else:
        viewer[1].set_data(frame)
    viewer[0].canvas.draw_idle()
    plt.pause(0.001)
    return viewer


def save_gif(frames, path, fps: float = 10) -> Path:
    """Write frames as a looping GIF animation, taking them one at a time: ``frames`` may be a
    generator, so a long episode is never held as RGB arrays (Pillow keeps each frame as a
    one-byte-per-pixel palette image until the file is written).

    Args:
        frames: a non-empty iterable of (H_px, W_px, 3) uint8 arrays of one size.
        path: output file.
        fps: frames per second.

    Returns:
        The path written.
    """
    if fps <= 0:
        raise ValueError(f"fps must be > 0, got {fps}")
    images = (Image.fromarray(np.asarray(f, dtype=np.uint8)) for f in frames)
    first = next(images, None)
    if first is None:
        raise ValueError("save_gif needs at least one frame")
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    first.save(path, save_all=True, append_images=images, duration=int(round(1000 / fps)),
               loop=0, optimize=True, disposal=1)
    return path


def draw_map_png(spec: MapSpec, path, tile: int = TILE) -> Path:
    """A picture of a map with its legend and figures (size, vertices, station).

    Args:
        spec: the map.
        path: output PNG file.
        tile: pixels per cell of the drawing.

    Returns:
        The path written.
    """
    from matplotlib.figure import Figure
    from matplotlib.patches import Patch

    H, W = spec.shape
    image = _static_layers(spec, tile)[0].copy()                 # no ink: labels come below
    tint = np.kron(spec.priority, np.ones((tile, tile), dtype=np.int8))            # (H*t, W*t)
    tinted = (tint > 0) & (image == EMPTY_RGB).all(axis=-1)
    strength = (0.25 + 0.05 * tint[tinted])[:, None]
    image[tinted] = ((1 - strength) * np.array(EMPTY_RGB) + strength * np.array(PRIORITY_RGB)).astype(np.uint8)
    fig = Figure(figsize=(1.6 + W * 0.38, 0.9 + H * 0.38), dpi=100)   # no pyplot: no window
    ax = fig.subplots()
    ax.imshow(image, interpolation="nearest", extent=(-0.5, W - 0.5, H - 0.5, -0.5))
    for r, c in zip(*np.nonzero(spec.priority)):
        ax.text(c, r, str(int(spec.priority[r, c])), ha="center", va="center", fontsize=10,
                fontweight="bold", color=np.array(TEXT_RGB) / 255)
    for cell in spec.stations:
        r, c = divmod(int(cell), W)
        ax.text(c, r, "S", ha="center", va="center", fontsize=10, fontweight="bold", color="white")
    ax.set_xticks([]), ax.set_yticks([])
    n_priority = int((spec.priority > 0).sum())
    ax.set_title(f"Map {spec.name}: {H} x {W}, {spec.n_vertices} vertices, "
                 f"{n_priority} priority", fontsize=10)
    handles = [Patch(facecolor=np.array(OBSTACLE_RGB) / 255, label="obstacle"),
               Patch(facecolor=np.array(EMPTY_RGB) / 255, edgecolor="grey", label="vertex"),
               Patch(facecolor=np.array(STATION_RGB) / 255, label="S station"),
               Patch(facecolor=np.array(PRIORITY_RGB) / 255, alpha=0.5,
                     label="1-9 priority p (idleness rate 1+p)")]
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8,
              frameon=False)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, bbox_inches="tight")
    return path


def plot_idleness_heatmap(spec: MapSpec, mean_idleness_per_vertex, path, title: str | None = None) -> Path:
    """A heat map of a per-vertex figure (for example the time-averaged idleness).

    Args:
        spec: the map.
        mean_idleness_per_vertex: (V,) values in vertex order.
        path: output PNG file.
        title: figure title.

    Returns:
        The path written.
    """
    from matplotlib.figure import Figure

    values = np.asarray(mean_idleness_per_vertex, dtype=np.float64)
    if values.shape != (spec.n_vertices,):
        raise ValueError(f"expected one value per vertex, shape ({spec.n_vertices},), "
                         f"got {values.shape}")
    H, W = spec.shape
    grid = np.full(H * W, np.nan)                                                  # (H*W,)
    grid[spec.vertex_cells] = values
    fig = Figure(figsize=(1.8 + W * 0.4, 0.8 + H * 0.4), dpi=100)
    ax = fig.subplots()
    ax.imshow(np.where(spec.kinds == OBSTACLE, 1.0, np.nan), cmap="Greys", vmin=0, vmax=1.4,
              interpolation="nearest")
    im = ax.imshow(np.ma.masked_invalid(grid.reshape(H, W)), cmap="YlOrRd", interpolation="nearest")
    for cell in spec.stations:
        r, c = divmod(int(cell), W)
        ax.text(c, r, "S", ha="center", va="center", fontsize=9, color=np.array(STATION_RGB) / 255,
                fontweight="bold")
    fig.colorbar(im, ax=ax, label="idleness (steps, rate-weighted)")
    ax.set_xticks([]), ax.set_yticks([])
    ax.set_title(title or f"Map {spec.name}: mean idleness per vertex", fontsize=10)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, bbox_inches="tight")
    return path
