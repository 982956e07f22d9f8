"""The animation of a run (``--animate FILE.gif``, or ``FILE.mp4`` when ffmpeg is installed).

Each frame shows the bodies as their real shapes at their real sizes (filled circles and
rectangles in 2D, shaded spheres and wireframe boxes in 3D with y up), their whole paths faint
behind them, the static obstacles, a flash (a star that fades over three frames, and a
"collision: step N" caption) where and when each collision happened, and a readout of the
time, the step and the frame.

Thinning: the animation shows ``frames`` moments evenly spaced in time from the first recorded
frame to the last (default: :data:`DEFAULT_FRAMES`, or fewer when the run recorded fewer
frames). Positions between two recorded frames are interpolated linearly, so any frame count
can be asked for, and the GIF has exactly that many frames (each frame's readout differs, so
no two frames are merged). It plays in real time, each frame shown 30 to 200 ms.
"""

from __future__ import annotations

import contextlib
import shutil
import subprocess
from collections.abc import Iterator
from pathlib import Path
from typing import Any, cast

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.colors import to_rgb
from matplotlib.figure import Figure
from matplotlib.patches import Circle as CirclePatch
from matplotlib.patches import Rectangle
from mpl_toolkits.mplot3d.art3d import Poly3DCollection
from numpy.typing import NDArray
from PIL import Image

from ..atomic import atomic_path
from ..errors import InvalidInputError
from ..model import Scenario
from ..shapes import AABB, Circle
from ._data import Array, RunArrays, box_edges, check_path, sphere_mesh, thin_indices
from ._run import DrawnRun
from .static import EVENT_COLOR, _check_size, body_color, draw_obstacles, m3, setup_view

__all__ = ["DEFAULT_ANIMATION_SIZE", "DEFAULT_FRAMES", "render_frames", "save_animation"]

#: Frames in an animation when no count is asked for (fewer when the run recorded fewer).
DEFAULT_FRAMES = 200
#: Width and height (pixels) of an animation when no size is asked for.
DEFAULT_ANIMATION_SIZE = (800, 600)
_DPI = 100
_FLASH_FRAMES = 3.0
_FORM = "FILE.gif (or FILE.mp4 when ffmpeg is installed) in an existing folder"


class _Scene:
    """One figure whose moving parts are updated frame by frame."""

    def __init__(self, run: RunArrays, size: tuple[int, int], count: int) -> None:
        self.run = run
        self.dims = run.record.dims
        self.fig = Figure(figsize=(size[0] / _DPI, size[1] / _DPI), dpi=_DPI)
        self.canvas: Any = cast(Any, FigureCanvasAgg(self.fig))  # its methods are untyped
        self.count = count
        self.shapes = [next(b.shape for b in run.scenario.bodies if b.name == n) for n in run.names]
        if self.dims == 2:
            self.ax: Any = self.fig.add_axes((0.09, 0.09, 0.88, 0.78))
        else:
            self.ax = self.fig.add_axes((0.02, 0.02, 0.96, 0.85), projection="3d")
        self.fig.suptitle(run.record.title, fontsize=13, fontweight="bold", y=0.975)
        self.readout = self.fig.text(0.5, 0.905, "", ha="center", fontsize=10, family="monospace")
        self.caption = self.fig.text(0.5, 0.875, "", ha="center", fontsize=10, color=EVENT_COLOR, fontweight="bold")
        bounds = run.bounds()
        keep = thin_indices(len(run.times), 1000, run.event_frames())
        for i in range(len(run.names)):
            path = run.positions[keep, i, :]
            if self.dims == 2:
                self.ax.plot(path[:, 0], path[:, 1], color=body_color(i), lw=1, alpha=0.35)
            else:
                self.ax.plot(*m3(path), color=body_color(i), lw=1, alpha=0.35)
        draw_obstacles(self.ax, run.scenario, bounds, self.dims)
        events = run.shown_events()
        self.event_times = np.array([e.time for e in events])
        self.event_steps = [e.step for e in events]
        self.event_points = np.array([e.point.as_tuple() for e in events]).reshape(-1, 3)
        if events:
            if self.dims == 2:
                self.ax.scatter(*self.event_points[:, :2].T, marker="x", s=20, color=EVENT_COLOR, alpha=0.4)
            else:
                self.ax.scatter(*m3(self.event_points), marker="x", s=20, color=EVENT_COLOR, alpha=0.4)
        setup_view(self.ax, bounds, self.dims)
        self.patches: list[Any] = []
        self.quads: dict[int, Array] = {}
        if self.dims == 2:
            for i, shape in enumerate(self.shapes):
                color = body_color(i)
                patch: Any
                if isinstance(shape, AABB):
                    half = shape.half_size
                    patch = Rectangle((0, 0), 2 * half.x, 2 * half.y, facecolor=color, edgecolor="k", alpha=0.75)
                else:
                    patch = CirclePatch((0, 0), shape.radius, facecolor=color, edgecolor="k", alpha=0.75)
                self.ax.add_patch(patch)
                self.patches.append(patch)
            self.flash = self.ax.scatter([], [], marker="*", s=[], color=EVENT_COLOR, edgecolor="k", zorder=10)
        else:
            for i, shape in enumerate(self.shapes):
                color = body_color(i)
                if isinstance(shape, AABB):
                    (line,) = self.ax.plot([], [], [], color=color, lw=2)
                    self.patches.append(line)
                elif not isinstance(shape, Circle):
                    quads, colors = _sphere_quads(shape.radius, color)
                    poly = Poly3DCollection(quads, facecolors=colors, edgecolors="none", alpha=0.9)
                    self.ax.add_collection3d(poly, autolim=False)
                    self.patches.append(poly)
                    self.quads[id(poly)] = quads
            self.flash = self.ax.scatter([0.0], [0.0], [0.0], marker="*", s=[0.0], color=EVENT_COLOR,
                                         edgecolor="k", depthshade=False)  # fmt: skip
        # Blitting: everything that does not move is drawn once and copied back each frame.
        for artist in (*self.patches, self.flash, self.readout, self.caption):
            artist.set_animated(True)
        self.canvas.draw()
        self.background = self.canvas.copy_from_bbox(self.fig.bbox)

    def _flash(self, t: float, dt_frame: float) -> tuple[Array, Array, list[int]]:
        """Points, ages (in frames) and steps of the collisions that flash at time ``t``."""
        if len(self.event_times) == 0:
            return np.zeros((0, 3)), np.zeros(0), []
        ages = (t - self.event_times) / dt_frame if dt_frame > 0 else np.where(self.event_times <= t, 0.0, -1.0)
        show = (ages >= 0) & (ages < _FLASH_FRAMES)
        steps = [s for s, on in zip(self.event_steps, show.tolist(), strict=True) if on]
        return self.event_points[show], ages[show], steps

    def update(self, k: int, t: float, step: int, centers: Array, dt_frame: float) -> None:
        """Put the scene at frame ``k`` (time ``t``, nearest step ``step``)."""
        total = self.run.record.steps
        self.readout.set_text(f"t = {t:.3f} s   step {step:>{len(str(total))}d}/{total}   frame {k + 1}/{self.count}")
        points, ages, steps = self._flash(t, dt_frame)
        if steps:
            shown = ", ".join(str(s) for s in steps[:5]) + (" ..." if len(steps) > 5 else "")
            self.caption.set_text(f"collision: step {shown}")
        else:
            self.caption.set_text("")
        sizes = 500.0 * (1.0 + 0.6 * ages)
        alphas = np.clip(1.0 - ages / _FLASH_FRAMES, 0.15, 1.0)
        if self.dims == 2:
            for patch, shape, c in zip(self.patches, self.shapes, centers, strict=True):
                if isinstance(patch, Rectangle):
                    half = shape.half_size  # type: ignore[union-attr]  # a Rectangle is an AABB's
                    patch.set_xy((c[0] - half.x, c[1] - half.y))
                else:
                    patch.set_center((c[0], c[1]))
            self.flash.set_offsets(points[:, :2] if len(points) else np.zeros((0, 2)))
            self.flash.set_sizes(sizes)
            self._fade(alphas)
            return
        for artist, shape, c in zip(self.patches, self.shapes, centers, strict=True):
            if isinstance(shape, AABB):
                half = np.array(shape.half_size.as_tuple())
                edges = box_edges(c - half, c + half)
                path = np.array([row for p, q in edges for row in (p, q, (np.nan,) * 3)])
                artist.set_data_3d(*m3(path))
            else:
                x, y, z = m3(c)
                artist.set_verts(self.quads[id(artist)] + np.array([x, y, z]))
        flash_points = points if len(points) else np.zeros((1, 3))
        self.flash._offsets3d = m3(flash_points)
        self.flash.set_sizes(sizes if len(sizes) else [0.0])
        self._fade(alphas if len(alphas) else np.zeros(1))

    def _fade(self, alphas: Array) -> None:
        """Each flash star's colour with its own opacity (fading with its age)."""
        face = np.tile(np.array([*to_rgb(EVENT_COLOR), 1.0]), (len(alphas), 1))
        edge = np.tile(np.array([0.0, 0.0, 0.0, 1.0]), (len(alphas), 1))
        face[:, 3] = edge[:, 3] = alphas
        self.flash.set_facecolor(face)
        self.flash.set_edgecolor(edge)

    def pixels(self) -> NDArray[np.uint8]:
        """The frame as RGB: the background copied back, then the moving parts drawn on it."""
        self.canvas.restore_region(self.background)
        moving = list(self.patches)
        if self.dims == 3:
            # 3D artists project themselves in Axes3D.draw, which blitting skips: project here,
            # then paint far to near (matplotlib's own order for 3D collections).
            depth = {id(a): a.do_3d_projection() if hasattr(a, "do_3d_projection") else 0.0 for a in moving}
            moving.sort(key=lambda a: depth[id(a)], reverse=True)
            self.flash.do_3d_projection()
        moving.append(self.flash)  # a flash is never hidden behind the bodies that collide
        for artist in moving:
            self.ax.draw_artist(artist)
        self.fig.draw_artist(self.readout)
        self.fig.draw_artist(self.caption)
        return np.asarray(self.canvas.buffer_rgba())[..., :3].copy()


def _sphere_quads(radius: float, color: str, n_u: int = 18, n_v: int = 10) -> tuple[Array, Array]:
    """A sphere about the origin as quads (N, 4, 3) in matplotlib's 3D coordinates (y up), and a
    shaded face colour for each (lit from above and in front)."""
    x, y, z = m3(np.stack(sphere_mesh(np.zeros(3), radius, n_u, n_v), axis=-1))
    grid = np.stack([x, y, z], axis=-1)
    quads = np.stack([grid[:-1, :-1], grid[:-1, 1:], grid[1:, 1:], grid[1:, :-1]], axis=2).reshape(-1, 4, 3)
    normals = quads.mean(axis=1)
    lengths = np.linalg.norm(normals, axis=1, keepdims=True)
    normals /= np.where(lengths > 0.0, lengths, 1.0)  # a degenerate quad keeps a zero normal
    light = np.array([0.1, -0.8, 0.9]) / np.linalg.norm([0.1, -0.8, 0.9])  # toward the default camera, above
    shade = 0.35 + 0.65 * np.clip(normals @ light, 0.0, 1.0)
    colors = np.clip(np.outer(shade, to_rgb(color)), 0.0, 1.0)
    return quads, colors


def render_frames(
    record: DrawnRun, scenario: Scenario, frames: int | None = None, size: tuple[int, int] = DEFAULT_ANIMATION_SIZE
) -> Iterator[NDArray[np.uint8]]:
    """The animation's frames as RGB arrays (height, width, 3), ``frames`` of them (see the
    module's docstring for the default and the thinning)."""
    run = RunArrays.build(record, scenario)
    count = min(DEFAULT_FRAMES, len(run.times)) if frames is None else frames
    times = np.linspace(run.times[0], run.times[-1], count)
    centers = run.interpolate(times)
    steps = np.rint(np.interp(times, run.times, run.steps.astype(np.float64))).astype(int)
    dt_frame = float(times[1] - times[0]) if count > 1 else 0.0
    scene = _Scene(run, size, count)
    for k in range(count):
        scene.update(k, float(times[k]), int(steps[k]), centers[k], dt_frame)
        yield scene.pixels()


def _frame_ms(record: DrawnRun, count: int) -> int:
    span = record.frames[-1].time - record.frames[0].time if record.frames else 0.0
    per_frame = 1000.0 * span / max(count - 1, 1)
    return int(round(min(max(per_frame, 30.0), 200.0) / 10.0) * 10)


def find_ffmpeg() -> str | None:
    """ffmpeg on the PATH, else the one the ``imageio-ffmpeg`` package ships (the ``video``
    extra: ``pip install 'collisionlab[video]'``), else ``None``."""
    found = shutil.which("ffmpeg")
    if found is not None:
        return found
    try:
        import imageio_ffmpeg  # optional; carries its own binary
    except ImportError:
        return None
    try:
        return str(imageio_ffmpeg.get_ffmpeg_exe())
    except RuntimeError:
        return None


def check_animation_path(path: str) -> Path:
    """``path`` if the animation can be written there (``.mp4`` needs ffmpeg), else
    ``InvalidInputError("--animate", ...)``."""
    target = check_path(path, "--animate", (".gif", ".mp4"), _FORM)
    if target.suffix.lower() == ".mp4" and find_ffmpeg() is None:
        raise InvalidInputError("--animate", "FILE.mp4 needs ffmpeg, which is not installed; use FILE.gif", got=path)
    return target


def save_animation(
    record: DrawnRun,
    scenario: Scenario,
    path: str,
    *,
    frames: int | None = None,
    size: tuple[int, int] | None = None,
) -> None:
    """Save the animation of a run (see the module's docstring) to ``path``: ``.gif``, or
    ``.mp4`` when ffmpeg is on the PATH. ``frames``: how many frames (default
    :data:`DEFAULT_FRAMES`, fewer for a short run); ``size`` = (width, height) pixels, default
    :data:`DEFAULT_ANIMATION_SIZE`. Written whole or not at all; a bad path, extension or frame
    count raises ``InvalidInputError("--animate", ...)``."""
    target = check_animation_path(path)
    ffmpeg = find_ffmpeg()
    if frames is not None and (isinstance(frames, bool) or not isinstance(frames, int) or not 1 <= frames <= 10000):
        raise InvalidInputError("--animate", "the frame count must be a whole number from 1 to 10000", got=frames)
    width, height = _check_size(size or DEFAULT_ANIMATION_SIZE, "--animate")
    images = render_frames(record, scenario, frames, (width, height))
    count = min(DEFAULT_FRAMES, len(record.frames)) if frames is None else frames
    ms = _frame_ms(record, count)
    with atomic_path(target) as tmp:
        if target.suffix.lower() == ".gif":
            _write_gif(images, tmp, ms)
        else:
            assert ffmpeg is not None
            _write_mp4(images, tmp, ms, (width, height), ffmpeg)


def _write_gif(images: Iterator[NDArray[np.uint8]], tmp: Path, ms: int) -> None:
    palette = [
        Image.fromarray(rgb).quantize(colors=128, method=Image.Quantize.FASTOCTREE, dither=Image.Dither.NONE)
        for rgb in images
    ]
    palette[0].save(tmp, format="GIF", save_all=True, append_images=palette[1:], duration=ms, loop=0)


def _write_mp4(images: Iterator[NDArray[np.uint8]], tmp: Path, ms: int, size: tuple[int, int], ffmpeg: str) -> None:
    command = [
        ffmpeg, "-y", "-loglevel", "error", "-f", "rawvideo", "-pix_fmt", "rgb24", "-s", f"{size[0]}x{size[1]}",
        "-r", f"{1000.0 / ms:g}", "-i", "-", "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-pix_fmt", "yuv420p",
        "-vcodec", "libx264", "-f", "mp4", str(tmp),
    ]  # fmt: skip
    process = subprocess.Popen(command, stdin=subprocess.PIPE, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    assert process.stdin is not None and process.stderr is not None
    try:
        for rgb in images:
            process.stdin.write(rgb.tobytes())
    except BrokenPipeError:  # ffmpeg stopped early: its message on stderr says why
        pass
    finally:
        with contextlib.suppress(BrokenPipeError):
            process.stdin.close()
        err = process.stderr.read()  # small: ffmpeg runs with -loglevel error
        process.wait()
    if process.returncode != 0:
        last = err.decode(errors="replace").strip().splitlines()[-1:] or ["no message"]
        raise InvalidInputError("--animate", f"ffmpeg could not write the video: {last[0]}")
