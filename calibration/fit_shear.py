"""Fit a normalised shear-force law to picture-frame data.

    python calibration/fit_shear.py --data frame.csv [--frame-side-mm L] [--form polynomial|ncf]
        [--degree N] [--out shear.toml] [--json fit.json] [--plot fit.png] [--check] [--force]

frame.csv: ``gamma_deg`` (or ``gamma_rad``) with ``f_norm_N_per_m``; or raw frame data
``gamma_deg``/``displacement_mm`` with ``force_N`` and ``--frame-side-mm`` (pin to pin), normalised
``F / (2 L cos(pi/4 - gamma/2))``. The polynomial (odd, no constant term) is constrained to be
non-decreasing on the fitted range; ``--form ncf`` adds the positive-only stitch term (the yarn
polynomial is the constrained part). The TOML holds ``[fabric] shear_poly_N_per_m`` (the key a
forming case reads) and a ``[shear_fit]`` record. ``--check`` simulates the picture frame with
the fitted law (the shell's picture-frame rig, ``jaxform.frame_tests``).
"""
from __future__ import annotations

import argparse
import pathlib
import sys


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--data", required=True, type=pathlib.Path)
    ap.add_argument("--frame-side-mm", type=float, help="frame side pin to pin, mm (raw force data)")
    ap.add_argument("--form", choices=("polynomial", "ncf"), default="polynomial")
    ap.add_argument("--degree", type=int, default=None, help="polynomial degree (default 7, ncf 5)")
    ap.add_argument("--no-monotone", action="store_true", help="drop the non-decreasing constraint")
    ap.add_argument("--out", type=pathlib.Path, default=None, help="shear law TOML")
    ap.add_argument("--json", type=pathlib.Path, default=None, help="fit summary JSON")
    ap.add_argument("--plot", type=pathlib.Path, default=None)
    ap.add_argument("--check", action="store_true", help="simulate the picture frame with the fitted law")
    ap.add_argument("--force", action="store_true", help="overwrite existing outputs")
    args = ap.parse_args(argv)
    for path in (args.out, args.json, args.plot):
        if path is not None and path.exists() and not args.force:
            ap.error(f"{path} exists; refusing to overwrite it (pass --force)")

    import jax

    jax.config.update("jax_enable_x64", True)
    from jaxform import calibrate
    from jaxform.io import calibration_files as cf

    side = None if args.frame_side_mm is None else args.frame_side_mm * 1e-3
    try:
        gamma, force = cf.read_shear_csv(args.data, frame_side=side)
        if args.form == "ncf":
            fit = calibrate.fit_shear_ncf(gamma, force, degree=args.degree or 5, monotone=not args.no_monotone)
        else:
            fit = calibrate.fit_shear_polynomial(gamma, force, degree=args.degree or 7, monotone=not args.no_monotone)
    except ValueError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    d = fit.as_dict()
    print(f"{fit.kind} fit: coefficients {[round(c, 3) for c in d['coeffs_N_per_m']]} N/m, rmse {fit.rmse:.4g} N/m, "
          f"monotone {fit.monotone}")
    if fit.stitch_gamma_knots is not None:
        print(f"stitch knots {fit.stitch_gamma_knots.round(4).tolist()} rad, peak {fit.stitch_force_knots[1]:.4g} N/m")
    if args.check:
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
    return 0


if __name__ == "__main__":
    sys.exit(main())
