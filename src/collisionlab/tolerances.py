"""The one home of every numerical tolerance in collisionlab.

Each constant has a unit (or is dimensionless) and a reason. Code elsewhere imports these
names; no bare epsilon literal appears anywhere else in the package.
"""

from __future__ import annotations

__all__ = [
    "APPROACH_ROUNDING",
    "BROADPHASE_WIDEN",
    "COLLINEAR_SINE",
    "CONTACT_MARGIN",
    "CONTACT_SLOP",
    "FALLBACK_NORMAL",
    "ISCLOSE_REL_TOL",
    "MAX_RUN_SPEED",
    "PICTURE_MIN_SPAN",
    "REST_SPEED",
    "SLEEP_SPEED",
    "SLEEP_TIME",
    "SOLVER_MARGIN",
    "SOLVER_TOLERANCE",
    "START_GAP",
    "TOI_GAP",
    "TOI_TOUCH",
]

#: Dimensionless. Three plane points are collinear when the sine of the angle between the two
#: edges ``b - a`` and ``c - a`` is at most this. Relative, so it is scale free: points 1e-6 apart
#: and points 1e6 apart are judged alike. 1e-12 is ~4500 ulp of 1.0, far above rounding noise
#: of one cross product and far below any plane a person means to give.
COLLINEAR_SINE: float = 1e-12

#: The unit axis used as contact normal when the two features coincide (coincident centres,
#: a centre exactly on a line): ``(1, 0, 0)``, pointing from shape A to shape B.
FALLBACK_NORMAL: tuple[float, float, float] = (1.0, 0.0, 0.0)

#: Dimensionless. The default relative tolerance of ``Vector3D.isclose``: two vectors are close
#: when they differ by at most this fraction of the longer one's length. The same default as
#: :func:`math.isclose`: about 4500 ulp, above the rounding of a few operations, far below any
#: difference a person means.
ISCLOSE_REL_TOL: float = 1e-9

#: Metres. After a collision is resolved, overlapping bodies are pushed apart until they are
#: separated by this gap, so the same pair is not detected again on the next step (no double
#: bounce). Relative to nothing: scenes are expected in metres at human scale. Box2D's linear
#: slop is 5 mm; ours is much smaller because we push apart fully rather than softly.
CONTACT_SLOP: float = 1e-9

#: Metres. The many-body world (``collisionlab.particles``) gives the impulse solver every pair
#: closer than ``r_a + r_b + SOLVER_MARGIN`` (and ball-wall gap below it), not only overlapping
#: ones: twice ``CONTACT_SLOP``, so that balls left ``CONTACT_SLOP`` apart by push-apart stay in
#: contact the next step. Without it a resting stack under gravity has no contacts between its
#: balls, the floor's impulse cannot reach up the stack, and the stack sinks into deep overlaps.
#: Only impulses see it (a pair approaching at a gap below 2 nm bounces now); push-apart still
#: acts on true overlaps only.
SOLVER_MARGIN: float = 2e-9

#: Metres per second. A contact whose approach speed along the normal is below this stops
#: bouncing (restitution is treated as 0), so a ball under gravity comes to rest instead of
#: making an endless run of ever smaller bounces. Box2D's restitution threshold is 1 m/s; ours
#: is small so that the lab's constant-velocity cases are never affected.
REST_SPEED: float = 1e-3


#: Metres per second. The contact solver (``contacts = "solve"``) iterates its impulses until no
#: contact's projected gradient (how far its normal velocity misses its target, where it pushes
#: or would need to) exceeds this: far below any speed a scene means (a body creeping at it for
#: a day moves 0.1 um) and above the rounding of an iteration at human scale (about 1e-16 m/s per
#: m/s of speed).
SOLVER_TOLERANCE: float = 1e-9

#: Metres per second and seconds. The contact solver puts an island of bodies to sleep when it
#: rests on a static and every body in it has stayed slower than ``SLEEP_SPEED`` for
#: ``SLEEP_TIME`` (Box2D's ``b2_timeToSleep`` and threshold, 0.5 s and 5 cm/s). What kinetic
#: energy the island still had is booked as a collision loss. A body that floats free never
#: sleeps, however slow: it drifts on, as it should.
SLEEP_SPEED: float = 5e-2
SLEEP_TIME: float = 0.5

#: Metres. A pair that has collided stays "in contact" (its next impulse is not a new impact
#: and is not reported again) until its distance grows beyond this. It also decides when a body
#: lies on a static obstacle (resting contact, exact mode). Larger than ``CONTACT_SLOP`` so that
#: the push-apart gap never reads as a separation.
CONTACT_MARGIN: float = 1e-7

#: Metres. The smallest extent a picture's view covers: a scene that does not move (or a single
#: point) still gets a view of this size, so no axis or aspect ratio divides by zero.
PICTURE_MIN_SPAN: float = 1e-6

#: Dimensionless. The broad phase's quick test of two balls compares squared distances, which
#: round differently from the narrow phase's distance; it is widened by this relative amount so
#: that it never rejects a pair the exact test would accept (it only lets a few more through).
BROADPHASE_WIDEN: float = 1e-12

#: Dimensionless. A mixture too dense for a lattice starts with its balls spread apart
#: (:mod:`collisionlab.edmd.spread`) until no two are closer than ``(r_i + r_j)(1 + START_GAP / 2)``,
#: each pair that was pushed to ``(r_i + r_j)(1 + START_GAP)``: relative, so it holds at any
#: size. Pushing pairs a little past touching takes a third of the sweeps of pushing them to
#: touching (a binary of radii 1 and 0.5 at fraction 0.5: 95 sweeps against 341 at 1e-9), and
#: 0.1% of a diameter is gone in the run's first collisions.
START_GAP: float = 1e-3

#: Metres. The exact stepper's time of impact (conservative advancement) stops when the two
#: shapes are this close: far below ``CONTACT_SLOP`` (so an impact is resolved before any push-apart
#: would be needed) and above the rounding of positions in scenes of up to about a kilometre
#: (1e-13 m at 1e3 m). Past that scale the iteration's cap ends it a little early instead, which
#: is conservative: the impact is resolved at a gap below ``CONTACT_MARGIN``, never after it.
TOI_GAP: float = 1e-12

#: Dimensionless. The scalar :func:`collisionlab.time_of_impact` runs the exact stepper's time of
#: impact to a gap of 0 in a frame scaled (by powers of two) to the pair's size; when the
#: iteration's cap ends it first, the shapes count as touching if their gap is at most this many
#: times that size: 2^-40 ~ 9e-13, a few thousand ulp of 1.0 (the gap's own rounding is a few
#: ulp), so a touch is accepted only at the precision of doubles. A larger gap is followed on.
TOI_TOUCH: float = 2.0**-40

#: Dimensionless. The exact stepper's approach speed ``v_n = (v_b - v_a) . n`` of a pair is taken
#: as zero when ``|v_n|`` is at most this times ``|v_a| + |v_b|``: the rounding of the dot product
#: and of the impulse that set it (an e = 0 impact of an oblique pair leaves ``v_n`` ~ 1e-17 m/s
#: at 1 m/s). Kicking such a pair calls for an impulse below one ulp of the velocities, which
#: changes nothing, so without this floor the pair would be kicked again without end.
#: 16 ulp of 1.0: above the rounding of a 3-term dot product of differences, far below any
#: approach a scene means (1e-15 m/s at 1 m/s).
APPROACH_ROUNDING: float = 16 * 2.0**-52

#: Metres per second. The fastest a body may move during a run (``limits.MAX_RUN_SPEED``, the
#: same number): beyond it the run stops with ``OutOfRangeError`` (a restitution above 1 pumping
#: speed up without bound). Here because the exact stepper's kernels check it, and the kernels
#: read only this file of the package's policies.
MAX_RUN_SPEED: float = 1e12
