"""How the engine's compiled kernels are kept (engine/compiled.py): which cached code is dropped
after an edit, and what the world is told is cached. numba itself is not run here."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from collisionlab import numba_cache
from collisionlab.engine import compiled


def test_an_edited_kernel_file_drops_its_own_cached_code_too(monkeypatch: pytest.MonkeyPatch) -> None:
    """numba would compile a changed file's kernels again anyway; its stale files must go first,
    or is_cached would say a kernel is cached while its first call compiles it."""
    dropped: dict[str, list[str]] = {}

    def spy(package: Path, stems: list[str], sources: list[Path]) -> None:
        dropped[stems[0]] = [source.name for source in sources]

    monkeypatch.setattr(compiled, "forget_stale", spy)
    compiled._forget_stale()
    euler = [
        "non_literal",
        "pair_separation",
        "broad_phase_grid",
        "broad_phase_pairs",
        "contact_order",
        "touching_memory",
        "event_rows",
        "euler_impulses",
        "euler_push_apart",
        "euler_clamps",
        "euler_integrate",
    ]
    exact = [
        "exact_flight",
        "pair_time_of_impact",
        "exact_impulses",
        "exact_rest",
        "exact_sweeps",
        "exact_settle",
        "exact_impacts",
        "exact_step_end",
    ]
    contact = [
        "contact_flight",
        "contact_memory",
        "contact_qp",
        "contact_time_of_impact",
        "contact_candidates",
        "contact_islands",
        "contact_impacts",
        "contact_solver",
        "contact_push_apart",
    ]
    assert set(dropped) == {
        "geometry_kernels",
        "contact_law",
        "event_heap",
        "step_kernels",
        "exact_kernels",
        "contact_kernels",
        *euler,
        *exact,
        *contact,
    }
    assert "geometry_kernels.py" in dropped["geometry_kernels"]
    assert {"step_kernels.py", "geometry_kernels.py"} <= set(dropped["step_kernels"])
    # The Forward Euler loop's machine code holds every file of its phases; the other steppers
    # call its lower files (the separations, the events), never the loop itself.
    assert {f"{stem}.py" for stem in euler} <= set(dropped["step_kernels"])
    for stepper in ("exact_kernels", "contact_kernels"):
        wanted = {f"{stepper}.py", "pair_separation.py", "event_rows.py", "geometry_kernels.py", "event_heap.py"}
        assert wanted <= set(dropped[stepper])
        assert "step_kernels.py" not in dropped[stepper]
    # The loop's machine code holds its phases' files, and the files they call (the impacts
    # call the geometry kernels and the event heap; the loop itself imports neither).
    assert {f"{stem}.py" for stem in exact} <= set(dropped["exact_kernels"])
    assert {"exact_impulses.py", "geometry_kernels.py"} <= set(dropped["exact_rest"])
    # The same for the contact stepper: its loop holds every file of its phases; the quadratic
    # program is held by the solve and push-apart, and calls no other file but the contact law's
    # velocity update (contact_law.pushed_velocity).
    assert {f"{stem}.py" for stem in contact} <= set(dropped["contact_kernels"])
    assert {"contact_qp.py", "contact_memory.py", "non_literal.py"} <= set(dropped["contact_solver"])
    options = {"tolerances.py", "numba_cache.py", "compiled.py"}  # what every kernel file's code depends on
    assert set(dropped["contact_qp"]) == {"contact_qp.py", "contact_law.py", *options}
    assert "contact_solver.py" not in dropped["contact_islands"]  # not dropped for another phase's edit
    assert "exact_impacts.py" not in dropped["exact_rest"]  # a file is not dropped for its callers' edits
    assert all({"compiled.py", "tolerances.py"} <= set(names) for names in dropped.values())
    # The kernels read no policy file: an edit of limits.py never recompiles them.
    assert not any("limits.py" in names for names in dropped.values())


def test_is_cached_asks_about_the_kernel_to_be_called(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """An exact world's check of overlaps calls find_near: whether run_steps is cached says
    nothing about it (a machine may never have run a large Forward Euler world)."""
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(compiled, "_started", [])  # its stale-code sweep, on this folder only
    folder = numba_cache._cache_folder(Path(compiled.__file__).resolve().parent)
    folder.mkdir(parents=True)
    (folder / "step_kernels.find_near-2101.py311.nbi").write_bytes(b"")
    assert compiled.is_cached("step_kernels", "find_near")
    assert not compiled.is_cached("step_kernels", "run_steps")
    assert not compiled.is_cached("exact_kernels", "run_exact_steps")
    assert not compiled.is_cached("exact_kernels", "find_near")  # another file's function


def test_is_cached_drops_stale_cached_code_before_it_answers(monkeypatch: pytest.MonkeyPatch) -> None:
    # After a kernel file changed, its old index files still stood when `collisionlab compile`
    # asked which kinds to compile side by side: it took them for cached, then compiled them one
    # after another in its own process (256 s instead of about 100). The stale code must go first.
    swept: list[bool] = []
    monkeypatch.setattr(compiled, "_started", [])
    monkeypatch.setattr(compiled, "_forget_stale", lambda: swept.append(True))
    compiled.is_cached("exact_kernels", "run_exact_steps")
    compiled.is_cached("step_kernels", "run_steps")
    assert swept == [True]  # once per process, before the first answer


def test_each_kernel_file_is_handed_the_compiled_files_it_imports() -> None:
    """compiled.py reads the import graph from the kernel files' own blocks: every file with such
    a block is reached from the steppers' loops, every line of a block is read (a line of another
    form would be a file left out: it would fail to compile, or drop a stale cache too seldom),
    each file is handed under one global name, and the graph has no circle."""
    folder = Path(compiled.__file__).resolve().parent
    files = set(compiled._kernel_files())
    block = re.compile(r'^if "_[A-Z_]+" in globals\(\):', re.MULTILINE)
    with_block = {p.stem for p in folder.glob("*.py") if block.search(p.read_text(encoding="utf-8"))}
    assert len(with_block) > 20
    assert with_block <= files
    names: dict[str, set[str]] = {}
    for stem in files:
        text = (folder / f"{stem}.py").read_text(encoding="utf-8")
        imports = compiled._imports(stem)
        assert len(re.findall(r'globals\(\)\["_', text)) == len(imports), stem
        assert len(re.findall(r"^\s+from \. import ", text, re.MULTILINE)) == len(imports), stem
        for module, name in imports.items():
            names.setdefault(module, set()).add(name)
    assert all(len(handed) == 1 for handed in names.values()), names

    def reaches(stem: str, seen: tuple[str, ...]) -> None:
        assert stem not in seen, f"import circle: {' -> '.join((*seen, stem))}"
        for callee in compiled._imports(stem):
            reaches(callee, (*seen, stem))

    for root in compiled._ROOTS:
        reaches(root, ())


def test_a_block_that_names_different_files_in_its_two_halves_is_refused(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    (tmp_path / "odd_kernels.py").write_text(
        'if "_GEOMETRY" in globals():\n    gk: Any = globals()["_GEOMETRY"]\n'
        "else:\n    from . import pair_separation as ps\n",
        encoding="utf-8",
    )
    monkeypatch.setattr(compiled, "_HERE", tmp_path)
    compiled._imports.cache_clear()
    try:
        with pytest.raises(RuntimeError, match=re.escape("odd_kernels.py: the compiled copy's globals")):
            compiled._imports("odd_kernels")
    finally:
        compiled._imports.cache_clear()
