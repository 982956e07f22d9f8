"""Times of impact of the event-driven engine, against arithmetic done by hand."""

from __future__ import annotations

import importlib
import math

import numpy as np
import pytest

from collisionlab.edmd.cells import nearest_image
from collisionlab.edmd.predict import ceiling_time, contact_time, floor_time, leave_time, wall_time


@pytest.mark.parametrize(
    ("args", "expected"),
    [
        # dr = (3,0,0), dv = (-1,0,0), sigma = 2: the gap 1 closes at speed 1 -> t = 1
        ((3.0, 0.0, 0.0, -1.0, 0.0, 0.0, 4.0), 1.0),
        # dr = (3,1,0), dv = (-1,0,0): |(3 - t, 1)| = 2 when (3 - t)^2 = 3, t = 3 - sqrt 3
        ((3.0, 1.0, 0.0, -1.0, 0.0, 0.0, 4.0), 3.0 - math.sqrt(3.0)),
        # moving apart: never
        ((3.0, 0.0, 0.0, 1.0, 0.0, 0.0, 4.0), math.inf),
        # passing by at distance 2.5 > 2: never
        ((3.0, 2.5, 0.0, -1.0, 0.0, 0.0, 4.0), math.inf),
        # already overlapping by rounding and approaching: now
        ((1.9999999, 0.0, 0.0, -1.0, 0.0, 0.0, 4.0), 0.0),
        # 3D: dr = (0,0,5), dv = (0,0,-2): gap 3 at speed 2
        ((0.0, 0.0, 5.0, 0.0, 0.0, -2.0, 4.0), 1.5),
    ],
)
def test_contact_time(args: tuple[float, ...], expected: float) -> None:
    assert contact_time(*args) == pytest.approx(expected, rel=1e-15, abs=0.0)


def test_contact_time_is_the_first_touch() -> None:
    # The oracle is the geometry, not the formula: at the time returned the centres are sigma = 2
    # apart, and at every earlier time sampled they are farther; "never" means no sample comes
    # within sigma over a long span.
    rng = np.random.default_rng(7)
    times = np.linspace(0.0, 50.0, 20_001)
    for row in rng.uniform(-3.0, 3.0, size=(500, 6)):
        d, w = row[:3], row[3:]
        if float(d @ d) <= 4.0:
            continue  # touching or overlapping: tested above
        t = contact_time(*(float(x) for x in row), 4.0)
        gaps = np.linalg.norm(d + np.outer(times, w), axis=1)
        if t == math.inf:
            assert gaps.min() > 2.0 - 1e-3 or float(d @ w) >= 0.0
        else:
            assert float(np.linalg.norm(d + t * w)) == pytest.approx(2.0, rel=1e-12)
            assert np.all(gaps[times < t * (1 - 1e-9)] > 2.0 - 1e-9)


def test_contact_time_just_apart_has_no_cancellation() -> None:
    # gap 1e-12 at speed 1: t = 1e-12 to full precision (the textbook root would lose 4 digits)
    t = contact_time(2.0 + 1e-12, 0.0, 0.0, -1.0, 0.0, 0.0, 4.0)
    assert t == pytest.approx(1e-12, rel=1e-3)


@pytest.mark.parametrize(
    ("x", "v", "expected"),
    [(5.0, 2.0, 2.0), (5.0, -1.0, 4.0), (5.0, 0.0, math.inf), (0.5, -1.0, 0.0)],  # walls at 1 and 9
)
def test_wall_time(x: float, v: float, expected: float) -> None:
    assert wall_time(x, v, 1.0, 9.0) == expected


def test_floor_time_under_gravity() -> None:
    # dropped from 3 onto 1 with g = 2: 2 = t^2 -> sqrt 2
    assert floor_time(3.0, 0.0, 2.0, 1.0) == pytest.approx(math.sqrt(2.0), rel=1e-15)
    # thrown up at 4 from the floor with g = 2: back after 2 v / g = 4
    assert floor_time(1.0, 4.0, 2.0, 1.0) == pytest.approx(4.0, rel=1e-15)
    # falling at 1 from height 1 above the floor, g = 2: t + t^2 = 1, t = (sqrt 5 - 1) / 2
    assert floor_time(2.0, -1.0, 2.0, 1.0) == pytest.approx((math.sqrt(5.0) - 1.0) / 2.0, rel=1e-15)
    # a hair below the floor, rising too slowly to clear it: met at the apex, v / g
    assert floor_time(1.0 - 1e-12, 1e-9, 1.0, 1.0) == pytest.approx(1e-9, rel=1e-12)


def test_ceiling_time_under_gravity() -> None:
    # rising at 4 from 0 with g = 2 to 3: 4t - t^2 = 3, t = 1 (the first root)
    assert ceiling_time(0.0, 4.0, 2.0, 3.0) == pytest.approx(1.0, rel=1e-15)
    # apex at v^2 / 2g = 4 < 5: never
    assert ceiling_time(0.0, 4.0, 2.0, 5.0) == math.inf
    assert ceiling_time(0.0, -1.0, 2.0, 3.0) == math.inf


def test_leave_time() -> None:
    # from the centre at speed 2 to the skin 0.5: 0.25
    assert leave_time(0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 0.5) == 0.25
    # 0.3 out, moving back in at 1: |0.3 - t| = 0.5 at t = 0.8
    assert leave_time(0.3, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, 0.5) == pytest.approx(0.8, rel=1e-15)
    assert leave_time(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.5) == math.inf
    # under gravity the bound |v| t + g t^2 / 2 = 0.5 with v = 0, g = 1: t = 1, never later than the truth
    assert leave_time(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.5) == pytest.approx(1.0, rel=1e-15)


def test_nearest_image() -> None:
    assert (nearest_image(9.0, 10.0), nearest_image(-9.0, 10.0), nearest_image(4.0, 10.0)) == (-1.0, 1.0, 4.0)


@pytest.mark.parametrize("stem", ["calendar", "cells", "compile", "loop", "predict", "structure"])
def test_a_kernel_compiled_on_its_own_is_the_event_driven_packages_own(stem: str) -> None:
    # numba keys a function's cache entry on its source file: the engine's geometry kernels,
    # compiled on their own here too, shared the engine's entries, and a process that loaded
    # them from there looked for the engine's compiled module (ModuleNotFoundError). So a
    # kernel of another file is only ever inlined here.
    from numba.core.registry import CPUDispatcher

    module = importlib.import_module(f"collisionlab.edmd.{stem}")
    for name, value in vars(module).items():
        if isinstance(value, CPUDispatcher) and value.targetoptions.get("inline") != "always":
            assert value.py_func.__module__.startswith("collisionlab.edmd."), name
