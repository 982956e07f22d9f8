"""The stateful simulation: a :class:`World` steps a :class:`~collisionlab.model.Scenario`.

Each step, in this order (``mode = "euler"``, the lab's part VI):

1. **Integrate** with Forward Euler: ``x += v dt`` then ``v += g dt``.
2. **Detect** every pair (body-body ``i < j`` first, then obstacle-body) with the narrow phase.
3. **Resolve** every contact whose bodies approach: against an obstacle lab eq. 24, between two
   bodies the impulse along the line of action with masses
   (:func:`~collisionlab.resolution.resolve_collision`). Approach slower than ``REST_SPEED``
   gets e = 0.
4. **Push apart** every overlapping pair (distance < 0), in inverse proportion to mass, to a gap of
   ``CONTACT_SLOP``, so a resolved pair is not found again on the next step.

With ``mode = "exact"`` nothing tunnels: within each step the world finds the earliest time of
impact among all pairs (:func:`~collisionlab.toi.time_of_impact`; the motion is exact, a
parabola under gravity), moves every body to that moment, resolves that impact, settles the
contacts it touches (sequential impulses over every touching pair until none approaches: a
row of touching balls passes the impact along, a body driven against a wall stops), and goes on
with the rest of the step, as many impacts as happen; then it pushes apart as in phase 4.
Times of impact are kept until one of the pair's bodies is kicked (event-driven), and bodies
whose swept boxes do not meet are not tested (the broad phase).
A body lying on a static obstacle or on another body (within ``CONTACT_MARGIN``, normal speed
below ``REST_SPEED``, gravity pressing them together) rests: the approach is stopped and the
pressing part of the acceleration is cancelled by the support, so it neither sinks nor jitters,
and stacks settle from the bottom up.

A collision is reported once per impact: a pair that collided stays "in contact" until its
distance grows beyond ``CONTACT_MARGIN``, and further impulses meanwhile are not new events.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass

from .contact import Separation
from .errors import InvalidInputError
from .limits import RangeGuard, is_overflow
from .model import Body, Obstacle, Scenario
from .narrowphase import separation
from .record import BodyState, CollisionEvent, Frame, RunRecord, SkippedContact
from .resolution import impulse_magnitude
from .shapes import AABB, Circle, Shape, Sphere
from .toi import Impact, time_of_impact
from .tolerances import CONTACT_MARGIN, CONTACT_SLOP, REST_SPEED
from .vector import Vector3D

__all__ = ["MAX_IMPACTS_PER_STEP", "RELAX_PASSES", "World", "simulate"]

#: The most impacts the exact stepper resolves within one step before it finishes the step
#: without them (and says so in the run's warnings); guards against an endless run of impacts.
MAX_IMPACTS_PER_STEP = 10_000

#: The most passes of sequential impulses that settle the contacts touched by one impact (a row
#: of k touching balls needs k; a cluster with e = 0 converges geometrically).
RELAX_PASSES = 64

_ZERO = Vector3D(0.0, 0.0, 0.0)


@dataclass(frozen=True)
class _Pair:
    """Indices of a pair: ``a`` is a body index, or an obstacle index when ``static``."""

    a: int
    b: int
    static: bool


def _boxes_meet(boxes: list[tuple[Vector3D, Vector3D]], pair: _Pair) -> bool:
    """The broad phase: two bodies can touch only if their (swept) boxes overlap; a pair with an
    obstacle always goes on to the narrow phase (lines and planes are unbounded)."""
    if pair.static:
        return True
    (low_a, high_a), (low_b, high_b) = boxes[pair.a], boxes[pair.b]
    return not any(ha < lb or hb < la for la, ha, lb, hb in zip(low_a, high_a, low_b, high_b, strict=True))


def _stopping_impulse(normal_speed: float, inverse_mass_sum: float) -> float:
    """The impulse that brings a relative normal speed to zero (e = 0)."""
    return -normal_speed / inverse_mass_sum


def _thickness(shape: Shape) -> float:
    """How far something must travel to pass through this shape (tunnelling check)."""
    if isinstance(shape, (Circle, Sphere)):
        return 2.0 * shape.radius
    if isinstance(shape, AABB):
        size = shape.max_corner - shape.min_corner
        return min(size.as_tuple()[: shape.dim])
    return 0.0


class World:
    """A running simulation. Build it from a scenario, then :meth:`step` or :meth:`run`."""

    def __init__(self, scenario: Scenario) -> None:
        self.scenario = scenario
        settings = scenario.settings
        self.positions: list[Vector3D] = [b.position for b in scenario.bodies]
        self.velocities: list[Vector3D] = [b.velocity for b in scenario.bodies]
        self.step_index = 0
        self.time = 0.0
        body_index = {id(b): i for i, b in enumerate(scenario.bodies)}
        obstacle_index = {id(o): i for i, o in enumerate(scenario.obstacles)}
        self._pairs = [
            _Pair(obstacle_index[id(a)], body_index[id(b)], True)
            if isinstance(a, Obstacle)
            else _Pair(body_index[id(a)], body_index[id(b)], False)
            for a, b in scenario.pairs()
        ]
        self._touching: set[_Pair] = set()
        #: Unit normals of what each resting body lies on (exact mode; found each sub-step).
        self._supports: dict[int, list[Vector3D]] = {}
        #: Longest sub-step before a body sliding on a curved support must be looked at again.
        self._slide_limit = math.inf
        #: Bodies whose velocity an impulse changed since this was last cleared (exact mode).
        self._kicked: set[int] = set()
        self._tunnel_warned = False
        self._impact_limit_warned = False
        self.record = RunRecord(
            title=scenario.title,
            mode=settings.mode,
            dt=settings.dt,
            steps=settings.steps,
            restitution=settings.restitution,
            gravity=settings.gravity,
            dims=scenario.dims,
        )
        ledger = self.record.ledger
        ledger.kinetic_start = ledger.kinetic_end = self.kinetic_energy()
        ledger.potential_start = ledger.potential_end = self.potential_energy()
        ledger.momentum_start = ledger.momentum_end = self.momentum()
        warning = scenario.energy_warning()
        if warning:
            self.record.warnings.append(warning)

    # --- state ---------------------------------------------------------------------------------
    @property
    def bodies(self) -> tuple[Body, ...]:
        return self.scenario.bodies

    def shape(self, index: int) -> Shape:
        """Body ``index``'s shape at its current position."""
        return self.scenario.bodies[index].shape.moved_to(self.positions[index])

    def kinetic_energy(self) -> float:
        return sum(0.5 * b.mass * v.length_squared() for b, v in zip(self.bodies, self.velocities, strict=True))

    def potential_energy(self) -> float:
        """``-sum m g.x``: zero at the origin."""
        g = self.scenario.settings.gravity
        return -sum(b.mass * g.dot(x) for b, x in zip(self.bodies, self.positions, strict=True))

    def energy(self) -> float:
        return self.kinetic_energy() + self.potential_energy()

    def momentum(self) -> Vector3D:
        total = _ZERO
        for body, v in zip(self.bodies, self.velocities, strict=True):
            total = total + v * body.mass
        return total

    def frame(self) -> Frame:
        return Frame(
            self.step_index,
            self.time,
            tuple(
                BodyState(b.name, x, v) for b, x, v in zip(self.bodies, self.positions, self.velocities, strict=True)
            ),
        )

    # --- pairs ---------------------------------------------------------------------------------
    def _thing_a(self, pair: _Pair) -> Body | Obstacle:
        return self.scenario.obstacles[pair.a] if pair.static else self.scenario.bodies[pair.a]

    def _names(self, pair: _Pair) -> tuple[str, str]:
        return (self._thing_a(pair).name, self.scenario.bodies[pair.b].name)

    def _shape_a(self, pair: _Pair) -> Shape:
        return self.scenario.obstacles[pair.a].shape if pair.static else self.shape(pair.a)

    def _velocity_a(self, pair: _Pair) -> Vector3D:
        return _ZERO if pair.static else self.velocities[pair.a]

    def _separation(self, pair: _Pair) -> Separation:
        return separation(self._shape_a(pair), self.shape(pair.b))

    def _restitution(self, pair: _Pair) -> float:
        """The pair's e: the larger of the two overrides if any (Box2D mixes by max), else the default."""
        overrides = [t.restitution for t in (self._thing_a(pair), self.scenario.bodies[pair.b])]
        given = [e for e in overrides if e is not None]
        return max(given) if given else self.scenario.settings.restitution

    def _forget_separated(self) -> None:
        """Pairs that have moved apart beyond ``CONTACT_MARGIN`` are no longer in contact."""
        self._touching = {pair for pair in self._touching if self._separation(pair).distance <= CONTACT_MARGIN}

    # --- resolution ----------------------------------------------------------------------------
    def _resolve(
        self, pair: _Pair, normal: Vector3D, point: Vector3D, time: float, fresh: bool = False
    ) -> float | None:
        """Apply the impulse along ``normal`` (from A to B) if the pair approaches; record it as
        an event if the pair was not already in contact, or if it arrives from a flight found by
        time of impact (``fresh``) faster than ``REST_SPEED``. Returns the approach speed
        ``v_n`` (< 0) when an impulse was applied, else ``None``."""
        va, vb = self._velocity_a(pair), self.velocities[pair.b]
        vn = (vb - va).dot(normal)
        if vn >= 0.0:
            if pair not in self._touching:
                self.record.skipped.append(SkippedContact(self.step_index, time, self._names(pair), "separating"))
            return None
        below = -vn < REST_SPEED
        e = 0.0 if below else self._restitution(pair)
        ke_before = self._pair_kinetic(pair)
        j, inverse_a, inverse_b = self._kick(pair, normal, lambda inverse_sum: impulse_magnitude(vn, inverse_sum, e))
        va_after, vb_after = self._velocity_a(pair), self.velocities[pair.b]
        ke_after = self._pair_kinetic(pair)
        self.record.ledger.collisions_predicted -= 0.5 * (1.0 - e * e) * vn * vn / (inverse_a + inverse_b)
        if pair not in self._touching or (fresh and not below):
            name_a, name_b = self._names(pair)
            before = {name_b: vb} if pair.static else {name_a: va, name_b: vb}
            after = {name_b: vb_after} if pair.static else {name_a: va_after, name_b: vb_after}
            mass_a = 1.0 / inverse_a if inverse_a > 0.0 else float("inf")
            self.record.events.append(
                CollisionEvent(
                    step=self.step_index,
                    time=time,
                    bodies=(name_a, name_b),
                    static=pair.static,
                    normal=normal,
                    point=point,
                    approach_speed=vn,
                    impulse=j,
                    restitution=e,
                    masses=(mass_a, 1.0 / inverse_b if inverse_b > 0.0 else float("inf")),
                    velocities_before=before,
                    velocities_after=after,
                    kinetic_energy_before=ke_before,
                    kinetic_energy_after=ke_after,
                    below_rest_threshold=below,
                )
            )
            self._touching.add(pair)
        return vn

    def _close_gap(self, pair: _Pair, normal: Vector3D, gap: float) -> None:
        """Bring a body sliding on a curved support back onto it (a gap below ``CONTACT_MARGIN``),
        shared between the two as an impulse would be (:meth:`_response`). The potential energy
        this changes goes to the ledger's push-apart."""
        energy_before = self.energy()
        dir_a, inverse_a = (_ZERO, 0.0) if pair.static else self._response(pair.a, -normal)
        dir_b, inverse_b = self._response(pair.b, normal)
        share = gap / (inverse_a + inverse_b)
        if not pair.static:
            self.positions[pair.a] = self.positions[pair.a] - dir_a * (share / self.bodies[pair.a].mass)
        self.positions[pair.b] = self.positions[pair.b] - dir_b * (share / self.bodies[pair.b].mass)
        self.record.ledger.push_apart += self.energy() - energy_before

    def _support_radius(self, pair: _Pair, normal: Vector3D) -> float:
        """Radius of curvature of the surface the pair slides on (the Minkowski sum of the two
        shapes): ``r_a + r_b`` for two balls, the ball's radius on a box's edge or corner (a normal
        off the axes), ``math.inf`` when flat (a plane, a line, a box face, two boxes)."""
        radii = [s.radius for s in (self._shape_a(pair), self.shape(pair.b)) if isinstance(s, (Circle, Sphere))]
        if len(radii) == 2:
            return radii[0] + radii[1]
        if len(radii) == 1 and sum(1 for c in normal if c != 0.0) >= 2:
            return radii[0]
        return math.inf

    def _kick(self, pair: _Pair, normal: Vector3D, impulse: Callable[[float], float]) -> tuple[float, float, float]:
        """Apply the impulse ``impulse(1/m_a + 1/m_b)`` along ``normal`` (A gets minus it), with
        supports taking their share (:meth:`_response`); the kinetic energy it changes goes to
        the ledger's collisions. Returns the impulse and the two inverse masses along the normal."""
        ke_before = self._pair_kinetic(pair)
        dir_a, inverse_a = (_ZERO, 0.0) if pair.static else self._response(pair.a, -normal)
        dir_b, inverse_b = self._response(pair.b, normal)
        j = impulse(inverse_a + inverse_b)
        self._kicked.add(pair.b)
        if not pair.static:
            self._kicked.add(pair.a)
            self.velocities[pair.a] = self.velocities[pair.a] + dir_a * (j / self.bodies[pair.a].mass)
        self.velocities[pair.b] = self.velocities[pair.b] + dir_b * (j / self.bodies[pair.b].mass)
        self.record.ledger.collisions += self._pair_kinetic(pair) - ke_before
        return j, inverse_a, inverse_b

    def _response(self, index: int, direction: Vector3D) -> tuple[Vector3D, float]:
        """How body ``index`` answers an impulse along ``direction``: a body resting on a support
        (exact mode) cannot be pushed into it, so the part of the push along the support's normal
        goes to the support (an obstacle of infinite mass) and only the rest moves the body.
        Returns the direction its velocity changes per unit impulse times mass, and its inverse
        mass along ``direction`` (``1/m`` free, ``(1 - (s.d)^2)/m`` on a support ``s``)."""
        moved = direction
        for support in self._supports.get(index, ()):
            into = moved.dot(support)
            if into < 0.0:
                moved = moved - support * into
        return moved, moved.dot(direction) / self.bodies[index].mass

    def _pair_kinetic(self, pair: _Pair) -> float:
        indices = (pair.b,) if pair.static else (pair.a, pair.b)
        return sum(0.5 * self.bodies[i].mass * self.velocities[i].length_squared() for i in indices)

    def _push_apart(self) -> None:
        """Phase 4: every overlapping pair is moved apart to a gap of ``CONTACT_SLOP``."""
        energy_before = self.energy()
        boxes = self._swept_boxes(0.0, [_ZERO] * len(self.bodies))
        for pair in self._pairs:
            if not _boxes_meet(boxes, pair):
                continue
            sep = self._separation(pair)
            if sep.distance >= 0.0:  # touching is not overlapping: nothing to undo
                continue
            push = CONTACT_SLOP - sep.distance
            self.record.ledger.max_penetration = max(self.record.ledger.max_penetration, -sep.distance)
            inverse_a = 0.0 if pair.static else 1.0 / self.bodies[pair.a].mass
            inverse_b = 1.0 / self.bodies[pair.b].mass
            total = inverse_a + inverse_b
            if not pair.static:
                self.positions[pair.a] = self.positions[pair.a] - sep.normal * (push * inverse_a / total)
            self.positions[pair.b] = self.positions[pair.b] + sep.normal * (push * inverse_b / total)
        self.record.ledger.push_apart += self.energy() - energy_before

    # --- stepping ------------------------------------------------------------------------------
    def step(self) -> None:
        """Advance one step of ``dt`` in the scenario's mode."""
        if self.scenario.settings.mode == "exact":
            self._step_exact()
        else:
            self._step_euler()
        self._push_apart()
        ledger = self.record.ledger
        ledger.kinetic_end = self.kinetic_energy()
        ledger.potential_end = self.potential_energy()
        ledger.momentum_end = self.momentum()

    def _step_euler(self) -> None:
        settings = self.scenario.settings
        dt, g = settings.dt, settings.gravity
        self._check_tunnelling(dt)
        energy_before = self.energy()
        # Phase 1: Forward Euler, position from the old velocity (the lab's integrator).
        self.positions = [x + v * dt for x, v in zip(self.positions, self.velocities, strict=True)]
        self.velocities = [v + g * dt for v in self.velocities]
        self.record.ledger.integrator += self.energy() - energy_before
        self.step_index += 1
        self.time = self.step_index * dt
        # Phase 2: detect (boxes first: bodies whose boxes, grown by CONTACT_MARGIN, do not meet
        # are farther apart than that); phase 3: resolve, in the fixed pair order.
        boxes = self._swept_boxes(0.0, [_ZERO] * len(self.bodies))
        separations = [(pair, self._separation(pair)) for pair in self._pairs if _boxes_meet(boxes, pair)]
        near = {pair for pair, sep in separations if sep.distance <= CONTACT_MARGIN}
        self._touching &= near
        for pair, sep in separations:
            if sep.distance <= 0.0:
                self._resolve(pair, sep.normal, sep.point, self.time)

    def _check_tunnelling(self, dt: float) -> None:
        if self._tunnel_warned:
            return
        for pair in self._pairs:
            relative = (self.velocities[pair.b] - self._velocity_a(pair)).length() * dt
            limit = _thickness(self._shape_a(pair)) + _thickness(self.shape(pair.b))
            if relative > limit:
                name_a, name_b = self._names(pair)
                self.record.warnings.append(
                    f"'{name_b}' moves {relative:.3g} m relative to '{name_a}' in one step, more than the "
                    f"{limit:.3g} m it takes to pass through: collisions can be missed (tunnelling); "
                    "use --mode exact"
                )
                self._tunnel_warned = True
                return

    def _step_exact(self) -> None:
        settings = self.scenario.settings
        start = self.step_index * settings.dt
        self.step_index += 1  # events of this step carry its number, as in euler mode
        elapsed = 0.0
        ignored: set[_Pair] = set()
        impacts = slides = 0
        # Times of impact found this step, as (time from the step's start, impact): the motion
        # between impacts is known exactly, so a pair stays valid until one of its bodies is
        # kicked or its acceleration changes (event-driven stepping, as in molecular dynamics).
        found: dict[_Pair, tuple[float, Impact] | None] = {}
        previous: list[Vector3D] | None = None
        while True:
            remaining = settings.dt - elapsed
            self._forget_separated()
            self._kicked = set()
            accelerations, resting = self._resting_contacts(start + elapsed)
            dirty = set(self._kicked)
            if previous is not None:
                dirty.update(i for i, (a, b) in enumerate(zip(accelerations, previous, strict=True)) if a != b)
            previous = accelerations
            boxes = self._swept_boxes(remaining, accelerations)
            best: tuple[_Pair, float, Impact] | None = None
            for pair in self._pairs:
                if pair in ignored or pair in resting:
                    found.pop(pair, None)
                    continue
                if pair not in found or pair.b in dirty or (not pair.static and pair.a in dirty):
                    found[pair] = self._time_of_impact(pair, remaining, accelerations, boxes, elapsed)
                entry = found[pair]
                if entry is not None and (best is None or entry[0] < best[1]):
                    best = (pair, entry[0], entry[1])
            limit = self._slide_limit
            if limit < remaining and slides < MAX_IMPACTS_PER_STEP and (best is None or best[1] - elapsed > limit):
                self._advance(limit, accelerations)  # then look at the sliding contacts again
                elapsed += limit
                slides += 1
                continue
            if best is None or impacts >= MAX_IMPACTS_PER_STEP:
                if best is not None and not self._impact_limit_warned:
                    self._impact_limit_warned = True
                    self.record.warnings.append(
                        f"more than {MAX_IMPACTS_PER_STEP} impacts in step {self.step_index}: the rest of "
                        "that step was integrated without them (said once; later steps may do the same)"
                    )
                self._advance(remaining, accelerations)
                break
            pair, when, impact = best
            wait = max(0.0, when - elapsed)
            self._advance(wait, accelerations)
            elapsed += wait
            fresh = impact.time > 0.0 and not impact.initially_overlapping
            self._kicked = set()
            vn = self._resolve(pair, impact.normal, self._separation(pair).point, start + elapsed, fresh)
            impacts += 1
            if vn is not None:
                self._relax_contacts(start + elapsed)
            found.pop(pair, None)
            if vn is None or -vn < REST_SPEED:
                # Nothing to do, or a touch too slow to bounce (e = 0 applied): this pair is in
                # resting contact; look at it again next step, so rounding cannot loop here.
                ignored.add(pair)
            else:
                ignored.clear()
            for index in self._kicked:  # their pairs must be searched again
                for other in [p for p in found if p.b == index or (not p.static and p.a == index)]:
                    del found[other]
        self.time = self.step_index * settings.dt

    def _relax_contacts(self, time: float) -> None:
        """After an impact, settle the bodies it touches: every pair in contact (within
        ``CONTACT_MARGIN``) that now approaches gets its impulse, pass after pass (sequential
        impulses, as Box2D's velocity iterations), until none approaches. This is how an impact
        runs along a row of touching balls (Newton's cradle) and how a body pushed against a
        wall by another stops both, within the instant, instead of sinking into the wall."""
        boxes = self._swept_boxes(0.0, [_ZERO] * len(self.bodies))
        near = [pair for pair in self._pairs if _boxes_meet(boxes, pair)]
        for _ in range(RELAX_PASSES):
            applied = False
            for pair in near:
                sep = self._separation(pair)
                if sep.distance > CONTACT_MARGIN:
                    continue
                if (self.velocities[pair.b] - self._velocity_a(pair)).dot(sep.normal) < 0.0:
                    applied = self._resolve(pair, sep.normal, sep.point, time) is not None or applied
            if not applied:
                return

    def _swept_boxes(self, duration: float, accelerations: list[Vector3D]) -> list[tuple[Vector3D, Vector3D]]:
        """Each body's bounding box over the next ``duration``: its shape's box at the start and
        at the end, grown by ``|a| t^2 / 2`` (the parabola leaves its chord by at most ``|a| t^2 / 8``)."""
        boxes = []
        for index, (x, v, a) in enumerate(zip(self.positions, self.velocities, accelerations, strict=True)):
            shape = self.scenario.bodies[index].shape
            extent = shape.half_size if isinstance(shape, AABB) else Vector3D(shape.radius, shape.radius, shape.radius)
            end = x + v * duration + a * (0.5 * duration * duration)
            grow = extent + Vector3D(1.0, 1.0, 1.0) * (0.5 * a.length() * duration * duration + CONTACT_MARGIN)
            low = Vector3D(min(x.x, end.x), min(x.y, end.y), min(x.z, end.z)) - grow
            high = Vector3D(max(x.x, end.x), max(x.y, end.y), max(x.z, end.z)) + grow
            boxes.append((low, high))
        return boxes

    def _time_of_impact(
        self,
        pair: _Pair,
        remaining: float,
        accelerations: list[Vector3D],
        boxes: list[tuple[Vector3D, Vector3D]],
        elapsed: float,
    ) -> tuple[float, Impact] | None:
        """The pair's first impact in the rest of the step, as (time from the step's start,
        impact); two bodies whose swept boxes do not meet cannot collide (the broad phase)."""
        if not _boxes_meet(boxes, pair):
            return None
        impact = time_of_impact(
            self._shape_a(pair),
            self.shape(pair.b),
            self._velocity_a(pair),
            self.velocities[pair.b],
            remaining,
            _ZERO if pair.static else accelerations[pair.a],
            accelerations[pair.b],
        )
        return None if impact is None else (elapsed + impact.time, impact)

    def _advance(self, duration: float, accelerations: list[Vector3D]) -> None:
        """Exact motion under constant acceleration: ``x += v t + a t^2/2``, ``v += a t``."""
        if duration <= 0.0:
            return
        energy_before = self.energy()
        half_t2 = 0.5 * duration * duration
        self.positions = [
            x + v * duration + a * half_t2
            for x, v, a in zip(self.positions, self.velocities, accelerations, strict=True)
        ]
        self.velocities = [v + a * duration for v, a in zip(self.velocities, accelerations, strict=True)]
        self.record.ledger.integrator += self.energy() - energy_before

    def _resting_contacts(self, time: float) -> tuple[list[Vector3D], set[_Pair]]:
        """Resting contacts under gravity, and the accelerations they leave.

        A pair rests when it touches (distance <= ``CONTACT_MARGIN``), its normal velocity is
        below ``REST_SPEED`` and its accelerations press it together. Then an approach is
        stopped (an e = 0 impulse) and the support cancels the pressing part of the
        acceleration: on a static obstacle the body's normal acceleration; between two bodies the
        relative one, taken by the body that is not yet supported (or shared by inverse mass).
        Passes repeat, so a stack settles from its support up (Gauss-Seidel on accelerations).
        Resting pairs are left out of the time-of-impact search for that sub-step.

        The contact force is shared as an impulse would be (:meth:`_response`): a body already
        on a support passes the part along the support's normal on to it, so a support pushes
        only along its own normal. On a curved support (two balls, a ball on a box's edge or
        corner, radius of curvature ``R``) a body sliding at ``v_t`` stays only while
        ``v_t^2 / R`` is below the pressing acceleration (else it flies off); the sub-step is
        then cut to ``sqrt(R CONTACT_MARGIN) / v_t`` and the small drift closed, so the body
        follows the surface instead of hopping along it."""
        gravity = self.scenario.settings.gravity
        accelerations = [gravity] * len(self.bodies)
        resting: set[_Pair] = set()
        self._slide_limit = math.inf
        if gravity == _ZERO:
            return accelerations, resting
        self._supports = {}
        self._slide_limit = math.inf
        for _ in range(len(self.bodies) + 1):  # a stack of k bodies settles in k passes
            changed = False
            for pair in self._pairs:
                sep = self._separation(pair)
                n = sep.normal  # from A to B
                if sep.distance > CONTACT_MARGIN:
                    continue
                relative = self.velocities[pair.b] - self._velocity_a(pair)
                vn = relative.dot(n)
                a_a = _ZERO if pair.static else accelerations[pair.a]
                pressing = (accelerations[pair.b] - a_a).dot(n)
                if abs(vn) > REST_SPEED or pressing >= 0.0:
                    continue
                radius = self._support_radius(pair, n)
                if radius < math.inf:  # a curved support (a ball, a box's edge): can it hold the body?
                    sliding = (relative - n * vn).length()
                    if sliding * sliding / radius > -pressing:
                        continue  # too fast to follow the curve: it leaves the surface, in free flight
                    if sliding > 0.0:  # re-check before the straight path drifts half CONTACT_MARGIN off
                        self._slide_limit = min(self._slide_limit, math.sqrt(radius * CONTACT_MARGIN) / sliding)
                    if sep.distance > 0.0:  # and close the drift, so the gaps of many re-checks do not add up
                        self._close_gap(pair, n, sep.distance)
                if vn < 0.0:  # a slow approach: e = 0 (below REST_SPEED), an event if it is new
                    self._resolve(pair, n, sep.point, time)
                elif vn > 0.0:  # a slow lift-off would float on with gravity cancelled: stop it
                    self._kick(pair, n, functools.partial(_stopping_impulse, vn))
                # The contact force that cancels the pressing acceleration, shared as an impulse
                # would be (a body on a support passes the part along its normal on to it).
                dir_a, inverse_a = (_ZERO, 0.0) if pair.static else self._response(pair.a, -n)
                dir_b, inverse_b = self._response(pair.b, n)
                force = -pressing / (inverse_a + inverse_b)
                if not pair.static:
                    accelerations[pair.a] = accelerations[pair.a] + dir_a * (force / self.bodies[pair.a].mass)
                accelerations[pair.b] = accelerations[pair.b] + dir_b * (force / self.bodies[pair.b].mass)
                if pair.static or pair.a in self._supports:
                    self._supports.setdefault(pair.b, []).append(n)
                elif pair.b in self._supports:
                    self._supports.setdefault(pair.a, []).append(-n)
                resting.add(pair)
                changed = True
            if not changed:
                break
        return accelerations, resting

    # --- running -------------------------------------------------------------------------------
    def run(self, every: int = 1, progress: Callable[[int, int], None] | None = None) -> RunRecord:
        """Run the remaining steps; keep a frame every ``every`` steps (and the first and last).
        ``progress(done, total)`` is called after each step."""
        total = self.scenario.settings.steps
        if not self.record.frames:
            self.record.frames.append(self.frame())
        guard = RangeGuard(self.scenario)  # numbers stay in the range that can be simulated
        while self.step_index < total:
            try:
                self.step()
            except (InvalidInputError, ArithmeticError) as error:
                if not is_overflow(error):
                    raise
                raise guard.overflowed(self.step_index, error) from None
            warning = guard.check(self.step_index, self.time, self.positions, self.velocities)
            if warning:
                self.record.warnings.append(warning)
            if self.step_index % every == 0 or self.step_index == total:
                self.record.frames.append(self.frame())
            if progress is not None:
                progress(self.step_index, total)
        return self.record


def simulate(scenario: Scenario, every: int = 1) -> RunRecord:
    """Run ``scenario`` from the start and return its record.

    >>> from collisionlab import Sphere, Plane
    >>> from collisionlab.model import Body, Obstacle, Settings, Scenario
    >>> ball = Body("ball", Sphere((0, 0.96, 0), 0.5), velocity=(0, -1, 0))
    >>> floor = Obstacle("floor", Plane((0, 0, 0), (0, 1, 0)))
    >>> record = simulate(Scenario(Settings(dt=0.1, steps=10, restitution=0.5), (ball,), (floor,)))
    >>> event = record.events[0]   # y = 0.96 - 0.1 k <= 0.5 first at k = 5 (4.6 rounded up)
    >>> event.step, event.velocities_after["ball"]   # -1 -> +0.5 (lab eq. 24, e = 0.5)
    (5, Vector3D(x=0.0, y=0.5, z=0.0))
    """
    return World(scenario).run(every=every)
