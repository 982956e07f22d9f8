"""Pictures of a run: a static plot, an animation and an interactive 3D page.

Every picture is drawn from the :class:`~collisionlab.record.RunRecord` of a run (the same
record the JSON output comes from) and the :class:`~collisionlab.model.Scenario` that made it
(for masses, shapes and obstacles): nothing is simulated again.

- :func:`save_plot` (``--plot FILE.png``): trajectories, obstacles and collisions, with energy
  and momentum over time; matplotlib.
- :func:`save_animation` (``--animate FILE.gif``, ``.mp4`` when ffmpeg is present): the bodies
  moving as their real shapes, a flash at each collision, a time readout; matplotlib.
- :func:`save_html` (``--html FILE.html``): one self-contained page with a 3D view to rotate and
  zoom, a time slider and a play button; plotly.

Long runs are thinned, never simulated coarser: the plot draws at most 2,000 frames per curve
(plus the frames on both sides of each collision), the animation and the page show 200
evenly spaced moments by default. Each file is written whole or not at all, and a bad path or
extension raises :class:`~collisionlab.errors.InvalidInputError` naming the option.
"""

from __future__ import annotations

from .animation import check_animation_path, save_animation
from .html import check_html_path, save_html
from .static import check_plot_path, save_plot

__all__ = [
    "check_animation_path",
    "check_html_path",
    "check_paths",
    "check_plot_path",
    "save_animation",
    "save_html",
    "save_plot",
]


def check_paths(plot: str | None = None, animate: str | None = None, html: str | None = None) -> None:
    """Check the picture paths before a run, so a bad one fails at once, not after the run."""
    for path, check in ((plot, check_plot_path), (animate, check_animation_path), (html, check_html_path)):
        if path is not None:
            check(path)
