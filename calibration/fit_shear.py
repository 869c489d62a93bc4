"""Fit a normalised shear-force law to picture-frame data.

    python calibration/fit_shear.py --data frame.csv [--frame-side-mm L] [--form polynomial|ncf]
        [--degree N] [--out shear.toml] [--json fit.json] [--plot fit.png] [--check] [--force]

frame.csv: ``gamma_deg`` (or ``gamma_rad``) with ``f_norm_N_per_m``; or raw frame data
``gamma_deg``/``displacement_mm`` with ``force_N`` and ``--frame-side-mm`` (pin to pin), normalised
``F / (2 L cos(pi/4 - gamma/2))``. The polynomial (odd, no constant term) is constrained to be
non-decreasing on the fitted range; ``--form ncf`` adds the positive-only stitch term (the yarn
polynomial is the constrained part). The TOML holds ``[fabric] shear_poly_N_per_m`` (the key a
forming case reads) with ``shear_reading = "conjugate"`` (the measured frame force is the formed
fabric's shear resultant; README, "Modelling choices") and a ``[shear_fit]`` record. ``--check`` simulates the picture frame with
the fitted law (the shell's picture-frame rig, ``jaxform.frame_tests``).

Input is checked before anything is fitted, and refused (``fit_shear.py: error: ...``, exit 2,
nothing written) when it cannot give a meaningful law: missing values (by line), radians under a
``gamma_deg`` header (or degrees under ``gamma_rad``), forces against the sign of the shear, a
frame side that is not a positive length in mm, a degree outside 1..9 or not below the number of
distinct angles. A fit that ran but is not to be used (the non-decreasing constraint not met, rmse
far above the data's own scatter, the optimiser stopped) writes its files with ``converged =
false`` and the reason, says why on stderr and exits 1.
"""
from __future__ import annotations

import argparse
import math
import pathlib
import sys


PROG = "fit_shear.py"
MIN_FRAME_SIDE_MM = 20.0  # picture frames are 100-300 mm pin to pin; below this the side is in metres


def main(argv=None) -> int:
    """Run the fit; exit status 0 (a fit to use), 1 (the fit did not converge: outputs written, with
    the reason), 2 (refused input: nothing written), 130 (interrupted: nothing written)."""
    ap = argparse.ArgumentParser(prog=PROG, description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--data", required=True, type=pathlib.Path)
    ap.add_argument("--frame-side-mm", type=float, help="frame side pin to pin, mm (raw force data)")
    ap.add_argument("--form", choices=("polynomial", "ncf"), default="polynomial")
    ap.add_argument("--degree", type=int, default=None, help="polynomial degree, 1 to 9 (default 7, ncf 5)")
    ap.add_argument("--no-monotone", action="store_true", help="drop the non-decreasing constraint")
    ap.add_argument("--out", type=pathlib.Path, default=None, help="shear law TOML")
    ap.add_argument("--json", type=pathlib.Path, default=None, help="fit summary JSON")
    ap.add_argument("--plot", type=pathlib.Path, default=None)
    ap.add_argument("--check", action="store_true", help="simulate the picture frame with the fitted law")
    ap.add_argument("--force", action="store_true", help="overwrite existing outputs")
    args = ap.parse_args(argv)
    # ----- the edge: every argument checked before anything is read, fitted or written
    from jaxform.calibrate.shear_fit import MAX_DEGREE

    if args.degree is not None and not 1 <= args.degree <= MAX_DEGREE:
        ap.error(f"--degree {args.degree}: must be an integer from 1 to {MAX_DEGREE} (odd polynomial without a "
                 "constant term; default 7, 5 for --form ncf)")
    if args.frame_side_mm is not None:
        if not (math.isfinite(args.frame_side_mm) and args.frame_side_mm > 0):
            ap.error(f"--frame-side-mm {args.frame_side_mm:g}: must be > 0 (the frame side pin to pin, mm)")
        if args.frame_side_mm < MIN_FRAME_SIDE_MM:
            ap.error(f"--frame-side-mm {args.frame_side_mm:g}: a picture frame is 100-300 mm pin to pin; a side under "
                     f"{MIN_FRAME_SIDE_MM:g} mm looks like metres (give millimetres, e.g. 145)")
    outs = [p for p in (args.out, args.json, args.plot) if p is not None]
    if len(set(outs)) < len(outs):
        ap.error("--out, --json and --plot must be different files")
    for path in outs:
        if path.exists() and not args.force:
            ap.error(f"{path} exists; refusing to overwrite it (pass --force)")
    try:
        return _run(args)
    except KeyboardInterrupt:
        print(f"{PROG}: interrupted; nothing written", file=sys.stderr)
        return 130


def _run(args) -> int:
    import jax

    jax.config.update("jax_enable_x64", True)
    from jaxform import calibrate
    from jaxform.io import calibration_files as cf

    side = None if args.frame_side_mm is None else args.frame_side_mm * 1e-3
    degree = args.degree if args.degree is not None else (5 if args.form == "ncf" else 7)
    try:
        gamma, force = cf.read_shear_csv(args.data, frame_side=side)
        fit_fn = calibrate.fit_shear_ncf if args.form == "ncf" else calibrate.fit_shear_polynomial
        fit = fit_fn(gamma, force, degree=degree, monotone=not args.no_monotone)
    except ValueError as err:
        print(f"{PROG}: error: {err}", file=sys.stderr)
        return 2
    d = fit.as_dict()
    print(f"{fit.kind} fit: coefficients {[round(c, 3) for c in d['coeffs_N_per_m']]} N/m, rmse {fit.rmse:.4g} N/m "
          f"(data scatter {fit.scatter:.3g} N/m), monotone {fit.monotone}")
    if fit.stitch_gamma_knots is not None:
        print(f"stitch knots {fit.stitch_gamma_knots.round(4).tolist()} rad, peak {fit.stitch_force_knots[1]:.4g} N/m")
    if args.check and fit.converged:
        chk = calibrate.check_shear_fit(fit)
        d["check_max_rel_diff"] = chk["max_rel_diff"]
        print(f"simulated picture frame vs fitted law: max relative difference {chk['max_rel_diff']:.3g}")
    if args.out is not None:
        cf.write_shear_toml(args.out, d, force=args.force)
        print(f"wrote {args.out}")
    if args.json is not None:
        cf.write_json(args.json, d, force=args.force)
        print(f"wrote {args.json}")
    if args.plot is not None:
        from jaxform.plots import calibration as pc

        pc.save(pc.shear_fit_figure(fit, gamma, force), args.plot)
        print(f"wrote {args.plot}")
    if not fit.converged:
        print(f"{PROG}: the fit did not converge: {fit.reason}" +
              (" (the files written record it: converged = false)" if args.out or args.json else ""), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
