"""Benchmark: the cantilever round-trip study of issue 18 (fit time and accuracy over the fabrics' range).

``run(quick)`` draws Voce laws, areal masses and chord angles from a seeded Latin hypercube
(``tests/reference/cantilever_study.py``: B_init 3e-4..1e-2 N·m, B_inf/B_init 0.02..0.2, kappa0
2..60 1/m, 150..600 g/m², chord 20..75°), makes one noisy side profile of each with the independent
elastica (60 points, 0.05 mm on z), fits each profile alone with ``jaxform.calibrate.fit_cantilever``
(the shell, default settings) and reports, per fit and in summary: B_init and B_inf errors, their
Fisher sds and whether the fit calls them determined, rmse over the true noise, whether the fit
called itself trustworthy, the wall time (the first fit includes compiling the solver; the median
is over all fits) and the process CPU time of the fit (user + system, all threads: on a machine
shared with other jobs the wall time alone says little). The table is written as Markdown to
``benchmarks/results/<UTC stamp>-cantilever_fit-rows.md`` after every fit (an interrupted run
keeps its rows). ``quick``: 3 profiles. The issue's targets: every rmse <= 1.5 x noise, B_init
within 3 %, B_inf within 10 % where its Fisher sd is under 3 %, median fit time <= 60 s on the
2-core machine. B_init within 3 % is checked where the fit says it is determined (Fisher sd under
1 %); where it says it is not, the true value must lie within 3 of its sds (``b_init_ok``), and the
summary counts those fits and quotes their errors: that part of the target is not met there, and
the fit says so rather than hiding it.
"""
from __future__ import annotations

import datetime as _dt
import math
import pathlib
import resource
import sys
import time

import numpy as np

HERE = pathlib.Path(__file__).resolve().parent
N_PROFILES, SEED, NOISE = 32, 18, 5e-5


def fit_row(i: int, p: dict) -> dict:
    """Fit one study profile (dict from ``cantilever_study.noisy_profile``) alone; the table's row."""
    from jaxform import calibrate as C

    t0, ru0 = time.perf_counter(), resource.getrusage(resource.RUSAGE_SELF)
    fit = C.fit_cantilever([C.Profile(p["x"], p["z"], p["overhang"])], areal_mass=p["areal_mass"], compute_b41_5=False)
    wall = time.perf_counter() - t0
    ru = resource.getrusage(resource.RUSAGE_SELF)
    cpu = (ru.ru_utime - ru0.ru_utime) + (ru.ru_stime - ru0.ru_stime)
    sd_inf = fit.sigma["b_inf"] / fit.b_inf if fit.b_inf > 0 else math.inf
    sd_init = fit.sigma["b_init"] / fit.b_init
    err_init = 100 * (fit.b_init / p["b_init"] - 1)
    return {
        "case": i, "b_init_Nm": p["b_init"], "ratio": p["ratio"], "kappa0_per_m": p["kappa0"],
        "areal_mass_gsm": 1e3 * p["areal_mass"], "chord_deg": p["chord_deg"], "overhang_mm": 1e3 * p["overhang"],
        "clamp_kappa_over_kappa0": p["clamp_curvature"] / p["kappa0"],
        "b_init_err_pct": err_init, "b_init_sd_pct": 100 * sd_init, "b_init_determined": fit.b_init_determined,
        "b_init_ok": bool(abs(err_init) <= 3 if fit.b_init_determined else abs(err_init) <= 300 * sd_init),
        "b_inf_err_pct": 100 * (fit.b_inf / p["b_inf"] - 1),
        "b_inf_sd_pct": 100 * sd_inf, "b_inf_determined": fit.b_inf_determined,
        "rmse_over_noise": fit.rmse / p["noise"], "noise_estimate_mm": 1e3 * fit.noise,
        "trustworthy": fit.trustworthy, "reason": fit.reason, "iterations": fit.iterations,
        "n_simulations": fit.n_simulations, "wall_time_s": wall, "cpu_time_s": cpu,
    }


def _table(rows) -> str:
    cols = [("case", "{:d}"), ("b_init_Nm", "{:.2e}"), ("ratio", "{:.3f}"), ("kappa0_per_m", "{:.1f}"),
            ("areal_mass_gsm", "{:.0f}"), ("chord_deg", "{:.1f}"), ("overhang_mm", "{:.1f}"),
            ("clamp_kappa_over_kappa0", "{:.1f}"), ("b_init_err_pct", "{:+.2f}"), ("b_init_sd_pct", "{:.2f}"),
            ("b_init_determined", "{}"), ("b_init_ok", "{}"), ("b_inf_err_pct", "{:+.1f}"),
            ("b_inf_sd_pct", "{:.1f}"), ("b_inf_determined", "{}"), ("rmse_over_noise", "{:.2f}"),
            ("noise_estimate_mm", "{:.4f}"), ("trustworthy", "{}"), ("n_simulations", "{:d}"), ("wall_time_s", "{:.1f}"),
            ("cpu_time_s", "{:.1f}")]
    lines = ["| " + " | ".join(c for c, _ in cols) + " |", "|" + "---|" * len(cols)]
    lines += ["| " + " | ".join(f.format(r[c]) for c, f in cols) + " |" for r in rows]
    return "\n".join(lines)


def summary(rows) -> dict:
    """The issue's figures over the rows."""
    t = np.array([r["wall_time_s"] for r in rows])
    cpu = np.array([r["cpu_time_s"] for r in rows])
    sharp = [r for r in rows if r["b_inf_sd_pct"] < 3.0]
    loose = [r for r in rows if not r["b_init_determined"]]
    return {
        "n_fits": len(rows),
        "worst_b_init_err_pct": max(abs(r["b_init_err_pct"]) for r in rows),
        "n_b_init_err_over_3pct": sum(abs(r["b_init_err_pct"]) > 3 for r in rows),
        "worst_b_init_err_pct_where_determined": max((abs(r["b_init_err_pct"]) for r in rows if r["b_init_determined"]),
                                                     default=float("nan")),
        "n_b_init_undetermined": len(loose),
        "b_init_undetermined_cases": [(r["case"], round(r["b_init_err_pct"], 2), round(r["b_init_sd_pct"], 2)) for r in loose],
        "worst_b_init_err_over_sd_where_undetermined": max((abs(r["b_init_err_pct"]) / r["b_init_sd_pct"] for r in loose),
                                                           default=float("nan")),
        "n_b_init_not_ok": sum(not r["b_init_ok"] for r in rows),
        "worst_rmse_over_noise": max(r["rmse_over_noise"] for r in rows),
        "n_b_inf_sd_under_3pct": len(sharp),
        "worst_b_inf_err_pct_where_sd_under_3pct": max((abs(r["b_inf_err_pct"]) for r in sharp), default=float("nan")),
        "n_not_trustworthy": sum(not r["trustworthy"] for r in rows),
        "median_fit_time_s": float(np.median(t)), "worst_fit_time_s": float(t.max()),
        "worst_fit_case": int(rows[int(np.argmax(t))]["case"]),
        "median_fit_cpu_s": float(np.median(cpu)), "worst_fit_cpu_s": float(cpu.max()),
        "first_fit_time_s_with_compile": float(t[0]), "median_fit_time_s_after_first": float(np.median(t[1:])) if t.size > 1 else float("nan"),
        "targets_met": bool(all(abs(r["b_init_err_pct"]) <= 3 and r["rmse_over_noise"] <= 1.5 for r in rows)
                            and all(abs(r["b_inf_err_pct"]) <= 10 for r in sharp) and np.median(t) <= 60),
        "targets_met_where_b_init_determined": bool(
            all(r["b_init_ok"] and r["rmse_over_noise"] <= 1.5 and r["trustworthy"] for r in rows)
            and all(abs(r["b_inf_err_pct"]) <= 10 for r in sharp) and np.median(t) <= 60),
    }


def run(quick: bool = False, n: int | None = None, out: pathlib.Path | None = None) -> dict:
    import jax

    jax.config.update("jax_enable_x64", True)
    sys.path.insert(0, str(HERE.parent / "tests"))
    from reference import cantilever_study as S

    n = n or (3 if quick else N_PROFILES)
    t0 = time.perf_counter()
    profiles = [S.noisy_profile(c, noise=NOISE, seed=i) for i, c in enumerate(S.study_laws(n, seed=SEED))]
    t_gen = time.perf_counter() - t0
    stamp = _dt.datetime.now(_dt.timezone.utc).strftime("%Y%m%dT%H%M%SZ")
    out = out or HERE / "results" / f"{stamp}-cantilever_fit-rows.md"
    out.parent.mkdir(parents=True, exist_ok=True)
    rows = []
    for i, p in enumerate(profiles):
        rows.append(fit_row(i, p))
        print(_table(rows).splitlines()[-1], flush=True)
        s = summary(rows)
        out.write_text(f"# Cantilever round trip (issue 18), {len(rows)} of {n} profiles, seed {SEED}, noise "
                       f"{NOISE * 1e3} mm\n\n" + "\n".join(f"- {k}: {v}" for k, v in s.items())
                       + f"\n- profile generation (elastica): {t_gen:.0f} s\n\n" + _table(rows) + "\n")
    return {**s, "table": str(out), "profile_generation_s": t_gen, "rows": rows}


if __name__ == "__main__":
    res = run(quick="--quick" in sys.argv)
    print({k: v for k, v in res.items() if k != "rows"})
