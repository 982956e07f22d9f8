"""The interactive page of a run (``--html FILE.html``), drawn with plotly.

One self-contained file (plotly.js is written into it; nothing is fetched when it opens): a 3D
view to rotate and zoom (y up; a 2D run is seen from above, in the x-y plane), with

- each body as its real shape at its real size (a sphere or disc mesh, a box), moving;
- each body's whole path as a line;
- the static obstacles: a line as a long segment, a plane as a square patch around the
  action, a box as a translucent box with its edges;
- every collision as a red cross at its contact point (hover for its step, time and bodies, the
  first 20 labelled "step N"), and a diamond that lights up in the frames where it happens;
- a time slider and Play / Pause buttons.

The run's data is embedded too, for a reader or a script: ``<script type="application/json"
id="collisionlab-run">`` holds the record's JSON form (as ``collisionlab run --format json``
prints it), with ``frames`` thinned as below and ``frames_total`` giving the recorded count.

Thinning: the animation has at most :data:`HTML_FRAMES` moments, evenly chosen among the
recorded frames (the first and last always); paths and the embedded frames keep at most
:data:`~.static.MAX_POINTS` frames, plus the frames on both sides of every collision.
"""

from __future__ import annotations

import html
import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from ..atomic import atomic_path
from ..extras import require
from ..model import Scenario
from ..shapes import AABB, Circle, Line, Plane
from ..tolerances import PICTURE_MIN_SPAN
from ._data import (
    BOX_TRIANGLES,
    Array,
    RunArrays,
    box_corners,
    box_edges,
    check_path,
    line_segment,
    plane_patch,
    sphere_mesh,
    thin_indices,
    uncrowded,
)
from ._run import DrawnRun
from .static import MAX_POINTS

__all__ = ["HTML_FRAMES", "build_figure", "save_html"]

#: At most this many moments in the page's animation.
HTML_FRAMES = 200
#: The id of the ``<script type="application/json">`` element that holds the run's data.
DATA_ELEMENT_ID = "collisionlab-run"
_TAB10 = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf")
_OBSTACLE = "#777777"
_EVENT = "crimson"
_SHADED = {"ambient": 0.55, "diffuse": 0.7, "specular": 0.2}
_FLAT = {"ambient": 0.95, "diffuse": 0.1, "specular": 0.0}  # a disc seen face on: its own colour


def _color(index: int) -> str:
    return _TAB10[index % len(_TAB10)]


def _body_mesh(shape: Any, many: bool) -> tuple[Array, list[int], list[int], list[int]]:
    """Vertices (V, 3) about the origin and triangles (i, j, k) of a body's shape."""
    if isinstance(shape, AABB):
        half = np.array(shape.half_size.as_tuple())
        if shape.dim == 2:
            half[2] = 0.0
        verts = box_corners(-half, half)
        tris = BOX_TRIANGLES
        return verts, [t[0] for t in tris], [t[1] for t in tris], [t[2] for t in tris]
    if isinstance(shape, Circle):
        n = 16 if many else 40
        angles = np.linspace(0.0, 2.0 * math.pi, n, endpoint=False)
        ring = np.stack([shape.radius * np.cos(angles), shape.radius * np.sin(angles), np.zeros(n)], axis=1)
        verts = np.vstack([np.zeros((1, 3)), ring])
        return verts, [0] * n, [1 + q for q in range(n)], [1 + (q + 1) % n for q in range(n)]
    n_u, n_v = (10, 6) if many else (20, 12)
    x, y, z = sphere_mesh(np.zeros(3), shape.radius, n_u, n_v)
    verts = np.stack([x.ravel(), y.ravel(), z.ravel()], axis=1)
    i: list[int] = []
    j: list[int] = []
    k: list[int] = []
    for a in range(n_v - 1):
        for b in range(n_u - 1):
            p, q, r, s = a * n_u + b, a * n_u + b + 1, (a + 1) * n_u + b + 1, (a + 1) * n_u + b
            i += [p, p]
            j += [q, r]
            k += [r, s]
    return verts, i, j, k


def _plotly() -> Any:
    """``plotly.graph_objects``, imported only when a page is drawn (the ``html`` extra)."""
    return require("plotly.graph_objects", "html", "interactive pages (--html)")


def _f32(values: Array) -> Any:
    return np.asarray(values, dtype=np.float32)


def _obstacle_traces(run: RunArrays) -> list[Any]:
    go = _plotly()
    traces: list[Any] = []
    bounds = run.bounds()
    for obstacle in run.scenario.obstacles:
        shape = obstacle.shape
        label = f"{obstacle.name} (static {type(shape).__name__.lower()})"
        if isinstance(shape, Line):
            a, b = line_segment(shape, bounds)
            pts = np.array([a, b])
            traces.append(go.Scatter3d(x=pts[:, 0], y=pts[:, 1], z=pts[:, 2], mode="lines", name=label,
                                       line={"color": _OBSTACLE, "width": 8}, hoverinfo="name"))  # fmt: skip
        elif isinstance(shape, Plane):
            c = plane_patch(shape, bounds)
            traces.append(go.Mesh3d(x=c[:, 0], y=c[:, 1], z=c[:, 2], i=[0, 0], j=[1, 2], k=[2, 3], name=label,
                                    color=_OBSTACLE, opacity=0.35, showlegend=True, hoverinfo="name",
                                    flatshading=True))  # fmt: skip
        else:
            low, high = np.array(shape.min_corner.as_tuple()), np.array(shape.max_corner.as_tuple())
            c = box_corners(low, high)
            tris = BOX_TRIANGLES
            traces.append(go.Mesh3d(x=c[:, 0], y=c[:, 1], z=c[:, 2], i=[t[0] for t in tris], j=[t[1] for t in tris],
                                    k=[t[2] for t in tris], name=label, color=_OBSTACLE, opacity=0.3,
                                    showlegend=True, hoverinfo="name", flatshading=True))  # fmt: skip
            edges = np.array([row for p, q in box_edges(low, high) for row in (p, q, (np.nan,) * 3)])
            traces.append(go.Scatter3d(x=edges[:, 0], y=edges[:, 1], z=edges[:, 2], mode="lines", showlegend=False,
                                       line={"color": "#333333", "width": 3}, hoverinfo="skip",
                                       connectgaps=False))  # fmt: skip
    return traces


def _event_traces(run: RunArrays) -> list[Any]:
    events = run.shown_events()
    if not events:
        return []
    go = _plotly()
    p = np.array([e.point.as_tuple() for e in events])
    hover = [f"collision at step {e.step}<br>t = {e.time:.4g} s<br>{e.bodies[0]} \u2194 {e.bodies[1]}" for e in events]
    keep = uncrowded(p, 0.15 * run.bounds().span)
    labels = [f"step {e.step}" if k else "" for e, k in zip(events, keep, strict=True)]
    return [
        go.Scatter3d(
            x=p[:, 0], y=p[:, 1], z=p[:, 2], mode="markers+text", name=f"collision ({len(run.record.events)})",
            marker={"symbol": "cross", "size": 7, "color": _EVENT}, text=labels, textposition="top center",
            textfont={"color": _EVENT, "size": 11}, hovertext=hover, hoverinfo="text",
        )
    ]  # fmt: skip


def build_figure(record: DrawnRun, scenario: Scenario) -> tuple[Any, RunArrays]:
    """The plotly figure of a run (see the module's docstring) and the arrays it was drawn from."""
    go = _plotly()
    run = RunArrays.build(record, scenario)
    dims = record.dims
    shapes = {b.name: b.shape for b in scenario.bodies}
    many = len(run.names) > 20
    keep = thin_indices(len(run.times), MAX_POINTS, run.event_frames())
    shown = thin_indices(len(run.times), HTML_FRAMES)

    traces: list[Any] = _obstacle_traces(run)
    for b, name in enumerate(run.names):
        path = run.positions[keep, b, :]
        traces.append(go.Scatter3d(x=_f32(path[:, 0]), y=_f32(path[:, 1]), z=_f32(path[:, 2]), mode="lines",
                                   name=f"{name} path", line={"color": _color(b), "width": 4}, opacity=0.6,
                                   hoverinfo="name"))  # fmt: skip
    traces += _event_traces(run)
    first_moving = len(traces)
    meshes = [_body_mesh(shapes[name], many) for name in run.names]
    for b, name in enumerate(run.names):
        verts, i, j, k = meshes[b]
        v = verts + run.positions[shown[0], b]
        traces.append(go.Mesh3d(x=_f32(v[:, 0]), y=_f32(v[:, 1]), z=_f32(v[:, 2]), i=i, j=j, k=k, name=name,
                                color=_color(b), opacity=1.0, showlegend=True, hoverinfo="name",
                                lighting=_FLAT if isinstance(shapes[name], Circle) else _SHADED))  # fmt: skip
    event_times = np.array([e.time for e in run.shown_events()])
    event_points = np.array([e.point.as_tuple() for e in run.shown_events()]).reshape(-1, 3)

    def flash(lo: float, hi: float) -> Any:
        on = (event_times > lo) & (event_times <= hi) if len(event_times) else np.zeros(0, dtype=bool)
        pts = event_points[on]
        return go.Scatter3d(x=pts[:, 0], y=pts[:, 1], z=pts[:, 2], mode="markers", name="collision now",
                            marker={"symbol": "diamond", "size": 14, "color": "gold", "line": {"color": _EVENT,
                                    "width": 3}}, hoverinfo="skip")  # fmt: skip

    t0 = float(run.times[shown[0]])
    traces.append(flash(-math.inf, t0))
    moving = list(range(first_moving, len(traces)))
    frames = []
    previous = -math.inf
    for n, f in enumerate(shown.tolist()):
        data: list[Any] = []
        for b in range(len(run.names)):
            v = meshes[b][0] + run.positions[f, b]
            data.append(go.Mesh3d(x=_f32(v[:, 0]), y=_f32(v[:, 1]), z=_f32(v[:, 2])))
        t = float(run.times[f])
        data.append(flash(previous, t))
        previous = t
        frames.append(go.Frame(data=data, traces=moving, name=str(n)))

    ms = int(min(max(1000.0 * (float(run.times[-1]) - t0) / max(len(shown) - 1, 1), 30.0), 200.0))
    steps = [
        {"method": "animate", "label": f"{float(run.times[f]):.3f}",
         "args": [[str(n)], {"mode": "immediate", "frame": {"duration": 0, "redraw": True},
                             "transition": {"duration": 0}}]}
        for n, f in enumerate(shown.tolist())
    ]  # fmt: skip
    bounds = run.bounds()
    span = bounds.span
    if dims == 2:
        low, high = bounds.low.copy(), bounds.high.copy()
        low[2], high[2] = -0.05 * span, 0.05 * span
        camera = {"up": {"x": 0, "y": 1, "z": 0}, "eye": {"x": 0.0, "y": 0.0, "z": 1.4},
                  "projection": {"type": "orthographic"}}  # fmt: skip
    else:
        cube = bounds.cube()
        low, high = cube.low, cube.high
        camera = {"up": {"x": 0, "y": 1, "z": 0}, "eye": {"x": 1.2, "y": 0.9, "z": 1.5}}
    ratio = (high - low) / max(float(np.max(high - low)), PICTURE_MIN_SPAN)
    subtitle = (f"{record.mode} mode, dt = {record.dt:g} s, {record.steps} steps, e = {record.restitution:g}, "
                f"{len(record.events)} collision{'s' if len(record.events) != 1 else ''}")  # fmt: skip
    layout = go.Layout(
        title={"text": f"{html.escape(record.title)}<br><sup>{subtitle}</sup>", "x": 0.5},
        scene={
            "xaxis": {"title": {"text": "x (m)"}, "range": [low[0], high[0]]},
            "yaxis": {"title": {"text": "y (m)"}, "range": [low[1], high[1]]},
            "zaxis": {
                "title": {"text": "z (m)" if dims == 3 else ""},
                "range": [low[2], high[2]],
                "showticklabels": dims == 3,
            },
            "aspectmode": "manual",
            "aspectratio": {"x": ratio[0], "y": ratio[1], "z": ratio[2]},
            "camera": camera,
        },
        legend={"x": 0.01, "y": 0.98, "bgcolor": "rgba(255,255,255,0.7)"},
        margin={"l": 0, "r": 0, "t": 70, "b": 0},
        updatemenus=[
            {
                "type": "buttons",
                "direction": "left",
                "x": 0.02,
                "y": 0.02,
                "xanchor": "left",
                "yanchor": "bottom",
                "pad": {"r": 10, "t": 10},
                "showactive": False,
                "buttons": [
                    {
                        "label": "\u25b6 Play",
                        "method": "animate",
                        "args": [
                            None,
                            {
                                "mode": "immediate",
                                "fromcurrent": True,
                                "frame": {"duration": ms, "redraw": True},
                                "transition": {"duration": 0},
                            },
                        ],
                    },
                    {
                        "label": "\u275a\u275a Pause",
                        "method": "animate",
                        "args": [
                            [None],
                            {
                                "mode": "immediate",
                                "frame": {"duration": 0, "redraw": False},
                                "transition": {"duration": 0},
                            },
                        ],
                    },
                ],
            }
        ],
        sliders=[
            {
                "active": 0,
                "x": 0.2,
                "len": 0.78,
                "y": 0.02,
                "yanchor": "bottom",
                "pad": {"t": 10, "b": 10},
                "currentvalue": {"prefix": "t = ", "suffix": " s", "font": {"size": 14, "color": "#222"}},
                "font": {"color": "rgba(0,0,0,0)"},
                "ticklen": 0,
                "minorticklen": 0,
                "steps": steps,
            }
        ],
    )
    return go.Figure(data=traces, layout=layout, frames=frames), run


def _embedded_data(run: RunArrays) -> str:
    data = run.record.to_dict()
    keep = thin_indices(len(run.times), MAX_POINTS, run.event_frames()).tolist()
    data["frames_total"] = len(data["frames"])
    data["frames"] = [data["frames"][i] for i in keep]
    text = json.dumps(data, separators=(",", ":"), allow_nan=False)
    # Inside <script>, "</" could end the element early; "<\/" is the same JSON string.
    return text.replace("</", "<\\/")


def check_html_path(path: str) -> Path:
    """``path`` if the page can be written there, else ``InvalidInputError("--html", ...)``;
    ``MissingExtraError`` when plotly (the ``html`` extra) is not installed, so a run asked for a
    page fails before it starts."""
    _plotly()
    return check_path(path, "--html", (".html", ".htm"), "FILE.html in an existing folder")


def save_html(record: DrawnRun, scenario: Scenario, path: str) -> None:
    """Save the interactive page of a run (see the module's docstring) to ``path`` (``.html``).
    Written whole or not at all; a bad path raises ``InvalidInputError("--html", ...)``."""
    target = check_html_path(path)
    fig, run = build_figure(record, scenario)
    page = fig.to_html(
        include_plotlyjs=True, full_html=True, auto_play=False, div_id="collisionlab-plot",
        default_width="100%", default_height="100vh",
        config={"displaylogo": False, "responsive": True, "scrollZoom": True},
    )  # fmt: skip
    title = f"<title>{html.escape(record.title)} \u2014 collisionlab</title>"
    page = page.replace("<head>", f"<head>{title}", 1)
    block = f'<script type="application/json" id="{DATA_ELEMENT_ID}">{_embedded_data(run)}</script>'
    head, tail = page.rsplit("</body>", 1)
    page = f"{head}{block}\n</body>{tail}"
    with atomic_path(target) as tmp:
        tmp.write_text(page, encoding="utf-8")
