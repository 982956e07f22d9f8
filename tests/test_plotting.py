"""Pictures of a run, tested by content: the PNG's size and pixels, the GIF's frame count, the
HTML's embedded data; bad paths; atomic writes; no second simulation; long runs thinned."""

from __future__ import annotations

import dataclasses
import json
import re
import time
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from PIL import Image

from collisionlab import Plane, Sphere, Vector3D, plotting
from collisionlab.demos import LAB_DEMOS, load_demo
from collisionlab.errors import InvalidInputError, OutOfRangeError
from collisionlab.model import Body, Obstacle, Scenario, Settings
from collisionlab.plotting import animation as animation_module
from collisionlab.plotting import html as html_module
from collisionlab.plotting import save_animation, save_html, save_plot
from collisionlab.plotting._data import RunArrays, thin_indices
from collisionlab.plotting.static import MAX_POINTS, draw_figure
from collisionlab.record import RunRecord
from collisionlab.world import World, simulate
from tests.schema_check import check

SMALL = (480, 360)


@pytest.fixture(scope="module")
def runs() -> dict[str, tuple[RunRecord, Scenario]]:
    out = {}
    for name in LAB_DEMOS:
        scenario = load_demo(name)
        out[name] = (World(scenario).run(), scenario)
    return out


@pytest.fixture(scope="module")
def pngs(runs: dict[str, tuple[RunRecord, Scenario]], tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    folder = tmp_path_factory.mktemp("png")
    out = {}
    for name, (record, scenario) in runs.items():
        out[name] = folder / f"{name}.png"
        save_plot(record, scenario, str(out[name]), size=SMALL)
    return out


def pixels(path: Path) -> np.ndarray:
    return np.asarray(Image.open(path).convert("RGB"), dtype=np.float64)


# --- the static plot ---------------------------------------------------------------------------
@pytest.mark.parametrize("name", LAB_DEMOS)
def test_plot_has_the_size_asked_and_is_not_blank(pngs: dict[str, Path], name: str) -> None:
    image = Image.open(pngs[name])
    assert image.format == "PNG"
    assert image.size == SMALL
    rgb = pixels(pngs[name])
    assert rgb.std() > 20
    assert len(np.unique(rgb.reshape(-1, 3), axis=0)) > 200


@pytest.mark.parametrize("a, b", list(zip(LAB_DEMOS, LAB_DEMOS[1:] + LAB_DEMOS[:1], strict=True)))
def test_plots_of_different_scenarios_differ(pngs: dict[str, Path], a: str, b: str) -> None:
    difference = np.abs(pixels(pngs[a]) - pixels(pngs[b]))
    assert (difference.max(axis=2) > 30).mean() > 0.02  # more than 2 % of the pixels clearly differ


def test_plot_default_size(runs: dict[str, tuple[RunRecord, Scenario]], tmp_path: Path) -> None:
    record, scenario = runs["spheres"]
    save_plot(record, scenario, str(tmp_path / "p.png"))
    assert Image.open(tmp_path / "p.png").size == (1200, 800)


def test_plot_draws_what_it_should(runs: dict[str, tuple[RunRecord, Scenario]]) -> None:
    record, scenario = runs["circle-line"]
    fig = draw_figure(record, scenario)
    scene, energy, momentum = fig.axes
    texts = [t.get_text() for t in scene.texts]
    assert f"step {record.events[0].step}" in texts
    assert scene.get_xlabel() == "x (m)" and scene.get_ylabel() == "y (m)"
    assert scene.get_aspect() == 1.0
    legend = [t.get_text() for t in scene.get_legend().get_texts()]
    assert "circle path" in legend and any(s.startswith("line (static line)") for s in legend)
    assert energy.get_ylabel() == "energy (J)" and energy.get_xlabel() == "time (s)"
    assert "momentum" in momentum.get_ylabel()
    assert fig.texts and record.title == fig.get_suptitle()
    # The kinetic energy curve is the record's: 0.5 m |v|^2 at the first and last frame.
    ke = next(ln for ln in energy.get_lines() if ln.get_label() == "kinetic").get_ydata()
    v0 = record.frames[0].bodies[0].velocity
    assert ke[0] == pytest.approx(0.5 * v0.length_squared())
    assert ke[-1] == pytest.approx(record.ledger.kinetic_end)


def test_3d_plot_uses_3d_axes(runs: dict[str, tuple[RunRecord, Scenario]]) -> None:
    record, scenario = runs["sphere-plane"]
    fig = draw_figure(record, scenario)
    assert fig.axes[0].name == "3d"
    assert fig.axes[0].get_zlabel() == "y (m)"


def test_momentum_matches_the_ledger(runs: dict[str, tuple[RunRecord, Scenario]]) -> None:
    for record, scenario in runs.values():
        arrays = RunArrays.build(record, scenario)
        assert arrays.momentum()[0] == pytest.approx(list(record.ledger.momentum_start))
        assert arrays.momentum()[-1] == pytest.approx(list(record.ledger.momentum_end))
        total = arrays.kinetic_energy() + arrays.potential_energy()
        assert total[-1] == pytest.approx(record.ledger.energy_end)


# --- the animation -----------------------------------------------------------------------------
@pytest.mark.parametrize("name", LAB_DEMOS)
def test_gif_has_the_frames_asked(runs: dict[str, tuple[RunRecord, Scenario]], tmp_path: Path, name: str) -> None:
    record, scenario = runs[name]
    path = tmp_path / f"{name}.gif"
    save_animation(record, scenario, str(path), frames=12, size=(320, 240))
    image = Image.open(path)
    assert image.format == "GIF"
    assert image.n_frames == 12
    assert image.size == (320, 240)
    first = np.asarray(image.convert("RGB"), dtype=np.float64)
    image.seek(11)
    last = np.asarray(image.convert("RGB"), dtype=np.float64)
    assert first.std() > 10
    assert np.abs(first - last).max(axis=2).mean() > 0.5  # the bodies moved


def test_gif_default_frames_follow_the_run(tmp_path: Path) -> None:
    scenario = load_demo("spheres").with_settings(steps=30)
    record = World(scenario).run()
    save_animation(record, scenario, str(tmp_path / "a.gif"), size=(200, 150))
    assert Image.open(tmp_path / "a.gif").n_frames == len(record.frames) == 31


def test_gif_flashes_at_the_collision(runs: dict[str, tuple[RunRecord, Scenario]]) -> None:
    record, scenario = runs["circle-line"]  # the impact is at step 76 of 150
    frames = list(animation_module.render_frames(record, scenario, frames=151, size=(320, 240)))
    red = [int(((f[..., 0] > 180) & (f[..., 1] < 60) & (f[..., 2] < 90)).sum()) for f in frames]
    assert max(red[74:80]) > 5 * max(max(red[:60]), 1)


def test_mp4_needs_ffmpeg(runs: dict[str, tuple[RunRecord, Scenario]], tmp_path: Path,
                          monkeypatch: pytest.MonkeyPatch) -> None:  # fmt: skip
    monkeypatch.setattr(animation_module, "find_ffmpeg", lambda: None)
    record, scenario = runs["spheres"]
    with pytest.raises(InvalidInputError, match="ffmpeg") as info:
        save_animation(record, scenario, str(tmp_path / "a.mp4"))
    assert info.value.field == "--animate"
    assert not (tmp_path / "a.mp4").exists()


@pytest.mark.skipif(animation_module.find_ffmpeg() is None, reason="no ffmpeg (install the 'video' extra)")
def test_mp4_with_ffmpeg(runs: dict[str, tuple[RunRecord, Scenario]], tmp_path: Path) -> None:
    record, scenario = runs["spheres"]
    save_animation(record, scenario, str(tmp_path / "a.mp4"), frames=10, size=(320, 240))
    assert (tmp_path / "a.mp4").read_bytes()[4:8] == b"ftyp"


# --- the page ----------------------------------------------------------------------------------
def embedded(page: str) -> dict[str, object]:
    match = re.search(r'<script type="application/json" id="collisionlab-run">(.*?)</script>', page, re.S)
    assert match
    data: dict[str, object] = check("run", json.loads(match.group(1)))
    return data


@pytest.mark.parametrize("name", LAB_DEMOS)
def test_html_holds_the_run(runs: dict[str, tuple[RunRecord, Scenario]], tmp_path: Path, name: str) -> None:
    record, scenario = runs[name]
    path = tmp_path / f"{name}.html"
    save_html(record, scenario, str(path))
    page = path.read_text(encoding="utf-8")
    assert "<script src=" not in page  # self-contained: plotly.js is inside
    assert "Plotly.newPlot" in page and len(page) > 1_000_000
    for body in scenario.bodies:
        assert body.name in page
    data = embedded(page)
    assert data["title"] == record.title
    frames = data["frames"]
    assert isinstance(frames, list)
    assert frames[-1]["bodies"][0]["position"] == list(record.frames[-1].bodies[0].position)
    assert data["frames_total"] == len(record.frames)
    assert data["events"][0]["step"] == record.events[0].step  # type: ignore[index]
    fig, _ = html_module.build_figure(record, scenario)
    assert len(fig.frames) == min(html_module.HTML_FRAMES, len(record.frames))
    assert fig.layout.sliders and fig.layout.updatemenus


# --- paths, atomic writes, one simulation ------------------------------------------------------
@pytest.mark.parametrize(
    "save, option, bad",
    [
        (save_plot, "--plot", "out.txt"),
        (save_animation, "--animate", "out.txt"),
        (save_animation, "--animate", "out.png"),
        (save_html, "--html", "out.png"),
        (save_plot, "--plot", "no-such-folder/out.png"),
        (save_html, "--html", "no-such-folder/out.html"),
    ],
)
def test_bad_paths_name_the_option(runs: dict[str, tuple[RunRecord, Scenario]], tmp_path: Path,
                                   save: object, option: str, bad: str) -> None:  # fmt: skip
    record, scenario = runs["spheres"]
    with pytest.raises(InvalidInputError) as info:
        save(record, scenario, str(tmp_path / bad))  # type: ignore[operator]
    assert info.value.field == option
    assert "expected" in str(info.value)
    assert list(tmp_path.iterdir()) == []


def test_bad_frame_count(runs: dict[str, tuple[RunRecord, Scenario]], tmp_path: Path) -> None:
    record, scenario = runs["spheres"]
    for frames in (0, -3, 2.5):
        with pytest.raises(InvalidInputError, match="frame count"):
            save_animation(record, scenario, str(tmp_path / "a.gif"), frames=frames)  # type: ignore[arg-type]


def test_a_failed_write_leaves_the_old_file(runs: dict[str, tuple[RunRecord, Scenario]], tmp_path: Path,
                                            monkeypatch: pytest.MonkeyPatch) -> None:  # fmt: skip
    record, scenario = runs["spheres"]
    target = tmp_path / "p.png"
    target.write_bytes(b"old")

    def fail(*args: object, **kwargs: object) -> None:
        Path(args[1] if len(args) > 1 else kwargs["fname"]).write_bytes(b"half")  # type: ignore[arg-type]
        raise OSError("disk full")

    from matplotlib.figure import Figure

    monkeypatch.setattr(Figure, "savefig", fail)
    with pytest.raises(OSError, match="disk full"):
        save_plot(record, scenario, str(target), size=SMALL)
    assert target.read_bytes() == b"old"
    assert [p.name for p in tmp_path.iterdir()] == ["p.png"]


def test_pictures_simulate_nothing_and_print_nothing(runs: dict[str, tuple[RunRecord, Scenario]], tmp_path: Path,
                                                     monkeypatch: pytest.MonkeyPatch,
                                                     capfd: pytest.CaptureFixture[str]) -> None:  # fmt: skip
    def no(*args: object, **kwargs: object) -> None:
        raise AssertionError("a picture must not simulate")

    monkeypatch.setattr(World, "step", no)
    monkeypatch.setattr(World, "run", no)
    record, scenario = runs["circle-line"]
    plotting.save_plot(record, scenario, str(tmp_path / "p.png"), size=SMALL)
    plotting.save_animation(record, scenario, str(tmp_path / "a.gif"), frames=3, size=(200, 150))
    plotting.save_html(record, scenario, str(tmp_path / "p.html"))
    out, err = capfd.readouterr()
    assert out == "" and err == ""


def test_a_record_and_a_foreign_scenario_are_refused(runs: dict[str, tuple[RunRecord, Scenario]],
                                                     tmp_path: Path) -> None:  # fmt: skip
    record, _ = runs["spheres"]
    with pytest.raises(InvalidInputError, match="not in the scenario"):
        save_plot(record, load_demo("circle-line"), str(tmp_path / "p.png"))


# --- long runs ---------------------------------------------------------------------------------
def test_thinning_keeps_ends_and_collisions() -> None:
    kept = thin_indices(10_001, 2000, keep=[5003, 5004]).tolist()
    assert kept[0] == 0 and kept[-1] == 10_000 and 5003 in kept and 5004 in kept
    assert len(kept) <= 2002


def test_a_10000_step_run_is_thinned_and_quick(tmp_path: Path, record_property: pytest.RecordProperty) -> None:
    scenario = load_demo("bouncing-ball").with_settings(steps=10_000, dt=0.001)
    record = World(scenario).run()
    assert len(record.frames) == 10_001
    timings = {}
    start = time.perf_counter()
    save_plot(record, scenario, str(tmp_path / "long.png"))
    timings["png"] = time.perf_counter() - start
    start = time.perf_counter()
    save_html(record, scenario, str(tmp_path / "long.html"))
    timings["html"] = time.perf_counter() - start
    start = time.perf_counter()
    save_animation(record, scenario, str(tmp_path / "long.gif"))
    timings["gif"] = time.perf_counter() - start
    for key, seconds in timings.items():
        record_property(f"seconds_{key}", round(seconds, 2))  # reported, never a limit
    assert Image.open(tmp_path / "long.gif").n_frames == animation_module.DEFAULT_FRAMES
    fig = draw_figure(record, scenario)
    longest = max(len(line.get_xdata()) for ax in fig.axes for line in ax.get_lines())
    assert longest <= MAX_POINTS + 2 * len(record.events)
    data = embedded((tmp_path / "long.html").read_text(encoding="utf-8"))
    assert len(data["frames"]) <= MAX_POINTS + 2 * len(record.events)  # type: ignore[arg-type]


def test_labels_skip_crowded_collisions() -> None:
    # Points 0, 0.5 and 3 along x with crowd 1: the second sits within 1 of the first, no label.
    from collisionlab.plotting._data import uncrowded

    points = np.array([[0.0, 0, 0], [0.5, 0, 0], [3.0, 0, 0]])
    assert uncrowded(points, 1.0) == [True, False, True]
    assert uncrowded(points, 1.0, limit=1) == [True, False, False]


# --- issue 11: extreme coordinates give a clear line, never a leaked warning ---------------------
def _far_run() -> tuple[Any, Scenario]:
    # From x = 1e9 m (the largest coordinate a scenario gives) at 1e9 m/s for 900 s: 9.01e11 m,
    # near the 1e12 m a run may reach.
    ball = Body("ball", Sphere((1e9, 0, 0), 1.0), velocity=(1e9, 1e8, 0))
    scenario = Scenario(Settings(dt=1.0, steps=900), (ball,), (Obstacle("floor", Plane((0, -1, 0), (0, 1, 0))),))
    return simulate(scenario), scenario


@pytest.mark.parametrize("name", ["far.png", "far.gif", "far.html"])
def test_pictures_of_the_farthest_run_draw_without_a_warning(tmp_path: Path, name: str) -> None:
    record, scenario = _far_run()
    save = {".png": plotting.save_plot, ".gif": plotting.save_animation, ".html": plotting.save_html}
    target = tmp_path / name
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a numpy or matplotlib warning fails the test
        save[target.suffix](record, scenario, str(target))
    assert target.stat().st_size > 0
    if name.endswith(".html"):  # the run's data in the page is strict JSON: no Infinity, no NaN
        page = target.read_text()
        embedded = page.split('id="collisionlab-run">', 1)[1].split("</script>", 1)[0]
        json.loads(embedded, parse_constant=lambda word: pytest.fail(f"{word} in the page's data"))


@pytest.mark.parametrize("name", ["far.png", "far.gif", "far.html"])
def test_pictures_of_coordinates_beyond_the_range_are_refused_in_one_line(tmp_path: Path, name: str) -> None:
    # x = 5e307 (a record made by hand: no run reaches it) used to leak numpy warnings and end
    # in "ValueError: arange"; the page wrote inf above 3.4e38.
    record, scenario = _far_run()
    far = dataclasses.replace(record.frames[-1].bodies[0], position=Vector3D(5e307, 0, 0))
    record.frames[-1] = dataclasses.replace(record.frames[-1], bodies=(far,))
    save = {".png": plotting.save_plot, ".gif": plotting.save_animation, ".html": plotting.save_html}
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(OutOfRangeError, match="beyond the 1e\\+12 m a picture draws"):
            save[Path(name).suffix](record, scenario, str(tmp_path / name))
    assert list(tmp_path.iterdir()) == []
