"""Checkpoints of an exact gas: the whole state of a run, written atomically, read back whole.

A checkpoint (``collisionlab gas --mode exact --checkpoint FILE``) is a numpy ``.npz`` (a zip
of ``.npy`` arrays, no pickle) holding:

* ``header``: UTF-8 JSON as bytes (``uint8``): ``format`` (:data:`FORMAT`), ``version``
  (:data:`VERSION`), ``gas`` (the run's parameters as given: ``n, dim, fraction, boundary, time,
  seed, restitution, gravity, tc, kt, radius, mass`` and ``species`` as ``[name, fraction,
  radius, mass or null]``), ``run`` (what the run carries that is not in the world's arrays:
  ``energy_start``, the total energy at time 0 for ``energy_drift``; ``seconds``, the loop's
  wall-clock time so far; ``checkpoint_every``), ``world`` (its ``shell``, ``time``, ``n``,
  ``dim``), ``observer`` and ``sha256``;
* every array of :data:`~.world.STATE_ARRAYS`: the bodies as stored (each at the time of its
  last event), neighbour lists, cells, the event calendar, parameters, every accumulator and
  counter (``G``, ``K``) and the species' tallies (``S, KS, SE``);
* for an observed run (``--observe``), the arrays of :data:`~.structure.OBSERVER_ARRAYS`: the
  g(r) pair counts summed so far (``observer_counts``, int64, one row per unordered pair of
  species), the MSD at each sample taken (``observer_msd``), the unwrapped positions, those at
  the observation's origin and those of the last stop (``observer_unwrapped``,
  ``observer_start``, ``observer_ref``, ``(n, dim)``) and each ball's species
  (``observer_kinds``).

``observer`` is ``null`` for a run not observed, else (:meth:`.observer.Observer.saved`) the
observation's settings, ``observe`` (names, in :data:`~.structure.OBSERVABLES`' order),
``samples``, ``end`` (the run's end its sample times were laid out for) and the species'
``names``, and its scalars: ``k`` (samples taken), ``rdf_samples``, ``last`` (the time of the
last stop), ``speed`` (the fastest ball's then: the next unwrapping stop), ``origin_taken`` and
``virial`` (the collision virial at the origin). Read back, the observer is made again for the
run as it was at the start (:func:`~.observables.observer_for`) and given this state
(:meth:`.observer.Observer.restore`, which checks it against the run): the continued run
stops, samples and reports as the observed run done in one go, to the last bit. Its sample
times are laid out over the run's ``time`` as it was started, so an observed run cannot be
continued to another total time (``collisionlab gas --resume`` refuses ``--time`` then).

The world is stored as it is, not rebuilt, so a run continued from a checkpoint handles the same
events with the same numbers as the run done in one go (the loop's result does not depend on
where a run is split into calls: :meth:`~.world.EventDrivenWorld.run`; nor does an observer's
stopping it). Nothing random is drawn
after the start (the seed only places the balls and their velocities), so there is no random
state to keep.

``sha256`` is the SHA-256 of the header without it (JSON, sorted keys) followed by, for each
array in name order, its name, dtype, shape and bytes. A file is read whole and checked (format,
version, checksum, the arrays' names, dtypes and shapes, agreement with the header, the
last ones in :mod:`.checkpoint_arrays`) before any world is made from it: a truncated, corrupt
or foreign file, or another version, raises :class:`CheckpointError` with one line, never a
half-read world.

Written atomically: into a temporary file in the target's folder (``.NAME.XXXXXXXX.tmp``),
flushed and ``fsync``-ed, then renamed over the target (``os.replace``) and the folder synced,
so a run killed at any moment (SIGKILL included) leaves the previous checkpoint whole; only a
kill during the write itself can leave the hidden temporary file beside it.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import stat
import tempfile
import zipfile
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import CollisionLabError, escape_controls
from .arrays import STATE_ARRAYS
from .checkpoint_arrays import check_arrays
from .exact_gas import ExactGas, Species
from .observables import observer_for
from .observer import Observer
from .structure import OBSERVABLES, OBSERVER_ARRAYS
from .world import EventDrivenWorld

__all__ = ["FORMAT", "VERSION", "Checkpoint", "CheckpointError", "read_checkpoint", "write_checkpoint"]

#: The ``format`` field of every checkpoint's header.
FORMAT = "collisionlab-edmd-checkpoint"
#: The layout this code writes and reads; a file of another version is refused. (2: the
#: header's ``observer`` and the observer's arrays; version 1 files, without them, are refused.)
VERSION = 2
#: The first bytes of a zip file (an ``.npz``).
_ZIP_MAGIC = b"PK\x03\x04"
#: The ``.npz`` member holding the header.
_HEADER = "header"
#: The fields of :class:`~.observables.ExactGas` a checkpoint keeps (all of them).
_GAS_FIELDS = tuple(f.name for f in fields(ExactGas))


class CheckpointError(CollisionLabError):
    """A file that is not a readable checkpoint of this version: the message is one line
    naming the file and what is wrong."""


@dataclass(frozen=True)
class Checkpoint:
    """A checkpoint read back: the run's parameters as given (``gas``, its ``time`` the run's
    end when it was written), the world as it was, and what the run carries beside it."""

    gas: ExactGas
    world: EventDrivenWorld
    energy_start: float
    seconds: float
    every: float | None
    #: The simulated time the checkpoint was written at (the world's, until it runs on).
    time: float
    #: An observed run's observer (``--observe``), as it was, on :attr:`world`; ``None``: the
    #: run was not observed.
    observer: Observer | None = None


def _gas_header(gas: ExactGas) -> dict[str, Any]:
    header: dict[str, Any] = {name: getattr(gas, name) for name in _GAS_FIELDS}
    header["species"] = [[sp.name, sp.fraction, sp.radius, sp.mass] for sp in gas.species]
    return header


def _digest(header: dict[str, Any], arrays: dict[str, NDArray[Any]]) -> str:
    """The checksum (see the module's docstring) of ``header`` (without ``sha256``) and ``arrays``."""
    digest = hashlib.sha256(json.dumps({k: v for k, v in header.items() if k != "sha256"}, sort_keys=True).encode())
    for name in sorted(arrays):
        array = np.ascontiguousarray(arrays[name])
        digest.update(f"{name}|{array.dtype.str}|{array.shape}|".encode())
        digest.update(array.reshape(-1).view(np.uint8).data)
    return digest.hexdigest()


def write_checkpoint(
    path: str | Path,
    gas: ExactGas,
    world: EventDrivenWorld,
    energy_start: float,
    seconds: float,
    every: float | None,
    observer: Observer | None = None,
) -> None:
    """Write ``world`` (as it is stored: call between runs, never after anything that brings
    the bodies to one time) and the run's ``gas`` (as given, unchecked: it is checked again when
    read), ``energy_start`` and ``seconds`` to ``path``, with an observed run's ``observer``
    (its whole state: :meth:`.observer.Observer.saved`), atomically (see the module's
    docstring). An :class:`OSError` names ``path``."""
    arrays = world.state_arrays()
    observed: dict[str, Any] | None = None
    if observer is not None:
        observed, observer_arrays = observer.saved()
        arrays = {**arrays, **observer_arrays}
    header: dict[str, Any] = {
        "format": FORMAT,
        "version": VERSION,
        "gas": _gas_header(gas),
        "run": {"energy_start": energy_start, "seconds": seconds, "checkpoint_every": every},
        "world": {"shell": world.shell, "time": world.time, "n": world.n, "dim": world.dim},
        "observer": observed,
    }
    header["sha256"] = _digest(header, arrays)
    members: dict[str, Any] = {_HEADER: np.frombuffer(json.dumps(header).encode(), dtype=np.uint8), **arrays}
    _write_atomically(str(path), lambda stream: np.savez(stream, **members))


def _write_atomically(given: str, write: Any) -> None:
    """``write(stream)`` into a temporary file beside ``given`` (a symlink followed), synced
    to disk, then renamed over it; removed on any error or signal."""
    target = Path(os.path.realpath(given))
    try:
        mode = stat.S_IMODE(target.stat().st_mode)
    except OSError:  # a new file: what open() would give it
        mask = os.umask(0o022)
        os.umask(mask)
        mode = 0o666 & ~mask
    try:
        handle, name = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
    except OSError as error:
        raise OSError(error.errno, error.strerror or str(error), given) from None
    temporary = Path(name)
    try:
        with os.fdopen(handle, "wb") as stream:
            write(stream)
            stream.flush()
            os.fchmod(stream.fileno(), mode)
            os.fsync(stream.fileno())
        os.replace(temporary, target)
        # the rename itself on disk too (a crash after it returns keeps the new file)
        folder = os.open(target.parent, os.O_RDONLY | os.O_DIRECTORY)
        try:
            os.fsync(folder)
        finally:
            os.close(folder)
    except OSError as error:
        temporary.unlink(missing_ok=True)
        raise OSError(error.errno, error.strerror or str(error), given) from None
    except BaseException:
        temporary.unlink(missing_ok=True)
        raise


def read_checkpoint(path: str | Path) -> Checkpoint:
    """The checkpoint at ``path``, read whole and checked (see the module's docstring):
    :class:`CheckpointError` when it is not one this code can continue; an :class:`OSError`
    when it cannot be read at all."""
    shown = escape_controls(str(path))

    def refuse(problem: str) -> CheckpointError:
        return CheckpointError(f"{shown}: {problem}")

    with open(path, "rb") as stream:
        if stream.read(len(_ZIP_MAGIC)) != _ZIP_MAGIC:
            raise refuse("not a collisionlab checkpoint (not a numpy .npz file)")
        stream.seek(0)
        arrays, header = _members(stream, refuse)
    if header.get("sha256") != _digest(header, arrays):
        raise refuse("checksum mismatch: the file is corrupt (or was changed)")
    gas = _gas(header.get("gas"), refuse)
    run = header.get("run")
    world_info = header.get("world")
    if not isinstance(run, dict) or not isinstance(world_info, dict):
        raise refuse("header lacks 'run' or 'world'")
    check_arrays(arrays, gas, world_info, refuse)
    world = EventDrivenWorld.from_state_arrays(arrays, _number(world_info.get("shell"), "world.shell", refuse))
    every = run.get("checkpoint_every")
    return Checkpoint(
        gas=gas,
        world=world,
        energy_start=_number(run.get("energy_start"), "run.energy_start", refuse),
        seconds=_number(run.get("seconds"), "run.seconds", refuse),
        every=None if every is None else _number(every, "run.checkpoint_every", refuse),
        time=world.time,
        observer=_observer(header["observer"], arrays, gas, world, refuse),
    )


def _observer(
    raw: dict[str, Any] | None, arrays: dict[str, NDArray[Any]], gas: ExactGas, world: EventDrivenWorld, refuse: Any
) -> Observer | None:
    """An observed run's observer, made for ``gas`` on ``world`` as the run made it, its state
    taken back (:meth:`.observer.Observer.restore`); ``None`` when the run was not observed."""
    if raw is None:
        return None
    observe, samples = raw.get("observe"), raw.get("samples")
    if (
        not isinstance(observe, list)
        or not observe
        or any(name not in OBSERVABLES for name in observe)
        or isinstance(samples, bool)
        or not isinstance(samples, int)
        or samples < 1
    ):
        raise refuse("header field observer.observe or observer.samples is not an observation")
    for name, dtype in OBSERVER_ARRAYS.items():
        if arrays[name].dtype != np.dtype(dtype):
            raise refuse(f"array {name} is {arrays[name].dtype}, expected {np.dtype(dtype)}")
    try:
        observer = observer_for(gas.checked(), world, tuple(observe), samples)
        observer.restore(raw, arrays)
    except ValueError as error:  # (InvalidInputError is a ValueError)
        raise refuse(f"header field 'observer' is not this run's: {escape_controls(str(error))}") from None
    return observer


def _members(stream: Any, refuse: Any) -> tuple[dict[str, NDArray[Any]], dict[str, Any]]:
    """The state arrays and the header (its format and version checked) of an open ``.npz``."""
    try:
        with np.load(stream, allow_pickle=False) as members:
            names = set(members.files)
            if _HEADER not in names:
                raise refuse(f"not a collisionlab checkpoint (no {_HEADER!r} in it)")
            header = _header(_array(members, _HEADER, refuse), refuse)
            if "observer" not in header or not (header["observer"] is None or isinstance(header["observer"], dict)):
                raise refuse("header lacks 'observer' (null for a run not observed)")
            wanted = (*STATE_ARRAYS, *(OBSERVER_ARRAYS if header["observer"] is not None else ()))
            missing = sorted(set(wanted) - names)
            if missing:
                raise refuse(f"incomplete checkpoint: no {', '.join(missing)}")
            return {name: _array(members, name, refuse) for name in wanted}, header
    except CheckpointError:
        raise
    except (zipfile.BadZipFile, ValueError, OSError, EOFError, KeyError) as error:
        # a truncated or corrupt zip (a member's CRC), or a bad member
        reason = escape_controls(str(error).splitlines()[0] if str(error) else type(error).__name__)
        raise refuse(f"not a readable checkpoint (truncated or corrupt: {reason})") from None


def _array(members: Any, name: str, refuse: Any) -> NDArray[Any]:
    """Member ``name`` of an open ``.npz``: an array (numpy hands a member that is not one over
    as bytes)."""
    value = members[name]
    if not isinstance(value, np.ndarray):
        raise refuse(f"not a collisionlab checkpoint ({name!r} is not a numpy array)")
    return value


def _header(raw: NDArray[Any], refuse: Any) -> dict[str, Any]:
    """The header member parsed, its format and version checked."""
    if raw.dtype != np.uint8 or raw.ndim != 1:
        raise refuse("not a collisionlab checkpoint (its header is not JSON bytes)")
    try:
        header = json.loads(raw.tobytes().decode("utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError):
        raise refuse("not a collisionlab checkpoint (its header is not JSON)") from None
    if not isinstance(header, dict) or header.get("format") != FORMAT:
        raise refuse(f"not a collisionlab checkpoint (format is not {FORMAT!r})")
    version = header.get("version")
    if version != VERSION:
        raise refuse(f"checkpoint format version {version!r}; this collisionlab reads version {VERSION} only")
    return header


def _number(value: object, what: str, refuse: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise refuse(f"header field {what} must be a finite number")
    return float(value)


def _gas(raw: object, refuse: Any) -> ExactGas:
    """The run's parameters from the header (as they were given), checked as a new run's are."""

    if not isinstance(raw, dict) or set(raw) != set(_GAS_FIELDS):
        raise refuse("header field 'gas' lacks the run's parameters")
    try:
        species = tuple(Species(*entry) for entry in raw["species"])
        gas = ExactGas(**{**raw, "species": species})
        gas.checked()
    except (TypeError, ValueError) as error:  # (InvalidInputError is a ValueError)
        raise refuse(f"header field 'gas' is not a valid run: {escape_controls(str(error))}") from None
    return gas
