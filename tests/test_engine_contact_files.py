"""The contact stepper's files (contact_kernels.py, the loop, and one file per concept it calls):
what each names for the compiler is its own function, and the loop file gives a world and its
stepper the numbers they read, in both forms, as the files of its phases own them."""

from __future__ import annotations

import math
import types
from typing import Any

import numpy as np
import pytest

from collisionlab.engine import (
    compiled,
    contact_candidates,
    contact_flight,
    contact_impacts,
    contact_islands,
    contact_kernels,
    contact_memory,
    contact_push_apart,
    contact_qp,
    contact_solver,
    contact_time_of_impact,
    pair_separation,
    pair_time_of_impact,
)

#: The contact stepper's files: the loop and one file per concept it calls.
CONTACT_FILES = (
    contact_flight,
    contact_time_of_impact,
    contact_candidates,
    contact_impacts,
    contact_memory,
    contact_qp,
    contact_solver,
    contact_push_apart,
    contact_islands,
    contact_kernels,
)


@pytest.mark.parametrize("module", CONTACT_FILES)
def test_every_helper_named_for_the_compiler_is_a_function_of_its_module(module: types.ModuleType) -> None:
    inline = set(getattr(module, "INLINE", ()))
    no_refcount = set(getattr(module, "NO_REFCOUNT", ()))
    assert not inline & no_refcount  # an inlined body is compiled as its caller is
    for name in inline | no_refcount:  # a misspelt name would silently compile the default way
        assert isinstance(getattr(module, name, None), types.FunctionType), name


def test_the_loop_file_gives_the_world_the_numbers_it_reads() -> None:
    """A world reads the cap of impacts per step, its stepper the pairs' row width and the
    counters, from the stepper's entry, contact_kernels, in both forms (loading the compiled copy
    compiles nothing)."""
    for kernels in (contact_kernels, compiled.contact_kernels()):
        assert kernels.MAX_IMPACTS_PER_STEP == contact_impacts.MAX_IMPACTS_PER_STEP
        assert kernels.PAIR_COLUMNS == contact_solver.PAIR_COLUMNS == 9
        assert kernels.STATUS_SIZE == contact_qp.STATUS_SIZE == 6


def _dropped_ball(height: float, radius: float, g: float) -> tuple[Any, ...]:
    """A ball of ``radius`` at rest with its centre ``height`` above the plane y = 0, under ``g``
    along -y: the arrays the time of impact reads (body 0; the plane is static 0, pair ``a = -1``)."""
    kind = np.array([pair_separation.BALL_3D], np.int64)
    pos = np.array([[0.0, height, 0.0]])
    vel = np.zeros((1, 3))
    acc = np.array([[0.0, -g, 0.0]])
    tau = np.zeros(1)
    ext = np.full((1, 3), radius)
    s_kind = np.array([pair_separation.STATIC_BOUNDARY], np.int64)
    s_a = np.zeros((1, 3))
    s_b = np.array([[0.0, 1.0, 0.0]])
    return kind, pos, vel, acc, tau, ext, s_kind, s_a, s_b


@pytest.mark.parametrize("height, g", [(3.0, 9.81), (1.5, 2.0), (101.0, 0.5)])
def test_every_stepper_s_time_of_impact_is_the_fall_s_closed_form_and_the_restitution_rule(
    height: float, g: float
) -> None:
    # A ball (r 1) dropped from rest onto a plane lands when it has fallen h - r: t = sqrt(2 (h - r) / g),
    # at v = sqrt(2 g (h - r)) (e.g. h 3, g 9.81: t = sqrt(4 / 9.81) = 0.6386 s at 6.264 m/s). The
    # exact stepper's call (every approach an impact, rest speed -inf) and the contact stepper's
    # (its own gap, an approach slower than its rest speed a resting contact) run one function.
    arrays = _dropped_ball(height, 1.0, g)
    fall = math.sqrt(2.0 * (height - 1.0) / g)
    landing = math.sqrt(2.0 * g * (height - 1.0))
    exact = pair_time_of_impact._time_of_impact(*arrays, -1, 0, 0.0, 2.0 * fall, 0.0, -math.inf, -math.inf)
    assert exact == pytest.approx(fall, rel=1e-12)
    contact = contact_time_of_impact._pair_toi(*arrays, -1, 0, 0.0, 2.0 * fall, 0.5 * landing)
    assert contact == pytest.approx(fall, rel=1e-9)  # within TOI_GAP of the plane: a hair sooner
    assert contact <= fall
    assert contact_time_of_impact._pair_toi(*arrays, -1, 0, 0.0, 2.0 * fall, 1.5 * landing) == math.inf
    slow = pair_time_of_impact._time_of_impact(*arrays, -1, 0, 0.0, 2.0 * fall, 0.0, -math.inf, 1.5 * landing)
    assert slow == math.inf
    assert pair_time_of_impact._time_of_impact(*arrays, -1, 0, 0.0, 0.5 * fall, 0.0, -math.inf, -math.inf) == math.inf
