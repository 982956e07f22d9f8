"""Forward Euler's impulses (phase 5 of :mod:`.step_kernels`, whose docstring gives the rules):
contact after contact in the order of :mod:`.contact_order`, each from the current velocities
(sequential impulses), swept again while a sweep applies one; an impulse on a pair that was not
already in contact is a collision event (:mod:`.event_rows`), unless it rests on a support
(:func:`_impulses`).

It imports :mod:`.contact_law`, :mod:`.non_literal`, :mod:`.pair_separation` and
:mod:`.event_rows`; it must not import the loop (:mod:`.step_kernels`), which calls it.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

if "_EVENT_ROWS" in globals():  # the compiled copy: the kernels it calls are compiled too
    evr: Any = globals()["_EVENT_ROWS"]
    cl: Any = globals()["_CONTACT_LAW"]
    nl: Any = globals()["_NON_LITERAL"]
    ps: Any = globals()["_PAIR_SEPARATION"]
else:
    from . import contact_law as cl
    from . import event_rows as evr
    from . import non_literal as nl
    from . import pair_separation as ps

__all__: list[str] = []  # helpers of the steppers' loops: nothing here is public


def _impulses(
    kind: Any,
    pos: Any,
    vel: Any,
    ext: Any,
    ima: Any,
    eb: Any,
    ids: Any,
    s_kind: Any,
    s_a: Any,
    s_b: Any,
    s_e: Any,
    ca: Any,
    cb: Any,
    cd: Any,
    cn: Any,
    touching: Any,
    seen: Any,
    changed: Any,
    clock: int,
    e_default: float,
    rest_speed: float,
    gravity: Any,
    dt: float,
    solver_margin: float,
    first_pass: bool,
    step: int,
    time: float,
    record: bool,
    events: Any,
    event_count: Any,
    event_of: Any,
    largest: Any,
    ledger: Any,
) -> Any:
    """One pass of impulses over the contacts, stored in the order they are resolved, each along
    its normal ``cn`` (found with the contacts: positions do not change while impulses are
    applied); returns the event buffer (grown if it had to be). ``event_count[1]`` counts the
    impulses this pass applied; ``event_of[k]`` gets the contact of the pass's k-th event;
    ``largest[0]`` is raised to the largest change of a body's speed an impulse makes.

    After the first pass a contact is looked at again only if the velocity of one of its bodies
    changed since it was last looked at: ``changed[body]`` is the tick of the body's last impulse,
    ``seen[c]`` that of the contact's last look (``_NEVER`` if none), and contact ``c`` looks at
    tick ``clock + c`` in this pass (ticks only grow). Its result could not differ from the last
    one, which applied nothing (an impulse changes the pair's own velocities), so skipping it
    changes no number."""
    before = np.zeros(6)
    first_event = event_count[0]
    for c in range(cd.shape[0]):
        b = cb[c]
        if not first_pass and changed[b] < seen[c]:
            a = ca[c]
            if a < 0 or changed[a] < seen[c]:
                continue  # neither velocity changed since this contact was last looked at
        if cd[c] < 0.0 and (touching[c] == 0 or cd[c] < -solver_margin):
            # Apart: a new impact needs contact (lab eqs. 2, 7, 9); a pair already in contact
            # keeps its impulses within solver_margin, so a resting stack stays supported.
            continue
        a = ca[c]
        ima_a = ima[a] if a >= 0 else 0.0
        inv_sum = ima_a + ima[b]
        if inv_sum == 0.0:
            continue
        tick = clock + c
        seen[c] = tick
        nx = cn[c, 0]
        ny = cn[c, 1]
        nz = cn[c, 2]
        vax = vel[a, 0] if a >= 0 else 0.0
        vay = vel[a, 1] if a >= 0 else 0.0
        vaz = vel[a, 2] if a >= 0 else 0.0
        vn = (vel[b, 0] - vax) * nx + (vel[b, 1] - vay) * ny + (vel[b, 2] - vaz) * nz
        id_a = ids[a] if a >= 0 else a
        if vn >= 0.0:
            if record and first_pass and touching[c] == 0 and cd[c] >= 0.0:
                for k in range(6):
                    before[k] = 0.0
                code = nl._int(evr.EVENT_SKIPPED)
                sep = ps._contact_separation(kind, pos, ext, s_kind, s_a, s_b, a, b)
                events = evr._write_event(
                    events, event_count[0], code, step, time, id_a, ids[b], sep, vn, 0.0, 0.0, before, vel, a, b
                )
                event_of[event_count[0] - first_event] = c
                event_count[0] += 1
            continue
        e_pair = ps._pair_e(eb[a] if a >= 0 else s_e[-1 - a], eb[b], e_default)
        # Resting: an approach no faster than gravity along n gives in one step (plus rest_speed)
        # is a body pressed onto its support, not an impact: no event. And a bounce is kept only
        # if it would rise above the depth one step of approach makes, e^2 v^2 / (2 g_n) >= v dt,
        # else e = 0: shorter hops are numerical (Forward Euler and push-apart feed them).
        # Only a support that does not fall (a static, a kinematic body) holds a body up: two free
        # bodies fall together, and gravity adds nothing to their approach. Unless they already
        # touch: then one is held up by what is under it (a stack, a pile), and the approach the
        # passes leave between them is at most what gravity gives in one step; bouncing it would
        # make a resting stack jitter.
        supported = a < 0 or ima[a] == 0.0 or ima[b] == 0.0 or touching[c] == 1
        g_dt = abs(gravity[0] * nx + gravity[1] * ny + gravity[2] * nz) * dt if supported else 0.0
        resting = rest_speed + g_dt
        squared = e_pair * e_pair
        if g_dt == 0.0:
            bounce_floor = rest_speed
        elif squared > 0.0:
            bounce_floor = rest_speed + 2.0 * g_dt / squared
        else:
            bounce_floor = math.inf
        e = cl.applied_restitution(vn, e_pair, bounce_floor)
        j = cl.impulse_magnitude(vn, inv_sum, e)
        ja = j * ima_a
        jb = j * ima[b]
        largest[0] = max(largest[0], abs(ja), abs(jb))
        kinetic_before = 0.0
        kinetic_after = 0.0
        before[0] = vax
        before[1] = vay
        before[2] = vaz
        before[3] = vel[b, 0]
        before[4] = vel[b, 1]
        before[5] = vel[b, 2]
        if a >= 0 and ima_a > 0.0:
            kinetic_before += (vax * vax + vay * vay + vaz * vaz) / ima_a
            vel[a, 0] = cl.pushed_velocity(vax, -j, ima_a, nx)
            vel[a, 1] = cl.pushed_velocity(vay, -j, ima_a, ny)
            vel[a, 2] = cl.pushed_velocity(vaz, -j, ima_a, nz)
            kinetic_after += (vel[a, 0] * vel[a, 0] + vel[a, 1] * vel[a, 1] + vel[a, 2] * vel[a, 2]) / ima_a
            changed[a] = tick
        if ima[b] > 0.0:
            kinetic_before += (before[3] * before[3] + before[4] * before[4] + before[5] * before[5]) / ima[b]
            vel[b, 0] = cl.pushed_velocity(before[3], j, ima[b], nx)
            vel[b, 1] = cl.pushed_velocity(before[4], j, ima[b], ny)
            vel[b, 2] = cl.pushed_velocity(before[5], j, ima[b], nz)
            kinetic_after += (vel[b, 0] * vel[b, 0] + vel[b, 1] * vel[b, 1] + vel[b, 2] * vel[b, 2]) / ima[b]
            changed[b] = tick
        ledger[1] += 0.5 * (kinetic_after - kinetic_before)
        ledger[3] -= cl.collision_loss(vn, inv_sum, e)
        if a >= 0:
            ledger[5] += 1.0
        else:
            ledger[6] += 1.0
        event_count[1] += 1
        if touching[c] == 0:
            touching[c] = 1
            if record and cl.is_impact(vn, resting):
                sep = ps._contact_separation(kind, pos, ext, s_kind, s_a, s_b, a, b)
                events = evr._write_event(
                    events,
                    event_count[0],
                    evr.EVENT_IMPACT if cl.is_impact(vn, bounce_floor) else evr.EVENT_BELOW_REST,
                    step,
                    time,
                    id_a,
                    ids[b],
                    sep,
                    vn,
                    j,
                    e,
                    before,
                    vel,
                    a,
                    b,
                )
                event_of[event_count[0] - first_event] = c
                event_count[0] += 1
    return events
