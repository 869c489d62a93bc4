"""Fit a bending law to cantilever side profiles through the differentiable shell cantilever.

    python calibration/fit_cantilever.py --profile P.csv --overhang-mm L [--profile P2.csv
        --overhang-mm L2 ...] --areal-mass-gsm W [--side pos|neg ...] [--law voce|linear]
        --out params.json [--plot fit.png] [--force]

P.csv: header ``x_mm,z_mm``, side profile of a strip clamped horizontally at the origin, hanging
under its own weight, z negative downwards; L the overhang along the strip (mm). Several overhangs
of one material constrain the law better. ``--side`` (once for all profiles, or once per profile)
says whether the strip was tested face up (``pos``, the default) or face down (``neg``): with both
sides present, each side's law is fitted from its own profiles (a hanging strip bends one way
only) and params.json holds ``pos`` and ``neg`` sections. Gravity 9.81 m/s².

params.json: ``b_inf_Nm``, ``m0_N``, ``kappa0_per_m``, ``b_init_Nm`` (= b_inf + m0/kappa0),
``b_41_5_Nm`` (standard test simulated with the fitted law), ``rmse_mm`` (RMS z-residual at the
measured x), ``sigma_*`` (Gauss–Newton standard errors), ``kappa_max_over_kappa0`` and
``b_inf_determined``, ``iterations``, ``wall_time_s``. An existing --out is never overwritten
without --force.

Progress goes to stderr, one update per optimiser iteration: a tqdm bar on a terminal, plain
lines (at most one every ``--progress-every`` seconds, and the last) when stderr is a file or pipe.
"""
from __future__ import annotations

import argparse
import importlib
import pathlib
import sys
import time


class _Progress:
    """Per-iteration progress of one fit on stderr: tqdm on a terminal, plain periodic lines otherwise."""

    def __init__(self, label: str, total: int, every_s: float):
        self.label, self.every_s, self.last = label, every_s, -float("inf")
        self.bar = None
        if sys.stderr.isatty():
            from tqdm import tqdm

            self.bar = tqdm(total=total, desc=f"fit [{label}]", unit="it", file=sys.stderr, leave=True)

    def __call__(self, info) -> None:
        text = f"rmse {1e3 * info.rmse:.4f} mm, B_init {float(info.law.b_init):.4g} N·m, {info.n_evaluations} evaluations"
        if self.bar is not None:
            self.bar.update(info.iteration - self.bar.n)
            self.bar.set_postfix_str(text)
        elif time.monotonic() - self.last >= self.every_s:
            self.last = time.monotonic()
            print(f"fit [{self.label}] iteration {info.iteration}: {text}", file=sys.stderr, flush=True)

    def close(self, fit) -> None:
        if self.bar is not None:
            self.bar.close()
        else:
            print(f"fit [{self.label}] done: {fit.iterations} iterations, {fit.n_simulations} simulations, "
                  f"rmse {1e3 * fit.rmse:.4f} mm", file=sys.stderr, flush=True)


def _simulate_from_spec(spec: str):
    mod, _, fn = spec.partition(":")
    return getattr(importlib.import_module(mod), fn or "simulate")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--profile", action="append", required=True, type=pathlib.Path, help="profile CSV (x_mm,z_mm)")
    ap.add_argument("--overhang-mm", action="append", required=True, type=float, help="overhang of each profile, mm")
    ap.add_argument("--areal-mass-gsm", required=True, type=float, help="areal mass, g/m²")
    ap.add_argument("--side", action="append", choices=("pos", "neg"), help="face up (pos) or down (neg)")
    ap.add_argument("--law", choices=("voce", "linear"), default="voce")
    ap.add_argument("--out", required=True, type=pathlib.Path, help="params.json to write")
    ap.add_argument("--plot", type=pathlib.Path, help="PNG of the fit")
    ap.add_argument("--force", action="store_true", help="overwrite --out / --plot if they exist")
    ap.add_argument("--no-standard-test", action="store_true", help="skip the simulated 41.5° test")
    ap.add_argument("--simulate", default="jaxform.cantilever:simulate",
                    help="forward model MODULE:FUNCTION (default jaxform.cantilever:simulate)")
    ap.add_argument("--float32", action="store_true", help="run in float32 (default float64)")
    ap.add_argument("--max-iter", type=int, default=60, help="largest number of optimiser evaluations")
    ap.add_argument("--progress-every", type=float, default=10.0, metavar="S",
                    help="seconds between progress lines when stderr is not a terminal (default 10)")
    args = ap.parse_args(argv)

    if len(args.profile) != len(args.overhang_mm):
        ap.error(f"{len(args.profile)} --profile but {len(args.overhang_mm)} --overhang-mm: give one overhang per profile")
    sides = args.side or ["pos"]
    if len(sides) == 1:
        sides = sides * len(args.profile)
    if len(sides) != len(args.profile):
        ap.error("--side: give it once (all profiles) or once per profile")
    if args.areal_mass_gsm <= 0:
        ap.error("--areal-mass-gsm must be > 0")
    for path in (args.out, args.plot):
        if path is not None and path.exists() and not args.force:
            ap.error(f"{path} exists; refusing to overwrite it (pass --force)")

    import jax

    if not args.float32:
        jax.config.update("jax_enable_x64", True)
    from jaxform import calibrate, units
    from jaxform.io import calibration_files as cf

    areal_mass = units.gsm_to_kg_per_m2(args.areal_mass_gsm)
    groups: dict[str, list] = {}
    try:
        for path, L_mm, side in zip(args.profile, args.overhang_mm, sides):
            if L_mm <= 0:
                raise ValueError(f"--overhang-mm {L_mm}: must be > 0")
            L = units.mm_to_m(L_mm)
            x, z = cf.read_profile_csv(path, overhang=L)
            groups.setdefault(side, []).append(calibrate.Profile(x, z, L))
    except ValueError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    simulate = _simulate_from_spec(args.simulate)
    t0 = time.perf_counter()
    results, fits = {}, {}
    for side, profs in groups.items():
        progress = _Progress(side, args.max_iter, args.progress_every)
        fit = calibrate.fit_cantilever(profs, areal_mass=areal_mass, law=args.law, simulate=simulate,
                                       compute_b41_5=not args.no_standard_test, max_iter=args.max_iter,
                                       callback=progress)
        progress.close(fit)
        fits[side] = fit
        d = fit.as_dict()
        d.update(side=side, areal_mass_gsm=args.areal_mass_gsm,
                 profiles=[{"file": str(p), "overhang_mm": L} for p, L, s in zip(args.profile, args.overhang_mm, sides) if s == side])
        results[side] = d
    if len(results) == 1:
        out = next(iter(results.values()))
    else:
        out = {"side": "both", **{s: results[s] for s in ("pos", "neg")}}
    out["total_wall_time_s"] = time.perf_counter() - t0
    cf.write_json(args.out, out, force=args.force)
    for side, d in results.items():
        det = "determined" if d["b_inf_determined"] else "UNDETERMINED (data do not reach 5 x kappa0)"
        print(f"[{side}] B_init {d['b_init_Nm']:.4g} ± {d['sigma_b_init_Nm']:.2g} N·m, "
              f"B_inf {d['b_inf_Nm']:.4g} ± {d['sigma_b_inf_Nm']:.2g} N·m ({det}), "
              f"kappa0 {d['kappa0_per_m']:.4g} 1/m, rmse {d['rmse_mm']:.3f} mm, "
              f"{d['iterations']} iterations, {d['wall_time_s']:.1f} s")
    print(f"wrote {args.out}")
    if args.plot is not None:
        from jaxform.plots import calibration as pc

        for side, fit in fits.items():
            path = args.plot if len(fits) == 1 else args.plot.with_name(f"{args.plot.stem}-{side}{args.plot.suffix}")
            pc.save(pc.cantilever_fit_figure(fit, groups[side], title=f"cantilever fit ({side})"), path)
            print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
