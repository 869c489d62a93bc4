"""``jaxform run NAME|CASE.toml --out DIR``: a hemisphere forming run with frames, summary and plots.

Writes into DIR: ``frames.pvd`` with ``frames_#####.vtu`` (deformed positions; point fields
displacement, shear angle, fibre strain and bending moment per family, M_f^RMS, contact pressure,
deviation from the tools, ply id), ``summary.json`` (SPEC section 6 keys, inputs, energy and
force histories, draw-in, versions) and PNG plots. The summary is written at the start with
``complete: false`` and rewritten at the end; an interrupted (Ctrl-C) or failed run keeps the frames
written so far and says why in ``reason``.
"""
from __future__ import annotations

import pathlib
import sys
import time

FIELD_UNITS = {
    "displacement": "m", "shear_angle_deg": "degree", "fibre_strain": "-", "bending_moment": "N (N·m/m)",
    "M_f_rms": "N", "contact_pressure": "Pa", "deviation": "m", "ply_id": "-",
}


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
    p.set_defaults(handler=run)


class Progress:
    """A one-line progress bar on stderr: percent, punch displacement, elapsed time and ETA."""

    def __init__(self, stream=None, width: int = 28, quiet: bool = False):
        self.stream = stream or sys.stderr
        self.width = width
        self.quiet = quiet
        self.first = None  # (steps, elapsed) at the first report (after compilation)
        self.last_len = 0

    def __call__(self, step, n_steps, t, disp, elapsed):
        if self.quiet:
            return
        if self.first is None:
            self.first = (step, elapsed)
            eta = None
        else:
            s0, e0 = self.first
            rate = (elapsed - e0) / max(step - s0, 1)
            eta = rate * (n_steps - step)
        frac = step / max(n_steps, 1)
        bar = "#" * int(frac * self.width)
        eta_s = "--" if eta is None else _hms(eta)
        line = (f"\r[{bar:<{self.width}}] {100 * frac:5.1f}%  punch {disp * 1e3:6.2f} mm  "
                f"elapsed {_hms(elapsed)}  ETA {eta_s}")
        self.stream.write(line + " " * max(0, self.last_len - len(line)))
        self.stream.flush()
        self.last_len = len(line)

    def done(self):
        if not self.quiet and self.last_len:
            self.stream.write("\n")
            self.stream.flush()


def _hms(s: float) -> str:
    s = max(0, int(round(s)))
    h, r = divmod(s, 3600)
    m, s = divmod(r, 60)
    return f"{h:d}:{m:02d}:{s:02d}" if h else f"{m:d}:{s:02d}"


def point_data(fields: dict, ply_id) -> dict:
    """The VTU point fields of a frame (names with their unit in :data:`FIELD_UNITS`)."""
    import numpy as np

    out = {
        "displacement": fields["displacement"],
        "shear_angle_deg": np.degrees(fields["shear_angle"]),
        "fibre_strain": fields["fibre_strain"],
        "bending_moment": fields["bending_moment"],
        "M_f_rms": fields["M_f_rms"],
        "contact_pressure": fields["contact_pressure"],
        "deviation": fields["deviation"],
        "ply_id": np.asarray(ply_id),
    }
    return out


def execute(case, out, *, force=False, quiet=False, stream=None, element_size=None, overrides=(), owner="run",
            **sim_kwargs):
    """Run ``case`` writing everything into ``out``; returns ``(result, written_paths)``.

    Shared by ``jaxform run`` and ``jaxform demo``. Never raises for a failed or interrupted run:
    the result says ``complete=False`` and why.
    """
    from jaxform import cases, forming
    from jaxform.io.frames import FrameWriter, write_json
    from jaxform.io.output import prepare_output_dir

    if not isinstance(case, cases.Case):
        case = cases.load(case)
    if element_size is not None:
        case = cases.with_element_size(case, element_size)
    if overrides:
        case = cases.apply_overrides(case, list(overrides))
    out = prepare_output_dir(out, force=force, owner=owner)
    summary_path = out / "summary.json"
    write_json(summary_path, {"complete": False, "reason": "running (or killed before it could say why)",
                              "case": case.name, "inputs": cases.to_dict(case), "max_ke_ie": None,
                              "max_shear_angle_deg": None, "wall_time_s": None})
    state = {"writer": None}

    def on_frame(k, t, x, fields):
        if state["writer"] is None:
            state["writer"] = FrameWriter(out, state["faces"], stem="frames")
        state["writer"].write(t, x, point_data(fields, state["ply_id"]))

    progress = Progress(stream=stream, quiet=quiet)
    # the faces are known only after building: peek through a tiny wrapper
    from jaxform.forming import build_mesh, grid_quads

    mesh = build_mesh(case)
    import numpy as np

    state["faces"] = grid_quads(*mesh.shape, plies=case.n_plies)
    ply = np.zeros(mesh.n_nodes, np.int32)
    for i, (a, b) in enumerate(mesh.ply_nodes):
        ply[a:b] = i + 1
    state["ply_id"] = ply
    t0 = time.perf_counter()
    try:
        result = forming.simulate(case, on_frame=on_frame, on_progress=progress, catch=True, **sim_kwargs)
    except BaseException as err:  # set-up errors (before the first frame): say so in the summary
        progress.done()
        write_json(summary_path, {"complete": False, "reason": f"error before the run started: {err}",
                                  "case": case.name, "inputs": cases.to_dict(case), "max_ke_ie": None,
                                  "max_shear_angle_deg": None, "wall_time_s": time.perf_counter() - t0})
        raise
    progress.done()
    result.summary["wall_time_s"] = time.perf_counter() - t0
    written = []
    if state["writer"] is not None:
        written.append(state["writer"].pvd_path)
    if len(result.t) >= 1:
        written += _plots(result, out)
    write_json(summary_path, result.summary)
    written.insert(0, summary_path)
    return result, written


def _plots(result, out):
    from jaxform.plots import forming as fplots
    from jaxform.plots.fields import save

    paths = [save(fplots.shear_map(result), out / "shear_angle.png"),
             save(fplots.deviation_map(result), out / "deviation.png")]
    if len(result.history["t"]) >= 2:
        paths.append(save(fplots.punch_force_curve(result), out / "punch_force.png"))
    return paths


def report(result, written, out, stream=None):
    stream = stream or sys.stdout
    s = result.summary
    state = "complete" if result.complete else f"INCOMPLETE ({result.reason})"
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
    print(f"Wrote to {pathlib.Path(out).resolve()}:", file=stream)
    for p in written:
        print(f"  {p}", file=stream)


def run(args) -> int:
    result, written = execute(args.case, args.out, force=args.force, quiet=args.quiet,
                              element_size=None if args.element_size_mm is None else args.element_size_mm * 1e-3,
                              overrides=args.overrides)
    report(result, written, args.out)
    if result.complete:
        return 0
    if result.reason and "KeyboardInterrupt" in result.reason:
        return 130
    return 1
