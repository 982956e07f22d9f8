"""The observer of a periodic event-driven run (``collisionlab gas --mode exact --observe``): it
stops the run at its sample times, unwraps the positions between stops, counts g(r)'s pairs and
takes the MSD, then reports g(r), its contact value, the compressibility both ways and the
self-diffusion coefficient. The formulas and their references are :mod:`.structure`'s; this
file owns when to stop, what is kept between stops (and saved in a checkpoint) and the report.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import InvalidInputError
from .structure import (
    BIN_WIDTH,
    FIT_FROM,
    OBSERVABLES,
    OBSERVE_FROM,
    RDF_MAX_BALLS,
    UNWRAP_SAFETY,
    _is_finite,
    _is_int,
    contact_fit,
    enskog_self_diffusion,
    pair_histogram,
    rdf_from_counts,
)
from .world import EventDrivenWorld

__all__ = ["Observer"]


@dataclass
class Observer:
    """Samples a periodic :class:`EventDrivenWorld` at ``samples`` equal times of a run to
    ``end`` after its start ``t_0 = OBSERVE_FROM end`` (``t_0 + (end - t_0) k / samples``,
    ``k = 1 .. samples``) and unwraps its positions in between (see the module's docstring);
    the MSD's origin is ``t_0``, and the collision virial is read there too, so that the
    compressibility of the collisions over the same window is reported beside g's. The run
    calls :meth:`next_stop` for the next time it must stop at and :meth:`stop` there (the
    world's bodies unmoved: :meth:`EventDrivenWorld.state`)."""

    world: EventDrivenWorld
    end: float
    samples: int
    rdf: bool
    msd: bool
    kinds: NDArray[np.int64]
    names: list[str]
    sample_times: list[float] = field(init=False)
    _k: int = field(init=False, default=0)
    _last: float = field(init=False, default=0.0)

    def __post_init__(self) -> None:
        world = self.world
        if not world.periodic:
            raise InvalidInputError(
                "observe", "needs --boundary periodic (g(r) and the MSD of a box of walls are not the bulk's)"
            )
        if self.rdf and world.n > RDF_MAX_BALLS:
            raise InvalidInputError("observe", f"rdf counts every pair: at most {RDF_MAX_BALLS:,} balls", got=world.n)
        self.origin = OBSERVE_FROM * self.end
        span = self.end - self.origin
        # (the last one the run's end itself: origin + span may round past it, and that sample be lost)
        self.sample_times = [self.origin + span * k / self.samples for k in range(1, self.samples)] + [self.end]
        self._origin_taken = False
        self._virial = 0.0
        pos, vel = world.state()
        self._last = world.time
        self._ref = pos
        self._start = pos.copy()
        self._unwrapped = pos.copy()
        self._speed = float(np.sqrt(np.einsum("ij,ij->i", vel, vel).max()))
        self.species = int(self.kinds.max()) + 1
        radii = world.radii
        self._radius = [float(radii[self.kinds == a][0]) for a in range(self.species)]
        self.numbers = [int(np.sum(self.kinds == a)) for a in range(self.species)]
        side = float(world.sides.min())
        self.width = BIN_WIDTH * 2.0 * min(self._radius)
        self._counts = np.zeros((self.species * (self.species + 1) // 2, int(0.5 * side / self.width)), dtype=np.int64)
        self._msd: list[float] = []
        self._rdf_samples = 0

    @property
    def observe(self) -> tuple[str, ...]:
        """The names of what is observed, in :data:`OBSERVABLES`' order."""
        return tuple(name for name in OBSERVABLES if getattr(self, name))

    def saved(self) -> tuple[dict[str, Any], dict[str, NDArray[Any]]]:
        """The observer's whole state, for a checkpoint: its settings and scalars (JSON: floats
        as ``repr`` gives them, read back to the same bits) and its arrays
        (:data:`OBSERVER_ARRAYS`). :meth:`restore` on an observer made as this one was (same
        gas, ``observe``, ``samples`` and end) takes it back to this very state."""
        fields = {
            "observe": list(self.observe),
            "samples": self.samples,
            "end": self.end,
            "names": list(self.names),
            "k": self._k,
            "last": self._last,
            "speed": self._speed,
            "origin_taken": self._origin_taken,
            "virial": self._virial,
            "rdf_samples": self._rdf_samples,
        }
        arrays = {
            "observer_counts": self._counts,
            "observer_msd": np.array(self._msd, dtype=np.float64),
            "observer_unwrapped": self._unwrapped,
            "observer_start": self._start,
            "observer_ref": self._ref,
            "observer_kinds": np.asarray(self.kinds, dtype=np.int64),
        }
        return fields, arrays

    def restore(self, fields: dict[str, Any], arrays: dict[str, NDArray[Any]]) -> None:
        """Take back the state :meth:`saved` gave (this observer made for the same run, on the
        world as it was saved); :class:`ValueError` with one line naming what disagrees, the
        observer unchanged then."""
        if fields.get("observe") != list(self.observe) or fields.get("samples") != self.samples:
            raise ValueError("the observer's 'observe' or 'samples' disagree with the run's")
        if fields.get("end") != self.end:
            raise ValueError("the observer's 'end' is not the run's end")
        if fields.get("names") != list(self.names) or not np.array_equal(arrays["observer_kinds"], self.kinds):
            raise ValueError("the observer's species disagree with the run's")
        k: Any = fields.get("k")
        rdf_samples: Any = fields.get("rdf_samples")
        if not _is_int(k) or not 0 <= k <= self.samples or rdf_samples != (k if self.rdf else 0):
            raise ValueError("the observer's sample counts are out of range")
        origin_taken = fields.get("origin_taken")
        if not isinstance(origin_taken, bool) or (k > 0 and not origin_taken):
            raise ValueError("the observer's 'origin_taken' must be true or false (true once sampled)")
        numbers: dict[str, Any] = {name: fields.get(name) for name in ("last", "speed", "virial")}
        for name, value in numbers.items():
            if not _is_finite(value):
                raise ValueError(f"the observer's {name!r} must be a finite number")
        if not 0.0 <= float(numbers["last"]) <= self.world.time or float(numbers["speed"]) < 0.0:
            raise ValueError("the observer's 'last' is after the world's time or its 'speed' is negative")
        shape = self._unwrapped.shape
        expected = {
            "observer_counts": self._counts.shape,
            "observer_msd": (k if self.msd else 0,),
            "observer_unwrapped": shape,
            "observer_start": shape,
            "observer_ref": shape,
        }
        for name, wanted in expected.items():
            if arrays[name].shape != wanted:
                raise ValueError(f"the observer's array {name} has shape {arrays[name].shape}, expected {wanted}")
        self._k = int(k)
        self._rdf_samples = int(rdf_samples)
        self._origin_taken = origin_taken
        self._last, self._speed, self._virial = (float(numbers[name]) for name in ("last", "speed", "virial"))
        self._counts = arrays["observer_counts"].copy()
        self._msd = [float(x) for x in arrays["observer_msd"]]
        self._unwrapped = arrays["observer_unwrapped"].copy()
        self._start = arrays["observer_start"].copy()
        self._ref = arrays["observer_ref"].copy()

    def next_stop(self) -> float:
        """The next time the run must stop at: the next sample, or sooner to unwrap."""
        if not self._origin_taken:
            target = self.origin
        else:
            target = self.sample_times[self._k] if self._k < self.samples else math.inf
        step = float(self.world.sides.min()) / (UNWRAP_SAFETY * self._speed) if self._speed > 0 else math.inf
        return min(target, self._last + step)

    def stop(self) -> None:
        """At a stop: unwrap, and at a sample time count pairs and take the MSD."""
        world = self.world
        pos, vel = world.state()
        d = pos - self._ref
        d -= world.sides * np.floor(d / world.sides + 0.5)
        self._unwrapped += d
        self._ref = pos
        self._last = world.time
        self._speed = float(np.sqrt(np.einsum("ij,ij->i", vel, vel).max()))
        if not self._origin_taken and world.time >= self.origin:
            self._origin_taken = True
            self._start = self._unwrapped.copy()
            self._virial = world.tally().virial
        if self._origin_taken and self._k < self.samples and world.time >= self.sample_times[self._k]:
            self._k += 1
            if self.msd:
                shift = self._unwrapped - self._start
                self._msd.append(float(np.einsum("ij,ij->", shift, shift)) / world.n)
            if self.rdf:
                pair_histogram(pos, self.kinds, self.species, world.sides, self.width, self._counts)
                self._rdf_samples += 1

    def report(self, kt: float, fraction: float, mass: float | None) -> dict[str, Any]:
        """The report's fields: ``rdf``, ``compressibility_contact`` and ``compressibility_window``
        (the collision virial's over the observed window), ``msd``, ``diffusion`` and
        ``diffusion_enskog`` (one kind of ball, elastic: else ``None``), as observed."""
        world = self.world
        dim, n = world.dim, world.n
        out: dict[str, Any] = {"observed_from": self.origin}
        if self.rdf and self._rdf_samples:
            volume = float(world.sides.prod())
            g = rdf_from_counts(self._counts, self._rdf_samples, self.width, volume, dim, self.numbers)
            r = self.width * (np.arange(g.shape[1], dtype=np.float64) + 0.5)
            pairs = []
            virial = 0.0
            density = n / volume
            row = 0
            for a in range(self.species):
                for b in range(a, self.species):
                    sigma = self._radius[a] + self._radius[b]
                    contact = contact_fit(r, g[row], self.width, sigma)
                    weight = (self.numbers[a] / n) * (self.numbers[b] / n) * (1.0 if a == b else 2.0)
                    virial += weight * sigma**dim * contact
                    pairs.append({"species": [self.names[a], self.names[b]], "sigma": sigma, "g": g[row].tolist(),
                                  "contact": contact})  # fmt: skip
                    row += 1
            factor = 2.0 * math.pi / 3.0 if dim == 3 else math.pi / 2.0
            out["rdf"] = {"samples": self._rdf_samples, "bin_width": self.width, "r": r.tolist(), "pairs": pairs}
            z = 1.0 + factor * density * virial
            out["compressibility_contact"] = z if math.isfinite(z) else None
            window = world.time - self.origin
            collided = world.tally().virial - self._virial
            nkt = n * kt
            out["compressibility_window"] = 1.0 + collided / (dim * nkt * window) if nkt > 0 and window > 0 else None
        if self.msd and self._msd:
            times = [t - self.origin for t in self.sample_times[: len(self._msd)]]
            out["msd"] = {"t": times, "msd": self._msd}
            use = [k for k, t in enumerate(times) if t >= FIT_FROM * (self.end - self.origin)]
            if len(use) >= 2:
                slope = float(np.polyfit(np.array(times)[use], np.array(self._msd)[use], 1)[0])
                out["diffusion"] = slope / (2.0 * dim)
            else:
                out["diffusion"] = None
            out["diffusion_enskog"] = (
                enskog_self_diffusion(fraction, dim, self._radius[0], mass, kt) if mass is not None else None
            )
        return out
