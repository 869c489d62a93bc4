"""Noisy cantilever side profiles from the independent elastica, spread over the fabrics' range.

numpy/scipy only, like :mod:`reference.elastica` (never imports ``jaxform``): the round-trip study of
the cantilever calibration (issue 18) fits these back. A seeded Latin hypercube over

    B_init 3e-4 .. 1e-2 N·m (log),  B_inf / B_init 0.02 .. 0.2 (log),  kappa0 2 .. 60 1/m (log),
    areal mass 150 .. 600 g/m²,  chord angle clamp -> tip 20 .. 75 deg,

each point a Voce law ``M = b_inf k + m0 (1 - exp(-k/kappa0))`` (``b_inf = ratio B_init``,
``m0 = (1 - ratio) B_init kappa0``) and the overhang at which its strip's chord reaches the angle
(least-droop branch: the strip slid out or loaded from flat). The profile is sampled at ``n_points``
x uniformly from 2 % to 99.5 % of the tip's x, with Gaussian noise of ``noise`` m on z.
"""
from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq
from scipy.stats import qmc

from reference import elastica as E

RANGES = {"b_init": (3e-4, 1e-2), "ratio": (0.02, 0.2), "kappa0": (2.0, 60.0), "areal_mass": (0.15, 0.60),
          "chord_deg": (20.0, 75.0)}


def overhang_for_chord(moment, areal_mass: float, chord: float, *, n: int = 41) -> float:
    """Overhang (m) at which the strip's clamp-to-tip chord is ``chord`` (rad) below horizontal."""
    b0 = float(moment.b_init)
    lc = (b0 / (areal_mass * E.GRAVITY)) ** (1.0 / 3.0)  # bending length of the initial stiffness

    def f(L):
        return E.solve_cantilever(moment, L, areal_mass, n=n)["chord_angle"] - chord

    lo, hi = 0.2 * lc, 1.0 * lc
    while f(hi) < 0:
        lo, hi = hi, 1.5 * hi
    while f(lo) > 0:
        lo *= 0.5
    return brentq(f, lo, hi, xtol=1e-6 * lc, rtol=1e-5)  # the chord to ~1e-4 rad: plenty for a study point


def study_laws(n: int, seed: int = 0) -> list[dict]:
    """``n`` cases of the Latin hypercube: dicts of ``b_inf, m0, kappa0, b_init, ratio, areal_mass, chord_deg``."""
    u = qmc.LatinHypercube(d=5, seed=seed).random(n)
    out = []
    for row in u:
        lg = {k: (math.log(a), math.log(b)) for k, (a, b) in RANGES.items() if k in ("b_init", "ratio", "kappa0")}
        b_init = math.exp(lg["b_init"][0] + row[0] * (lg["b_init"][1] - lg["b_init"][0]))
        ratio = math.exp(lg["ratio"][0] + row[1] * (lg["ratio"][1] - lg["ratio"][0]))
        kappa0 = math.exp(lg["kappa0"][0] + row[2] * (lg["kappa0"][1] - lg["kappa0"][0]))
        mass = RANGES["areal_mass"][0] + row[3] * (RANGES["areal_mass"][1] - RANGES["areal_mass"][0])
        chord = RANGES["chord_deg"][0] + row[4] * (RANGES["chord_deg"][1] - RANGES["chord_deg"][0])
        out.append(dict(b_inf=ratio * b_init, m0=(1.0 - ratio) * b_init * kappa0, kappa0=kappa0, b_init=b_init,
                        ratio=ratio, areal_mass=mass, chord_deg=chord))
    return out


def noisy_profile(case: dict, *, noise: float = 5e-5, n_points: int = 60, seed: int = 0, n_ref: int = 4001) -> dict:
    """One noisy side profile of ``case`` (from :func:`study_laws`): dict with ``x``, ``z`` (m),
    ``overhang`` (m), ``areal_mass`` (kg/m²), the true law's numbers and the elastica's
    ``tip_angle``, ``chord_angle`` (rad) and ``clamp_curvature`` (1/m)."""
    law = E.voce_moment(case["b_inf"], case["m0"], case["kappa0"])
    L = overhang_for_chord(law, case["areal_mass"], math.radians(case["chord_deg"]))
    r = E.solve_cantilever(law, L, case["areal_mass"], n=n_ref)
    xq = np.linspace(0.02 * r["x"][-1], 0.995 * r["x"][-1], n_points)
    zq = np.interp(xq, r["x"], r["z"]) + np.random.default_rng(seed).normal(0.0, noise, n_points)
    return dict(case, x=xq, z=zq, overhang=L, noise=noise, tip_angle=r["tip_angle"], chord_angle=r["chord_angle"],
                clamp_curvature=float(r["kappa"][0]))


__all__ = ["RANGES", "overhang_for_chord", "study_laws", "noisy_profile"]
