"""Run one point of a sweep and return its row of metrics.

The only module of the sweep that calls the simulation, and only through the public API:
:func:`collisionlab.scenario_file.parse_scenario` and a :class:`~collisionlab.engine.world.World`'s
``run()`` for a scenario (its compiled kernels loaded first, out of the point's time); for
the gas, its scenario (:func:`collisionlab.particles.gas_scenario`, or
:class:`collisionlab.edmd.observables.ExactGas` with ``mode = "exact"``) on the engine's
:class:`~collisionlab.engine.world.World`, exactly as ``collisionlab run``,
``collisionlab gas`` and ``collisionlab gas --mode exact`` do, so a row equals running its point alone.

Everything here is a pure function of the :class:`Task` (its seed included): nothing depends on
the worker, the process, or the order the tasks run in.
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from ..engine import WorldParams
from ..engine.world import World
from ..errors import InvalidInputError
from ..particles import gas_scenario, pick_backend
from ..record import RunRecord
from ..scenario_file import parse_scenario
from .theory import compressibility_from_collisions

if TYPE_CHECKING:  # the exact gas (and numba) load only when a sweep runs it
    from ..edmd.exact_gas import ExactGas

__all__ = [
    "EXACT_GAS_DEFAULTS",
    "EXACT_GAS_KEYS",
    "EXACT_GAS_METRICS",
    "GAS_DEFAULTS",
    "GAS_METRICS",
    "GAS_MODES",
    "SCENARIO_METRICS",
    "SPECIES_KEYS",
    "SPECIES_TABLE",
    "Task",
    "check_base",
    "metric_columns",
    "run_point",
]

#: The time-stepped gas's parameters (``[sweep.gas]`` and ``gas.KEY`` paths) and their defaults, those of
#: ``collisionlab gas``; ``fraction``, ``radius`` and ``step_fraction`` are
#: :func:`~collisionlab.particles.gas_scenario`'s.
GAS_DEFAULTS: dict[str, Any] = {
    "mode": "stepped",
    "n": 10_000,
    "dim": 2,
    "steps": 1000,
    "restitution": 1.0,
    "gravity": 0.0,
    "speeds": "gaussian",
    "backend": "auto",
    "fraction": 0.2,
    "radius": 1.0,
    "step_fraction": 0.1,
}

#: ``[sweep.gas] mode``: the time-stepped gas (default) or the exact, event-driven one.
GAS_MODES = ("stepped", "exact")

#: The exact gas's parameters (``mode = "exact"``) and their defaults, those of ``collisionlab gas
#: --mode exact`` (:class:`~collisionlab.edmd.observables.ExactGas`); the seed is the row's.
EXACT_GAS_DEFAULTS: dict[str, Any] = {
    "mode": "exact",
    "n": 10_000,
    "dim": 2,
    "fraction": 0.2,
    "boundary": "walls",
    "time": 10.0,
    "restitution": 1.0,
    "gravity": 0.0,
}
#: Its keys: the defaults', ``tc`` (``--tc``; absent: the exact gas's own default) and ``species``
#: (a mixture, ``--species``: an array of tables, see :data:`SPECIES_KEYS`; absent: one kind).
EXACT_GAS_KEYS: tuple[str, ...] = (*EXACT_GAS_DEFAULTS, "tc", "species")
#: The keys of one species of the exact gas (``[[sweep.gas.species]]``): ``name``, ``fraction``
#: (by number), ``radius`` and ``mass`` (optional: ``radius^dim``), as ``--species
#: NAME:FRACTION:RADIUS[:MASS]``; ``gas.species.NAME.KEY`` varies one (not the name).
SPECIES_KEYS: tuple[str, ...] = ("name", "fraction", "radius", "mass")
#: The form of a species, for the messages.
SPECIES_TABLE = "{name, fraction, radius[, mass]}"

_VECTOR = ("x", "y", "z")

#: Metric name -> its columns and their types ("int", "float", "bool"), for a scenario.
SCENARIO_METRICS: dict[str, tuple[tuple[str, str], ...]] = {
    "collisions": (("collisions", "int"),),
    "first_collision_step": (("first_collision_step", "int"),),
    "first_collision_time": (("first_collision_time", "float"),),
    "kinetic_energy_start": (("kinetic_energy_start", "float"),),
    "kinetic_energy_end": (("kinetic_energy_end", "float"),),
    "energy_start": (("energy_start", "float"),),
    "energy_end": (("energy_end", "float"),),
    "momentum_start": tuple((f"momentum_start_{c}", "float") for c in _VECTOR),
    "momentum_end": tuple((f"momentum_end_{c}", "float") for c in _VECTOR),
    "ledger": tuple(
        (f"ledger_{cause}", "float") for cause in ("collisions", "integrator", "push_apart", "residual", "predicted")
    ),
    "collision_rate": (("collision_rate", "float"),),
    "max_overlap": (("max_overlap", "float"),),
    "tunnelling_warning": (("tunnelling_warning", "bool"),),
    "wall_time": (("wall_time", "float"),),
}

#: The same for the gas.
GAS_METRICS: dict[str, tuple[tuple[str, str], ...]] = {
    "collisions": (("collisions", "int"),),
    "wall_collisions": (("wall_collisions", "int"),),
    "kinetic_energy_start": (("kinetic_energy_start", "float"),),
    "kinetic_energy_end": (("kinetic_energy_end", "float"),),
    "energy_drift": (("energy_drift", "float"),),
    "momentum_start": tuple((f"momentum_start_{c}", "float") for c in _VECTOR),
    "momentum_end": tuple((f"momentum_end_{c}", "float") for c in _VECTOR),
    "collision_rate": (("collision_rate", "float"),),
    "compressibility": (("compressibility", "float"),),
    "max_overlap": (("max_overlap", "float"),),
    "wall_time": (("wall_time", "float"),),
}


#: The same for the exact gas (``collisionlab gas --mode exact``'s report): ``max_overlap`` in
#: diameters, ``kt`` the temperature at the end, ``compressibility_walls`` from the momentum given
#: to the walls (empty with a periodic box), ``events`` every event handled,
#: ``compressibility_theory`` the equation of state's Z at the row's fraction (Carnahan-Starling,
#: or Henderson in 2D; a mixture's: BMCSL, or Santos-Yuste-Lopez de Haro in 2D; empty when
#: inelastic or under gravity).
EXACT_GAS_METRICS: dict[str, tuple[tuple[str, str], ...]] = {
    "collisions": (("collisions", "int"),),
    "wall_collisions": (("wall_collisions", "int"),),
    "events": (("events", "int"),),
    "kinetic_energy_start": (("kinetic_energy_start", "float"),),
    "kinetic_energy_end": (("kinetic_energy_end", "float"),),
    "energy_drift": (("energy_drift", "float"),),
    "momentum_start": tuple((f"momentum_start_{c}", "float") for c in _VECTOR),
    "momentum_end": tuple((f"momentum_end_{c}", "float") for c in _VECTOR),
    "kt": (("kt", "float"),),
    "collision_rate": (("collision_rate", "float"),),
    "compressibility": (("compressibility", "float"),),
    "compressibility_theory": (("compressibility_theory", "float"),),
    "compressibility_walls": (("compressibility_walls", "float"),),
    "max_overlap": (("max_overlap", "float"),),
    "wall_time": (("wall_time", "float"),),
}


@dataclass(frozen=True)
class Task:
    """One row to compute: point ``point``, replica ``replica``, with the base's data already
    changed to the point's values (``kind`` ``"scenario"``: TOML data; ``"gas"``: parameters)."""

    point: int
    replica: int
    seed: int
    kind: str
    data: Mapping[str, Any]
    metrics: tuple[str, ...]

    @property
    def key(self) -> tuple[int, int]:
        return (self.point, self.replica)


def metric_columns(kind: str, metrics: tuple[str, ...]) -> list[tuple[str, str]]:
    """The columns (name, type) that ``metrics`` fill, in order.

    >>> metric_columns("scenario", ("collisions", "momentum_end"))[:2]
    [('collisions', 'int'), ('momentum_end_x', 'float')]
    """
    registry = {**GAS_METRICS, **EXACT_GAS_METRICS} if kind == "gas" else SCENARIO_METRICS
    return [column for name in metrics for column in registry[name]]


def _vector(prefix: str, values: object) -> dict[str, float]:
    components = [float(v) for v in values] + [0.0] * 3  # type: ignore[attr-defined]
    return {f"{prefix}_{c}": components[i] for i, c in enumerate(_VECTOR)}


# --- a scenario ---------------------------------------------------------------------------------
def _scenario_metrics(record: RunRecord, seconds: float) -> dict[str, Any]:
    ledger = record.ledger
    first = record.events[0] if record.events else None
    duration = record.frames[-1].time if record.frames else 0.0
    return {
        "collisions": record.collision_total,
        "first_collision_step": first.step if first else None,
        "first_collision_time": first.time if first else None,
        "kinetic_energy_start": ledger.kinetic_start,
        "kinetic_energy_end": ledger.kinetic_end,
        "energy_start": ledger.energy_start,
        "energy_end": ledger.energy_end,
        **_vector("momentum_start", ledger.momentum_start),
        **_vector("momentum_end", ledger.momentum_end),
        "ledger_collisions": ledger.collisions,
        "ledger_integrator": ledger.integrator,
        "ledger_push_apart": ledger.push_apart,
        "ledger_residual": ledger.residual,
        "ledger_predicted": ledger.collisions_predicted,
        "collision_rate": record.collision_total / duration if duration > 0 else math.nan,
        "max_overlap": ledger.max_penetration,
        "tunnelling_warning": any("tunnelling" in warning for warning in record.warnings),
        "wall_time": seconds,
    }


def _run_scenario(data: Mapping[str, Any]) -> dict[str, Any]:
    world = World(parse_scenario(data, "scenario"))
    world.load_kernels()  # compiling (a worker's first task) is not the point's time
    began = time.perf_counter()
    record = world.run()
    return _scenario_metrics(record, time.perf_counter() - began)


# --- the gas ------------------------------------------------------------------------------------
def _gas_world(data: Mapping[str, Any], seed: int) -> tuple[World, int]:
    """The world ``collisionlab gas`` builds from these parameters, and its steps."""
    steps = data["steps"]
    if isinstance(steps, bool) or not isinstance(steps, int) or steps < 1:
        raise InvalidInputError("steps", "must be a whole number >= 1", got=steps)
    gas = gas_scenario(
        data["n"],
        data["dim"],
        seed,
        radius=data["radius"],
        fraction=data["fraction"],
        step_fraction=data["step_fraction"],
        speeds=data["speeds"],
    )
    compiled = pick_backend(data["backend"]) == "numba"
    scenario = gas.scenario(steps, data["restitution"], data["gravity"])
    return World(scenario, WorldParams(compiled=compiled), events=False), steps


def _run_gas(data: Mapping[str, Any], seed: int) -> dict[str, Any]:
    world, steps = _gas_world(data, seed)
    if world.compiled:
        world.step(0)  # loads the compiled kernels: compiling (a worker's first task) is not the point's time
    energy_start, momentum_start = world.kinetic_energy(), world.momentum()
    seconds = world.advance(steps)
    energy_end = world.kinetic_energy()
    collisions, wall_collisions = world.impulses()
    settings = world.scenario.settings
    n, dim = len(world.scenario.bodies), world.dims
    radius = float(data["radius"])
    return {
        "collisions": collisions,
        "wall_collisions": wall_collisions,
        "kinetic_energy_start": energy_start,
        "kinetic_energy_end": energy_end,
        "energy_drift": (energy_end - energy_start) / energy_start if energy_start > 0 else 0.0,
        **_vector("momentum_start", list(momentum_start)),
        **_vector("momentum_end", list(world.momentum())),
        "collision_rate": 2.0 * collisions / (n * settings.dt * steps),
        # Time-stepped: Z from the collision rate (theory.py); the exact gas (mode = "exact",
        # _run_exact_gas) reports the collision virial instead.
        "compressibility": compressibility_from_collisions(
            collisions, n, dim, 2.0 * radius, settings.dt * steps, (energy_start + energy_end) / 2
        ),
        "max_overlap": world.deepest_overlap(),
        "wall_time": seconds,
    }


# --- the exact gas ------------------------------------------------------------------------------
def _species(given: object) -> tuple[Any, ...]:
    """The exact gas's ``species`` (an array of tables :data:`SPECIES_TABLE`) as
    :class:`~collisionlab.edmd.observables.Species`, unchecked (:class:`InvalidInputError`,
    field ``species``, when not tables of those keys)."""
    from ..edmd.exact_gas import Species

    if given is None:
        return ()
    if not isinstance(given, list) or not all(isinstance(table, Mapping) for table in given):
        raise InvalidInputError("species", f"must be an array of tables {SPECIES_TABLE} ([[sweep.gas.species]])")
    out = []
    for table in given:
        unknown = sorted(set(table) - set(SPECIES_KEYS))
        missing = [key for key in ("name", "fraction", "radius") if key not in table]
        if unknown or missing:
            what = f"unknown key {unknown[0]!r}" if unknown else f"missing {missing[0]!r}"
            raise InvalidInputError("species", f"{what}; each species is a table {SPECIES_TABLE}", got=dict(table))
        if not isinstance(table["name"], str):
            raise InvalidInputError("species", f"a name must be a string ({SPECIES_TABLE})", got=table["name"])
        out.append(Species(table["name"], table["fraction"], table["radius"], table.get("mass")))
    return tuple(out)


def _exact_gas(data: Mapping[str, Any], seed: int) -> ExactGas:
    """The exact gas ``collisionlab gas --mode exact --seed SEED`` builds from these parameters."""
    from ..edmd.exact_gas import ExactGas

    return ExactGas(
        n=data["n"],
        dim=data["dim"],
        fraction=data["fraction"],
        boundary=data["boundary"],
        time=data["time"],
        seed=seed,
        restitution=data["restitution"],
        gravity=data["gravity"],
        tc=data.get("tc"),
        species=_species(data.get("species")),
    ).checked()


def _momentum(masses: Any, velocities: Any) -> list[float]:
    return [float(x) for x in masses @ velocities]


def _run_exact_gas(data: Mapping[str, Any], seed: int) -> dict[str, Any]:
    from ..edmd.observables import run_exact_gas

    gas = _exact_gas(data, seed)
    if gas.species:  # a mixture runs on its event-driven world alone, as collisionlab gas runs it
        balls = gas.world()  # compiling the loop (a worker's first task) is not the point's time
        kinetic_start, momentum_start = balls.kinetic_energy(), _momentum(balls.masses, balls.velocities)
        report = run_exact_gas(gas, balls=balls)
        kinetic_end, momentum_end = balls.kinetic_energy(), _momentum(balls.masses, balls.velocities)
    else:
        world = World(gas.scenario(), events=False)  # (compiling, as above, out of the point's time)
        kinetic_start, momentum_start = world.kinetic_energy(), list(world.momentum())
        report = run_exact_gas(gas, world)
        kinetic_end, momentum_end = world.kinetic_energy(), list(world.momentum())
    return {
        "collisions": report["collisions"],
        "wall_collisions": report["wall_collisions"],
        "events": report["events"],
        "kinetic_energy_start": kinetic_start,
        "kinetic_energy_end": kinetic_end,
        "energy_drift": report["energy_drift"],
        **_vector("momentum_start", momentum_start),
        **_vector("momentum_end", momentum_end),
        "kt": report["kT"],
        "collision_rate": report["collision_rate"],
        "compressibility": report["compressibility"],  # the collision virial: exact, no time step
        "compressibility_theory": report["compressibility_theory"],
        "compressibility_walls": report.get("compressibility_walls"),
        "max_overlap": report["max_overlap"],
        "wall_time": report["seconds"],
    }


# --- the entry points ---------------------------------------------------------------------------
def check_base(kind: str, data: Mapping[str, Any]) -> None:
    """Raise :class:`InvalidInputError` if the base itself (before any point's change) is invalid."""
    if kind == "gas" and data.get("mode") == "exact":
        from ..edmd.start import lattice

        gas = _exact_gas(data, 0)
        if gas.species:
            gas._mixture_start(gas.mixture()[1])  # the start fits
        else:
            lattice(gas.n, gas.dim, gas.fraction, gas.radius, gas.boundary == "periodic", 0)  # the start fits
    elif kind == "gas":
        _gas_world(data, 0)
    else:
        parse_scenario(data, "scenario")


def run_point(task: Task) -> dict[str, Any]:
    """The row of ``task``: ``point``, ``replica``, ``seed``, ``error`` (empty, or why the point could
    not run: the rest of the sweep goes on) and the metrics' columns (None after an error)."""
    row: dict[str, Any] = {"point": task.point, "replica": task.replica, "seed": task.seed, "error": ""}
    columns = metric_columns(task.kind, task.metrics)
    try:
        if task.kind != "gas":
            values = _run_scenario(task.data)
        elif task.data.get("mode") == "exact":
            values = _run_exact_gas(task.data, task.seed)
        else:
            values = _run_gas(task.data, task.seed)
    except InvalidInputError as error:
        row["error"] = f"{error.field}: {error.problem}" + (f" (got {error.got!r})" if error.got is not None else "")
        values = {}
    except (ArithmeticError, MemoryError, TypeError, ValueError, KeyError) as error:
        row["error"] = f"{type(error).__name__}: {error}"
        values = {}
    row.update({name: values.get(name) for name, _ in columns})
    return row
