"""How ``collisionlab gas`` prints its report: the table of either mode (with the species, the
observables, the checkpoint and the trajectory), or one JSON object."""

from __future__ import annotations

import argparse
import json
from collections.abc import Callable
from typing import Any

from .gas_common import PROG
from .streams import Streams

__all__ = [
    "checkpoint_lines",
    "compiling_lines",
    "emit_report",
    "exact_table",
    "observed_lines",
    "species_lines",
    "stepped_table",
    "trajectory_line",
]


def stepped_table(report: dict[str, Any]) -> list[str]:
    shape = "discs" if report["dim"] == 2 else "spheres"
    lines = [
        f"{PROG}: {report['n']:,} {shape} in {report['dim']}D, {report['steps']:,} steps "
        f"(seed {report['seed']}, e = {report['restitution']:g}, gravity {report['gravity']:g}, "
        f"dt = {report['dt']:.4g})",
        f"  backend          {report['backend']}",
        *compiling_lines(report),
        f"  stepping         {report['seconds']:.3f} s",
        f"  body-steps/s     {report['body_steps_per_s'] / 1e6:.2f} million",
        f"  collisions       {report['collisions']:,} between balls, {report['wall_collisions']:,} with walls",
        f"  energy drift     {report['energy_drift']:.3e} (relative change of kinetic energy)",
        f"  memory           {report['bytes_per_body']:.0f} bytes per ball",
    ]
    if report.get("plot"):
        lines.append(f"  plot             {report['plot']}")
    lines += trajectory_line(report)
    return lines


def compiling_lines(report: dict[str, Any]) -> list[str]:
    """The table's line for the time spent loading (or compiling) the kernels, when any."""
    seconds = report["compile_seconds"]
    return [f"  compiling        {seconds:.3f} s (before the clock: not in the rates)"] if seconds > 0 else []


def exact_table(report: dict[str, Any]) -> list[str]:
    shape = "discs" if report["dim"] == 2 else "spheres"
    z_theory = report.get("compressibility_theory")
    lines = [
        f"{PROG}: {report['n']:,} {shape} in {report['dim']}D, exact (event-driven), {report['boundary']}, "
        f"fraction {report['fraction']:g}, time {report['sim_time']:g} (seed {report['seed']}, "
        f"e = {report['restitution']:g}, gravity {report['gravity']:g})",
        *compiling_lines(report),
        f"  simulation loop  {report['seconds']:.3f} s",
        f"  collisions       {report['collisions']:,} between balls, {report['wall_collisions']:,} with walls"
        + (f" ({report['collisions_per_s'] / 1e6:.3f} million/s)" if report["collisions_per_s"] else ""),
        f"  kT               {report['kT']:.6g}",
        f"  Z = PV/(N kT)    {report['compressibility']:.5f} (collision virial)"
        + (f", theory {z_theory:.5f}" if z_theory is not None else ""),
    ]
    if "compressibility_walls" in report:
        lines.append(f"  Z from walls     {report['compressibility_walls']:.5f} (momentum given to the walls)")
    rate_theory = report.get("collision_rate_enskog")
    lines += [
        f"  collision rate   {report['collision_rate']:.5g} per ball per unit time"
        + (f", Enskog {rate_theory:.5g}" if rate_theory is not None else ""),
        f"  energy drift     {report['energy_drift']:.3e} (relative change of the total energy)",
        f"  max overlap      {report['max_overlap']:.3e} diameters",
        f"  memory           {report['bytes_per_body']:.0f} bytes per ball",
    ]
    lines += species_lines(report)
    lines += observed_lines(report)
    lines += checkpoint_lines(report)
    if report.get("events_file"):
        lines.append(f"  events           {report['events_file']}")
    lines += trajectory_line(report)
    if report.get("plot"):
        lines.append(f"  plot             {report['plot']}")
    return lines


def species_lines(report: dict[str, Any]) -> list[str]:
    """A mixture's lines: each species, then each ordered pair's collision rate."""
    lines = [
        f"  species {sp['name']:<8} {sp['count']:,} balls, radius {sp['radius']:g}, mass {sp['mass']:g}, "
        f"kT {sp['kT']:.6g}"
        for sp in report.get("species", ())
    ]
    for pair in report.get("pair_collision_rates", ()):
        theory = pair["rate_enskog"]
        a, b = pair["species"]
        lines.append(
            f"  rate {a} -> {b} ".ljust(19)
            + f"{pair['rate']:.5g} per {a} ball per unit time"
            + (f", Enskog {theory:.5g}" if theory is not None else "")
        )
    return lines


def observed_lines(report: dict[str, Any]) -> list[str]:
    """``--observe``'s lines: g's contact values and Z from them, the self-diffusion."""
    lines = []
    if "rdf" in report:
        for pair in report["rdf"]["pairs"]:
            a, b = pair["species"]
            lines.append(f"  g({a}-{b}) contact   {pair['contact']:.5g} at r = {pair['sigma']:g}")
        window = report.get("compressibility_window")
        lines.append(
            f"  Z from g(sigma)  {report['compressibility_contact']:.5f}"
            + (f", collisions over the same window {window:.5f}" if window is not None else "")
        )
    if "msd" in report:
        diffusion, enskog = report["diffusion"], report["diffusion_enskog"]
        lines.append(
            "  self-diffusion   "
            + (f"{diffusion:.5g}" if diffusion is not None else "n/a")
            + (f", Enskog {enskog:.5g}" if enskog is not None else "")
            + f" (MSD at {len(report['msd']['t'])} times)"
        )
    return lines


def checkpoint_lines(report: dict[str, Any]) -> list[str]:
    """The checkpoint written and, for a continued run, the one it started from."""
    lines = []
    if "resumed_from" in report:
        lines.append(f"  resumed from     {report['resumed_from']} at time {report['resumed_at']:g}")
    if "checkpoint" in report:
        lines.append(f"  checkpoint       {report['checkpoint']} ({report['checkpoints_written']} written)")
    return lines


def trajectory_line(report: dict[str, Any]) -> list[str]:
    if not report.get("trajectory"):
        return []
    return [f"  trajectory       {report['trajectory']} ({report['trajectory_frames']} frames)"]


def emit_report(
    args: argparse.Namespace,
    streams: Streams,
    report: dict[str, Any],
    table: Callable[[dict[str, Any]], list[str]] = exact_table,
) -> int:
    """Print a gas run's report as ``--format`` asks (JSON, or the ``table``: an exact run's by
    default); exit status 0."""
    if args.format == "json":
        streams.out(json.dumps(report))
    else:
        for line in table(report):
            streams.out(line)
    return 0
