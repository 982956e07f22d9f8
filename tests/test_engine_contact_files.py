"""The contact stepper's files (contact_kernels.py, the loop, and one file per concept it calls):
what each names for the compiler is its own function, and the loop file gives a world and its
stepper the numbers they read, in both forms, as the files of its phases own them."""

from __future__ import annotations

import types

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
