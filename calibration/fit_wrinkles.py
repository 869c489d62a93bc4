"""Fit the bending law (and optionally a shear-law scale) to wrinkle sections of a formed part,
through the forming simulation; jointly with cantilever side profiles when given.

    python calibration/fit_wrinkles.py --case CASE.toml|PRESET --section A.csv --line X0,Y0,X1,Y1
        [--section B.csv --line ...] [--profile P.csv --overhang-mm L ... --areal-mass-gsm W]
        [--params voce|voce+shear] --out params.json [--plot fit.png] [--force]
        [--element-size-mm S] [--set KEY=VALUE ...] [--noise-mm 0.05] [--smoothing-mm W] [--ply 1]
        [--starts 8] [--max-iter 8] [--restarts 2] [--seeds 1] [--scatter-seeds N] [--no-gradient-check]

A section CSV has the header ``s_mm,amplitude_mm``: the position along the line from (X0, Y0) in
the top view of the formed part (mm, punch axis at the origin, as ``jaxform run`` writes it) and
the wrinkle amplitude there (the distance from the ply mid-surface to the tool, d_P, mm). Each
``--section`` takes the ``--line`` given after it. The case gives the rig, the mesh and the
starting law (its ``fabric.voce`` or its preset's); ``--set`` changes case keys as for ``jaxform
run``. With ``--profile``, cantilever side profiles of the same fabric (``x_mm,z_mm``, as for
``fit_cantilever.py``) join the objective: the cantilever pins B_init, the wrinkles inform the law
at high curvature.

params.json: ``b_inf_Nm``, ``m0_N``, ``kappa0_per_m``, ``b_init_Nm``, ``shear_scale``, their
``sigma_*`` (Gauss-Newton / Laplace, checked against the loss along the covariance's principal
axes, the flattest further out, and widened where it rises less, the fit moved to a probe that fits
better (``sigma_check.moved_from``): ``sigma_check``; plus the scatter of
the fitted law's part from ``--scatter-seeds`` imperfect blanks: ``scatter``; ``null`` where no
finite sd exists), ``determined`` (sd under 10 %, not a lower bound; ``b_inf``, ``m0``, ``kappa0`` only
where the part bends to 5 kappa0), ``moment_band`` (M and its sd up to ``kappa_reach``, what
wrinkles do determine), ``loss_initial``,
``loss_final``, ``rms_mm_per_section`` and ``nrmse_per_section`` (the paper's metric),
``gradient_check`` (AD vs central differences at the start and what the fit did about it),
``iterations``, ``forming_runs``, ``wall_time_s``, ``misfit`` (the chi-square against what the noise
leaves at the true law, as a whole and per block of data: ``blocks``, ``failed``), ``local_fits`` (each local fit: its start, final loss and misfit p; more than
one where the first ended in a local minimum), ``cantilever_start`` (with profiles: the law they give
alone, one of the starts), ``gn_decrease_chi2`` and ``gn_decrease_dof`` (what a Gauss-Newton step
from the fit would still gain, raw and in the noise's degrees of freedom: under 1 counts as
converged), ``converged`` and ``reason``. An existing --out
is never overwritten without --force.

Exit status: 0 fitted; 1 a fit that is not to be used (params.json says ``converged: false`` and
why) or one that could not start (nothing written); 2 refused input (nothing written: a CSV error,
a line in metres, a section off the blank or off the formed part, an unknown case or key);
130 interrupted (no params.json).
"""
from __future__ import annotations

import argparse
import math
import pathlib
import sys
import time

PROG = "fit_wrinkles.py"


class _Progress:
    """One line per stage or every ``every_s`` seconds on stderr (a tqdm bar on a terminal)."""

    def __init__(self, every_s: float, total: int):
        self.every_s, self.last, self.t0 = every_s, -math.inf, time.monotonic()
        self.bar = None
        self.stage = None
        if sys.stderr.isatty():
            from tqdm import tqdm

            self.bar = tqdm(total=total, desc="fit_wrinkles", unit="run", file=sys.stderr)

    def __call__(self, p) -> None:
        text = f"{p.stage}: {p.forming_runs} forming runs, best loss {p.loss:.4g}"
        if self.bar is not None:
            self.bar.update(p.forming_runs - self.bar.n)
            self.bar.set_postfix_str(text)
        elif p.stage != self.stage or time.monotonic() - self.last >= self.every_s:
            self.last, self.stage = time.monotonic(), p.stage
            print(f"fit_wrinkles [{time.monotonic() - self.t0:.0f} s] {text}", file=sys.stderr, flush=True)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


def _pairs(ap, args):
    """The ``--section``/``--line`` and ``--profile``/``--overhang-mm`` pairs, in order."""
    if not args.section:
        ap.error("give at least one --section with its --line")
    if len(args.section) != len(args.line or []):
        ap.error(f"{len(args.section)} --section but {len(args.line or [])} --line: give one line (X0,Y0,X1,Y1 in mm) per section")
    profiles = args.profile or []
    if len(profiles) != len(args.overhang_mm or []):
        ap.error(f"{len(profiles)} --profile but {len(args.overhang_mm or [])} --overhang-mm: give one overhang per profile")
    if profiles and args.areal_mass_gsm is None:
        ap.error("--profile needs --areal-mass-gsm (the fabric's areal mass, g/m²)")
    for name, v, ok in (("--noise-mm", args.noise_mm, args.noise_mm > 0), ("--starts", args.starts, args.starts >= 1),
                        ("--max-iter", args.max_iter, args.max_iter >= 1), ("--seeds", args.seeds, args.seeds >= 1),
                        ("--restarts", args.restarts, args.restarts >= 0),
                        ("--scatter-seeds", args.scatter_seeds, args.scatter_seeds is None or args.scatter_seeds >= 0),
                        ("--ply", args.ply, args.ply >= 1),
                        ("--smoothing-mm", args.smoothing_mm, args.smoothing_mm is None or args.smoothing_mm >= 0),
                        ("--areal-mass-gsm", args.areal_mass_gsm, args.areal_mass_gsm is None or args.areal_mass_gsm > 0),
                        ("--element-size-mm", args.element_size_mm, args.element_size_mm is None or args.element_size_mm > 0)):
        if not (ok and (not isinstance(v, float) or math.isfinite(v))):
            ap.error(f"{name} {v}: out of range")
    for L in args.overhang_mm or []:
        if not (math.isfinite(L) and L > 0):
            ap.error(f"--overhang-mm {L:g}: must be > 0 (the strip's free length, mm)")
    if args.plot is not None and args.plot == args.out:
        ap.error("--plot and --out must be different files")
    for path in (args.out, args.plot):
        if path is not None and path.exists() and not args.force:
            ap.error(f"{path} exists; refusing to overwrite it (pass --force)")
    return list(zip(args.section, args.line)), list(zip(profiles, args.overhang_mm or []))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog=PROG, description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--case", required=True, help="case TOML or preset name (the rig, mesh and starting law)")
    ap.add_argument("--section", action="append", type=pathlib.Path, help="section CSV (s_mm,amplitude_mm)")
    ap.add_argument("--line", action="append", help="the section's line X0,Y0,X1,Y1 in mm (top view)")
    ap.add_argument("--profile", action="append", type=pathlib.Path, help="cantilever profile CSV (x_mm,z_mm)")
    ap.add_argument("--overhang-mm", action="append", type=float, help="overhang of each profile, mm")
    ap.add_argument("--areal-mass-gsm", type=float, help="the fabric's areal mass, g/m² (with --profile)")
    ap.add_argument("--params", choices=("voce", "voce+shear"), default="voce")
    ap.add_argument("--out", required=True, type=pathlib.Path, help="params.json to write")
    ap.add_argument("--plot", type=pathlib.Path, help="PNG of the fit")
    ap.add_argument("--force", action="store_true", help="overwrite --out / --plot if they exist")
    ap.add_argument("--element-size-mm", type=float, help="element size of the forming mesh, mm (default the case's)")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="case key override")
    ap.add_argument("--noise-mm", type=float, default=0.05, help="the sections' measurement noise, mm (default 0.05)")
    ap.add_argument("--smoothing-mm", type=float, help="width of the residual's smoothing, mm (default the element size)")
    ap.add_argument("--ply", type=int, default=1, help="the ply the sections measured (1 touches the punch)")
    ap.add_argument("--starts", type=int, default=8, help="laws scored in the global phase (default 8)")
    ap.add_argument("--max-iter", type=int, default=8, help="optimiser evaluations (default 8)")
    ap.add_argument("--restarts", type=int, default=2,
                    help="local fits from the next-best starts where a fit fails the misfit test (default 2)")
    ap.add_argument("--seeds", type=int, default=1, help="imperfect blanks averaged per evaluation (default 1)")
    ap.add_argument("--scatter-seeds", type=int, default=None,
                    help="imperfect blanks run at the fitted law for its uncertainty (default: the fit's, "
                         "jaxform.calibrate.wrinkle_fit.SCATTER_SEEDS; 0: none)")
    ap.add_argument("--no-gradient-check", action="store_true", help="skip AD vs FD at the start (the fit uses FD)")
    ap.add_argument("--progress-every", type=float, default=30.0, metavar="S", help="seconds between progress lines")
    args = ap.parse_args(argv)
    sections, profiles = _pairs(ap, args)
    try:
        return _run(args, sections, profiles)
    except KeyboardInterrupt:
        print(f"\n{PROG}: interrupted; {args.out} not written", file=sys.stderr)
        return 130


def _run(args, section_args, profile_args) -> int:
    import jax

    if profile_args:
        jax.config.update("jax_enable_x64", True)  # the cantilever's equilibrium solve
    from jaxform import calibrate, cases, units
    from jaxform.calibrate import wrinkle_fit
    from jaxform.io import calibration_files as cf

    try:
        case = cases.resolve(args.case, element_size=None if args.element_size_mm is None else args.element_size_mm * 1e-3,
                             overrides=args.set)
        sections = []
        for path, line in section_args:
            a, b = cf.parse_line_mm(line)
            sections.append(cf.read_section_csv(path, a, b))
            calibrate.check_section(sections[-1], case)
        profiles = []
        for path, L_mm in profile_args:
            x, z = cf.read_profile_csv(path, overhang=L_mm * 1e-3)
            profiles.append(calibrate.Profile(x, z, L_mm * 1e-3))
    except (ValueError, KeyError, FileNotFoundError) as err:
        print(f"{PROG}: error: {err}", file=sys.stderr)
        return 2
    p = 3 if args.params == "voce" else 4
    progress = _Progress(args.progress_every, args.starts + 3 * p + 1 + args.max_iter * (2 * p + 1))
    try:
        fit = wrinkle_fit.fit_wrinkles(
            case, sections, params=args.params, profiles=profiles or None,
            areal_mass=None if args.areal_mass_gsm is None else units.gsm_to_kg_per_m2(args.areal_mass_gsm),
            noise=args.noise_mm * 1e-3, smoothing=None if args.smoothing_mm is None else args.smoothing_mm * 1e-3,
            ply=args.ply, n_starts=args.starts, max_iter=args.max_iter, restarts=args.restarts, seeds=args.seeds,
            gradient_check=not args.no_gradient_check, callback=progress,
            **({} if args.scatter_seeds is None else {"scatter_seeds": args.scatter_seeds}))
    except ValueError as err:  # a section the case's rig cannot produce
        progress.close()
        print(f"{PROG}: error: {err}", file=sys.stderr)
        return 2
    except RuntimeError as err:
        progress.close()
        print(f"{PROG}: the fit could not start: {err}; {args.out} not written", file=sys.stderr)
        return 1
    progress.close()
    out = fit.as_dict()
    out.update(case=case.name, element_size_mm=case.element_size * 1e3, params=args.params, noise_mm=args.noise_mm,
               sections=[{"file": str(pth), "line_mm": ln} for pth, ln in section_args],
               profiles=[{"file": str(pth), "overhang_mm": L} for pth, L in profile_args])
    cf.write_json(args.out, out, force=args.force)
    v, s, band = fit.values, fit.sigma, fit.moment_band
    nd = {k: "" if fit.determined[k] else " (not determined)" for k in fit.determined}
    print(f"B_init {v['b_init']:.4g} ± {s['b_init']:.2g} N·m{nd['b_init']}, B_inf {v['b_inf']:.4g} ± {s['b_inf']:.2g} "
          f"N·m{nd['b_inf']}, kappa0 {v['kappa0']:.4g} ± {s['kappa0']:.2g} 1/m{nd['kappa0']}; M at the curvature the "
          f"wrinkles reach ({band['kappa_per_m'][-1]:.3g} 1/m) {band['moment_N'][-1]:.4g} ± {band['sd_N'][-1]:.2g} N"
          f"{'' if band['determined'] else ' (not determined)'}; loss {fit.loss_initial:.4g} -> {fit.loss_final:.4g}; "
          "section RMS " + ", ".join(f"{1e3 * r:.3f} mm" for r in fit.rms_per_section)
          + f"; {fit.forming_runs} forming runs, {fit.wall_time:.0f} s; jacobian {fit.jacobian}")
    if fit.gradient_check.get("done") and not fit.gradient_check["agree"]:
        print(f"gradient check: {fit.gradient_check['action']}")
    if fit.scatter.get("chi_squares"):
        chis = fit.scatter["chi_squares"]
        print(f"the fitted law from {len(chis)} imperfect blanks: chi-square {min(chis):.4g} to {max(chis):.4g} "
              f"(its own {2.0 * fit.loss_final:.4g}); their scatter's share of the B_init variance "
              f"{100.0 * fit.scatter['share'][0]:.0f} %")
    if fit.scatter.get("failed"):
        print(f"note: the fitted law's run failed from {fit.scatter['failed']} imperfect blank(s); left out of its "
              "uncertainty (the law forms this part only from a near-perfect blank)")
    print(f"wrote {args.out}")
    if args.plot is not None:
        from jaxform.plots import calibration as pc

        title = "wrinkle fit" if fit.converged else f"wrinkle fit NOT CONVERGED: {fit.reason[:120]}"
        pc.save(pc.wrinkle_fit_figure(fit, sections, title=title), args.plot)
        print(f"wrote {args.plot}")
    if not fit.converged:
        print(f"{PROG}: the fit is not to be used: {fit.reason} ({args.out} records it: converged false)", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
