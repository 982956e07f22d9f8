"""The engine: one world that owns its state in arrays and steps it, the lab's way (Forward
Euler) or exactly.

* :mod:`.geometry_kernels` - the narrow phase and two balls' time of impact as scalar kernels,
  written once: the scalar API calls them as Python, the steppers compiled.
* :mod:`.contact_law` - the contact law, each rule once (restitution, impulse, velocity update,
  the ledger's loss term), the same way.
* :mod:`.params` - :class:`WorldParams`, every tunable of a world in one typed object.
* :mod:`.state` - the structure of arrays a world steps, built from a scenario.
* :mod:`.step_kernels` - the Forward Euler stepper over arrays: its loop; one file per phase it
  calls, :mod:`.broad_phase_grid` (the grid), :mod:`.broad_phase_pairs` (the candidate pairs),
  :mod:`.contact_order` (contacts in a geometric order), :mod:`.touching_memory`,
  :mod:`.euler_impulses` (sequential impulses), :mod:`.euler_push_apart` and
  :mod:`.euler_clamps`; below them, for every stepper, :mod:`.pair_separation` (the kinds and a
  pair's separation), :mod:`.event_rows` (the events) and :mod:`.non_literal`.
* :mod:`.compiled` - the same kernels compiled by numba, for large worlds.
* :mod:`.ahead` - the compiled kernels loaded (or compiled) ahead of a run, timed apart from it,
  and ``--kernels``' choices.
* :mod:`.stepper` - :class:`~.stepper.EulerStepper`: what a Forward Euler run keeps between
  calls (scratch, the pairs in contact, buffers) and the one call that advances it.
* :mod:`.exact_kernels` - the exact stepper over the same arrays (times of impact within each
  step, earliest first from an event calendar): its loop; one file per phase it calls,
  :mod:`.exact_sweeps` (the candidates' bounds), :mod:`.exact_rest` (resting contacts),
  :mod:`.pair_time_of_impact`, :mod:`.exact_impacts` (impacts in time order),
  :mod:`.exact_settle` (what an impact touches, settled), :mod:`.exact_step_end`,
  :mod:`.exact_impulses` and :mod:`.exact_flight`; :mod:`.exact_stepper` keeps its state
  between calls.
* :mod:`.contact_kernels` - exact mode with ``contacts = "solve"``: impacts at their time of
  impact, slow and resting contacts solved together at mid-step (warm-started MPRGP,
  then APGD), bodies at rest asleep: its loop; one file per concept it calls,
  :mod:`.contact_candidates`, :mod:`.contact_flight`, :mod:`.contact_time_of_impact`,
  :mod:`.contact_impacts` (impacts in time order), :mod:`.contact_solver` (the mid-step solve),
  :mod:`.contact_qp` (its quadratic program), :mod:`.contact_memory`, :mod:`.contact_push_apart`
  and :mod:`.contact_islands` (islands and sleep); :mod:`.contact_stepper` keeps its state
  between calls.
* :mod:`.event_heap` - the exact steppers' event calendar.
* :mod:`.event_stepper` - balls in a box run event by event (the loop of
  :mod:`collisionlab.edmd`: neighbour lists, an event calendar), for ``mode = "exact"``.
* :mod:`.world` - :class:`World`: owns the state, steps it, records what happened and tells it
  to an observer as it happens.
  Its bases: :mod:`.world_runs` (runs in chunks of steps) and :mod:`.world_readings` (what it
  reads of its state).
"""

from __future__ import annotations

from .params import WorldParams

__all__ = ["WorldParams"]
