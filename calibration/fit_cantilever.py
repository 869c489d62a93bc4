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
``b_inf_determined`` (Fisher sd of B_inf under 10 % and the data past 5 kappa0), ``b_init_sd_pct``
and ``b_init_determined`` (Fisher sd of B_init under 1 %: a short strip bent far past kappa0 near
the clamp can leave B_init and kappa0 trading against each other), ``noise_mm`` (read
off the profile) and ``rmse_over_noise``, ``iterations``, ``wall_time_s``. An existing --out is never overwritten
without --force.

Progress goes to stderr, one update per optimiser iteration: a tqdm bar on a terminal, plain
lines (at most one every ``--progress-every`` seconds, and the last) when stderr is a file or pipe.

Input is checked before anything is fitted, and refused (``fit_cantilever.py: error: ...``, exit
2, nothing written): an overhang or areal mass that is not > 0, a profile with missing values (the
lines are named), a profile that spans under 1 % of its overhang (metres in the mm file), and
what :func:`jaxform.io.calibration_files.read_profile_csv` refuses. A fit that is not to be used
(the optimiser did not converge, the fitted strip is not an equilibrium, or its rmse is over twice
the noise read off the profile: no Voce law reproduces it) writes params.json with ``converged:
false`` and the ``reason``, says why on stderr (and in the plot's title) and exits 1;
Ctrl-C stops with a message, no params.json, exit 130. The areal mass only scales the law (a strip's shape depends on
M / w): a wrong --areal-mass-gsm gives a law wrong by the same factor and passes every check.
"""
from __future__ import annotations

import argparse
import importlib
import math
import pathlib
import sys
import textwrap
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

    def abandon(self) -> None:
        """End the display of a fit that stopped (interrupted or failed) without a summary line."""
        if self.bar is not None:
            self.bar.close()
            self.bar = None

    def close(self, fit) -> None:
        if self.bar is not None:
            self.bar.close()
        else:
            print(f"fit [{self.label}] done: {fit.iterations} iterations, {fit.n_simulations} simulations, "
                  f"rmse {1e3 * fit.rmse:.4f} mm", file=sys.stderr, flush=True)


PROG = "fit_cantilever.py"


def _simulate_from_spec(spec: str):
    """``MODULE:FUNCTION`` → the function; ``ValueError`` saying what could not be found."""
    mod, _, fn = spec.partition(":")
    try:
        module = importlib.import_module(mod)
    except ImportError as err:
        raise ValueError(f"--simulate {spec}: cannot import {mod!r} ({err}); give MODULE:FUNCTION of a module on "
                         "the Python path (default jaxform.cantilever:simulate)") from None
    f = getattr(module, fn or "simulate", None)
    if not callable(f):
        raise ValueError(f"--simulate {spec}: {mod} has no function {fn or 'simulate'!r}")
    return f


def _not_converged(fit, max_iter: int) -> str:
    """Why a fit is not one to use ("" when it is): the fit's own verdict (optimiser, equilibrium,
    rmse against the profile's noise), with the option that gives the optimiser more room."""
    if fit.trustworthy:
        return ""
    hint = f" (--max-iter {max_iter}; raise it)" if not fit.converged else ""
    return fit.reason + hint


def main(argv=None) -> int:
    """Run the fit; exit status 0 (fitted), 1 (a fit did not converge: params.json written with
    ``converged: false`` and the reason; or it could not start: nothing written), 2 (refused input:
    nothing written), 130 (interrupted, Ctrl-C: no params.json)."""
    ap = argparse.ArgumentParser(prog=PROG, description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
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

    # ----- the edge: every argument and every profile checked before anything is fitted or written
    if len(args.profile) != len(args.overhang_mm):
        ap.error(f"{len(args.profile)} --profile but {len(args.overhang_mm)} --overhang-mm: give one overhang per profile")
    sides = args.side or ["pos"]
    if len(sides) == 1:
        sides = sides * len(args.profile)
    if len(sides) != len(args.profile):
        ap.error("--side: give it once (all profiles) or once per profile")
    if not (math.isfinite(args.areal_mass_gsm) and args.areal_mass_gsm > 0):
        ap.error(f"--areal-mass-gsm {args.areal_mass_gsm:g}: must be > 0 (g/m²)")
    for L_mm in args.overhang_mm:
        if not (math.isfinite(L_mm) and L_mm > 0):
            ap.error(f"--overhang-mm {L_mm:g}: must be > 0 (the strip's free length, mm)")
    if args.max_iter < 1:
        ap.error(f"--max-iter {args.max_iter}: must be >= 1")
    if not (math.isfinite(args.progress_every) and args.progress_every >= 0):
        ap.error(f"--progress-every {args.progress_every:g}: must be >= 0 seconds")
    if args.plot is not None and args.plot == args.out:
        ap.error("--plot and --out must be different files")
    for path in (args.out, args.plot):
        if path is not None and path.exists() and not args.force:
            ap.error(f"{path} exists; refusing to overwrite it (pass --force)")
    try:
        return _run(args, sides)
    except KeyboardInterrupt:
        done = f"{args.out} was written before (the plot was not)" if args.out.exists() and getattr(args, "wrote_out", False) \
            else f"{args.out} not written"
        print(f"\n{PROG}: interrupted; {done}", file=sys.stderr)
        return 130


def _run(args, sides) -> int:
    import jax

    if not args.float32:
        jax.config.update("jax_enable_x64", True)
    from jaxform import calibrate, units
    from jaxform.io import calibration_files as cf

    areal_mass = units.gsm_to_kg_per_m2(args.areal_mass_gsm)
    groups: dict[str, list] = {}
    try:
        simulate = _simulate_from_spec(args.simulate)
        for path, L_mm, side in zip(args.profile, args.overhang_mm, sides):
            L = units.mm_to_m(L_mm)
            x, z = cf.read_profile_csv(path, overhang=L)
            groups.setdefault(side, []).append(calibrate.Profile(x, z, L))
    except ValueError as err:
        print(f"{PROG}: error: {err}", file=sys.stderr)
        return 2
    t0 = time.perf_counter()
    results, fits, failed = {}, {}, {}
    for side, profs in groups.items():
        progress = _Progress(side, args.max_iter, args.progress_every)
        try:
            fit = calibrate.fit_cantilever(profs, areal_mass=areal_mass, law=args.law, simulate=simulate,
                                           compute_b41_5=not args.no_standard_test, max_iter=args.max_iter,
                                           callback=progress)
        except RuntimeError as err:  # no starting point gave a finite, converged simulation
            progress.abandon()
            print(f"{PROG}: the fit [{side}] could not start: {err}; {args.out} not written", file=sys.stderr)
            return 1
        except BaseException:
            progress.abandon()
            raise
        progress.close(fit)
        fits[side] = fit
        d = fit.as_dict()
        reason = _not_converged(fit, args.max_iter)
        d.update(converged=not reason, reason=reason, side=side, areal_mass_gsm=args.areal_mass_gsm,
                 profiles=[{"file": str(p), "overhang_mm": L} for p, L, s in zip(args.profile, args.overhang_mm, sides) if s == side])
        if reason:
            failed[side] = reason
        results[side] = d
    if len(results) == 1:
        out = next(iter(results.values()))
    else:
        out = {"side": "both", "converged": not failed, **{s: results[s] for s in ("pos", "neg")}}
    out["total_wall_time_s"] = time.perf_counter() - t0
    cf.write_json(args.out, out, force=args.force)
    args.wrote_out = True
    for side, d in results.items():
        det = "determined" if d["b_inf_determined"] else \
            "UNDETERMINED: its Fisher sd is over 10 % or the data do not reach 5 x kappa0"
        det_init = "determined" if d["b_init_determined"] else \
            "UNDETERMINED: its Fisher sd is over 1 %; this profile does not pin it to 3 %, add a longer overhang"
        print(f"[{side}] B_init {d['b_init_Nm']:.4g} ± {d['sigma_b_init_Nm']:.2g} N·m "
              f"({d['b_init_sd_pct']:.1f} %, {det_init}), "
              f"B_inf {d['b_inf_Nm']:.4g} ± {d['sigma_b_inf_Nm']:.2g} N·m ({det}), "
              f"kappa0 {d['kappa0_per_m']:.4g} 1/m, rmse {d['rmse_mm']:.3f} mm ({d['rmse_over_noise']:.2f} x the noise "
              f"{d['noise_mm']:.3f} mm read off the profile), "
              f"{d['iterations']} iterations, {d['wall_time_s']:.1f} s")
    print(f"wrote {args.out}")
    if args.plot is not None:
        from jaxform.plots import calibration as pc

        for side, fit in fits.items():
            path = args.plot if len(fits) == 1 else args.plot.with_name(f"{args.plot.stem}-{side}{args.plot.suffix}")
            title = f"cantilever fit ({side})" if side not in failed else \
                f"cantilever fit ({side}) NOT TRUSTWORTHY: {textwrap.shorten(failed[side], 150)}"
            pc.save(pc.cantilever_fit_figure(fit, groups[side], title=title), path)
            print(f"wrote {path}")
    for side, reason in failed.items():
        print(f"{PROG}: the fit [{side}] failed: {reason} ({args.out} records it: converged false)",
              file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
