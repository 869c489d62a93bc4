"""``jaxform run NAME|CASE.toml --out DIR``: a hemisphere forming run with frames, summary and plots.

Writes into DIR: ``frames.pvd`` with ``frames_#####.vtu`` (deformed positions in m; point fields
named with their unit, :data:`FIELD_UNITS`: displacement, shear angle, fibre strain and bending
moment per family, M_f^RMS, contact pressure, deviation from the tools, ply id), ``summary.json`` (SPEC section 6 keys, inputs, energy and
force histories, draw-in, versions) and PNG plots. The summary is written at the start with
``complete: false`` and rewritten at the end; an interrupted (Ctrl-C) or failed run keeps the frames
written so far and says why in ``reason``.
"""
from __future__ import annotations

import pathlib
import sys
import time

from jaxform.cli.progress import Progress

FIELD_UNITS = {
    "displacement_m": "m", "shear_angle_deg": "degree", "fibre_strain": "dimensionless (|g_f| - 1)",
    "bending_moment_N": "N (N·m/m)", "M_f_rms_N": "N", "contact_pressure_Pa": "Pa", "deviation_m": "m",
    "ply_id": "-",
}
"""The VTU point fields of a frame: each name ends with its unit (as in ``wrinkles.vtu``)."""


OUTPUTS = ("frames_*.vtu", "frames.pvd", "summary.json", "shear_angle.png", "deviation.png", "punch_force.png")
"""What a run writes into its folder (a rerun replaces all of it)."""
HALF_SPEED = "half_speed"
"""The sub-folder of ``--verify-quasi-static``'s half-speed run (a run folder of its own)."""
NOT_QUASI_STATIC = 3
"""Exit status of a complete run that ``--verify-quasi-static`` finds not quasi-static (or cannot check)."""


def add_parser(subparsers) -> None:
    p = subparsers.add_parser(
        "run",
        help="run a hemisphere forming case (a preset name or a CASE.toml)",
        description=__doc__,
    )
    p.add_argument("case", help="preset name (see 'jaxform cases') or a case .toml file")
    p.add_argument("--out", type=pathlib.Path, required=True, help="output directory")
    p.add_argument("--element-size-mm", type=float, default=None, help="override blank.element_size_mm")
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                   help="override a case key, e.g. --set process.speed_mm_per_s=250 (repeatable)")
    p.add_argument("--force", action="store_true", help="write into a non-empty directory")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument("--verify-quasi-static", action="store_true",
                   help=f"also run the case at half the punch speed (into OUT/{HALF_SPEED}) and report the differences "
                        "(shear-angle map, edge draw-in, flange wrinkles) in summary.json under 'quasi_static_check'; "
                        f"exit status {NOT_QUASI_STATIC} when they exceed the limits")
    p.set_defaults(handler=run)


def point_data(fields: dict, ply_id) -> dict:
    """The VTU point fields of a frame, named with their unit (:data:`FIELD_UNITS`)."""
    import numpy as np

    return {
        "displacement_m": fields["displacement"],
        "shear_angle_deg": np.degrees(fields["shear_angle"]),
        "fibre_strain": fields["fibre_strain"],
        "bending_moment_N": fields["bending_moment"],
        "M_f_rms_N": fields["M_f_rms"],
        "contact_pressure_Pa": fields["contact_pressure"],
        "deviation_m": fields["deviation"],
        "ply_id": np.asarray(ply_id),
    }


def execute(case, out, *, force=False, quiet=False, stream=None, element_size=None, overrides=(), owner="run",
            **build_kwargs):
    """Run ``case`` writing everything into ``out``; returns ``(result, written_paths)``.

    Shared by ``jaxform run`` and ``jaxform demo``. The case is normalised once and the rig built
    once; the frames, the summary and the plots read what the rig built. Never raises for a failed
    or interrupted run: the result says ``complete=False`` and why.
    """
    from jaxform import cases, forming
    from jaxform.cli import use_case_dtype
    from jaxform.io.frames import FrameWriter, write_json
    from jaxform.io.output import prepare_output_dir

    case = cases.resolve(case, element_size=element_size, overrides=overrides)
    use_case_dtype(case)
    out = prepare_output_dir(out, force=force, owner=owner, replaces=OUTPUTS)
    summary_path = out / "summary.json"
    t0 = time.perf_counter()

    def early_summary(reason):
        return {"complete": False, "reason": reason, "case": case.name, "inputs": cases.to_dict(case),
                "max_ke_ie": None, "max_shear_angle_deg": None, "wall_time_s": time.perf_counter() - t0}

    write_json(summary_path, early_summary("running (or killed before it could say why)"))
    progress = Progress(stream=stream, quiet=quiet)
    try:
        rig = forming.build(case, **build_kwargs)
    except BaseException as err:  # set-up errors (before the first frame): say so in the summary
        write_json(summary_path, early_summary(f"error before the run started: {err}"))
        raise
    writer = FrameWriter(out, rig.info.faces, stem="frames")

    def on_frame(k, t, x, fields):
        writer.write(t, x, point_data(fields, rig.info.ply_id))

    progress.start(rig.info.n_steps, case.name)
    try:
        result = forming.run(rig, on_frame=on_frame, on_progress=progress, catch=True)
    finally:
        progress.done()
    result.wall_time_s = time.perf_counter() - t0
    result.summary["wall_time_s"] = result.wall_time_s
    written = [writer.pvd_path] if len(result.t) else []
    if len(result.t) >= 1:
        written += save_plots(result, out)
    write_json(summary_path, result.summary)
    written.insert(0, summary_path)
    return result, written


def save_plots(result, out):
    """The run's PNG plots in ``out`` (shear map, deviation map, punch force); returns their paths."""
    from jaxform.plots import forming as fplots
    from jaxform.plots.fields import save

    paths = [save(fplots.shear_map(result), out / "shear_angle.png"),
             save(fplots.deviation_map(result), out / "deviation.png")]
    if len(result.history["t_s"]) >= 2:
        paths.append(save(fplots.punch_force_curve(result), out / "punch_force.png"))
    return paths


def verify_quasi_static(result, out, *, force=False, quiet=False, stream=None) -> dict:
    """Run ``result``'s case again at half its punch speed into ``out/half_speed`` and record the
    comparison (:func:`jaxform.forming.quasi_static_check`) in ``out/summary.json`` under
    ``quasi_static_check``; returns it. An incomplete run is not checked (the record says so)."""
    from jaxform import cases, forming
    from jaxform.io.frames import write_json

    out = pathlib.Path(out)
    if not result.complete:
        check = {"quasi_static": False, "reason": f"the run is incomplete ({result.reason}): not checked"}
    else:
        case = result.info.case
        half_case = cases.apply_overrides(case, [f"process.speed_mm_per_s={0.5e3 * float(case.process.speed)!r}"])
        half, _ = execute(half_case, out / HALF_SPEED, force=force, quiet=quiet, stream=stream, owner="run")
        check = forming.quasi_static_check(result, half)
        check.update(half_speed_dir=str(out / HALF_SPEED), half_speed_wall_time_s=half.wall_time_s)
    result.summary["quasi_static_check"] = check
    write_json(out / "summary.json", result.summary)
    return check


def _remove_stale_half_speed(out):
    """A run without ``--verify-quasi-static`` removes the half-speed folder an earlier run of
    ``jaxform run`` left there (only its own outputs), so that it is never read as this run's."""
    from jaxform.io.output import MARKER, remove_outputs, written_by

    sub = pathlib.Path(out) / HALF_SPEED
    if not written_by(sub, "run"):
        return
    remove_outputs(sub, OUTPUTS)
    (sub / MARKER).unlink()
    if not any(sub.iterdir()):
        sub.rmdir()


def report_check(check, stream):
    """Print a :func:`jaxform.forming.quasi_static_check` (``half_speed_dir`` in it) as ``jaxform run`` does."""
    lim = check.get("limits", {})
    if check.get("shear_p95_deg") is None:
        print(f"  quasi-static check: NOT made: {check.get('reason')}", file=stream)
        return
    verdict = "quasi-static" if check["quasi_static"] else "NOT quasi-static"
    print(f"  quasi-static check against half the speed ({check['half_speed_mm_per_s']:g} mm/s, "
          f"in {check['half_speed_dir']}): shear-angle map {check['shear_p95_deg']:.2f}° at the 95th percentile "
          f"(limit {lim['shear_p95_deg']:g}°), edge draw-in {100 * check['draw_in_edge_mid_rel']:.2f} % "
          f"(limit {100 * lim['draw_in_edge_mid_rel']:g} %), flange wrinkles {check['flange_wrinkles'][0]} vs "
          f"{check['flange_wrinkles'][1]}: {verdict}", file=stream)
    to, per, depth = check.get("shear_agrees_to_punch_mm"), check.get("shear_p95_deg_per_frame"), check.get("punch_mm_per_frame")
    if per and max(per) >= lim["shear_p95_deg"]:
        over = ", ".join(f"{v:.2f}° at {d:.1f} mm" for v, d in zip(per, depth) if v >= lim["shear_p95_deg"])
        print(f"  along the stroke: the shear maps part for good after {0.0 if to is None else to:.1f} mm of punch "
              f"travel; beyond {lim['shear_p95_deg']:g}°: {over}", file=stream)
    if check.get("cause"):
        print(f"  why: {check['cause']['text']}", file=stream)


def report(result, written, out, stream=None):
    stream = stream or sys.stdout
    s = result.summary
    state = "complete" if result.complete else f"INCOMPLETE ({result.reason})"
    if result.complete and s.get("warnings"):
        state += f", with warnings ({', '.join(s['warnings'])}; below): not the converged answer as it stands"
    print(f"{s['case']}: {state}; {s['frames_written']} frames, wall time {s['wall_time_s']:.1f} s", file=stream)
    if s.get("max_shear_angle_deg") is not None:
        print(f"  max shear angle {s['max_shear_angle_deg']:.1f}°", end="", file=stream)
        di = s.get("draw_in")
        if di:
            print(f", draw-in {di['edge_mid_m'] * 1e3:.1f} mm (edge mid-sides) / {di['corner_m'] * 1e3:.1f} mm "
                  f"(corners)", end="", file=stream)
        if s.get("max_ke_ie") is not None:
            print(f", max KE/IE {s['max_ke_ie']:.3g}", end="", file=stream)
        print(file=stream)
    n = s.get("numerics") or {}
    if n.get("dt_governed_by"):
        fm = n.get("fibre_mass_scaling", 1.0)
        safety = "from the given stiffness" if n.get("contact_safety") is None else f"{n['contact_safety']:.3g}"
        mass = "off" if fm == 1.0 else f"x{fm:g}" + (" (auto)" if n.get("fibre_mass_choice") == "auto" else "") + (
            " with its momentum term" if n.get("fibre_mass_momentum_term") else "") + (
            f" (from step {n['fibre_mass_momentum_term_from_step']}: a chunk failed without it)"
            if n.get("fibre_mass_momentum_term_from_step") is not None else "")
        normal = " (normal forces backward)" if n.get("contact_implicit_normal") else ""
        print(f"  numerics: step {n['dt_s']:.3g} s x {n['n_steps']} (set by the {n['dt_governed_by']}), contact safety "
              f"{safety}{normal}, fibre mass {mass}, punch {1e3 * n['punch_speed_m_per_s']:g} mm/s "
              f"({n.get('speed_choice', 'given')})", file=stream)
    for f in s.get("findings") or []:
        print(f"  {f['level']}: {f['text']}", file=stream)
    if "quasi_static_check" in s:
        report_check(s["quasi_static_check"], stream)
    print(f"Wrote to {pathlib.Path(out).resolve()}:", file=stream)
    for p in written:
        print(f"  {p}", file=stream)


def run(args) -> int:
    result, written = execute(args.case, args.out, force=args.force, quiet=args.quiet,
                              element_size=None if args.element_size_mm is None else args.element_size_mm * 1e-3,
                              overrides=args.overrides)
    check = None
    if args.verify_quasi_static:
        check = verify_quasi_static(result, args.out, force=args.force, quiet=args.quiet)
    else:
        _remove_stale_half_speed(args.out)
    report(result, written, args.out)
    if result.complete:
        return 0 if check is None or check["quasi_static"] else NOT_QUASI_STATIC
    from jaxform.cli import TERMINATED

    if result.reason == TERMINATED:
        return 143
    if result.reason and "KeyboardInterrupt" in result.reason:
        return 130
    return 1
