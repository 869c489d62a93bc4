"""A least-squares fit's Laplace (Gauss-Newton) covariance, checked against the loss itself.

``cov = c (J^T J)^-1`` holds where the loss is quadratic over the parameters' spread. Through a
buckled forming run it need not be: the run is chaotically sensitive to the law, the loss is rough
on the scale of a finite-difference step, and a Jacobian taken there can be much steeper than the
loss one or two standard deviations away (the joint wrinkle fit reported ``b_inf`` 1.66e-5 ± 0.06e-5
N·m against a truth of 3e-5: 22 of its own sds). :func:`checked_covariance` probes the loss along
the covariance's principal axes, compares the measured rise of the chi-square with the quadratic
model's, and widens the covariance along an axis where the loss is flatter than the model says
(the secant curvature of its probes instead of the Jacobian's).

Why principal axes, further out, and profiled. A wrinkle fit determines the moment M(kappa) up to
the curvature the part reaches; laws with the same M there lie in a long, narrow valley of the
loss that runs obliquely to every parameter (the Voce split ``b_inf``, ``m0``, ``kappa0``). Probes
along each parameter found the loss as steep as modelled (rises 0.83-1.0 of the predicted ones)
while the truth lay 8-20 sds away along the valley (record 20261205T-qs-joint-2profiles). Along the
valley the rough loss rises by its roughness, about constant, more than by the small quadratic term
a step of two sds adds, and a Jacobian made steep by the roughness need not even make the valley the
flattest axis. One distance cannot tell the two apart; so every axis is probed again
:data:`EXTEND_FACTOR` times further out, and again while the secant's standard deviation (of the
flatter side: a valley can be one-sided) keeps growing by :data:`GROW` or more per step (a constant
rise: the roughness, not the curvature, set it), at most :data:`EXTEND_ROUNDS` times. An axis whose last step
still grew, or that the bounds stopped, is ``open``: its standard deviation is only a lower bound.
A straight probe leaves a narrow valley that its axis misses by a few degrees and climbs the wall
(on the joint fit, 8 sds out along the flattest axis the chi-square rose 3-11x more than modelled
while the truth, 18 sds along it, lies only 65 above the fit); so where the model says re-fitting
the other axes at a probe (one Gauss-Newton step) lowers the chi-square by more than the axis's
two-sd rise, that point is run too and the lower of the two read: the profile of the loss along the
axis, as a profile likelihood reads it. 4 p to about 16 p runs. A probe below the fit means the fit
is not at a minimum; that is reported, not hidden. Host-side numpy, no physics.
"""
from __future__ import annotations

import math
from typing import Callable, Sequence

import numpy as np

PROBE_SDS = 2.0
"""The first probes lie this many (Laplace) standard deviations either side of the fit."""
EXTEND_FACTOR = 4.0
"""Each further probe of an axis lies this many times further out than the one before."""
EXTEND_ROUNDS = 3
"""At most this many further probes per axis (out to ``PROBE_SDS * EXTEND_FACTOR**3`` = 128 sds)."""
GROW = 2.0
"""The probes of an axis go on while the secant standard deviation grows by this factor per step."""
MISFIT_P = 1e-3
"""A fit is consistent with its noise where the noise alone, at the true law, would leave a
chi-square at least as large with this probability or more (:func:`misfit`)."""
LOWER_SDS = 1.0
"""A probe below the fit says the fit is not at a minimum where its chi-square is lower by more
than the model's rise over this many standard deviations (less: within the loss's roughness)."""
ROUGH_SDS = 3.0
"""... and by more than this many times the loss's roughness: the rms difference of the chi-square
between the two first probes of an axis over sqrt 2 (their mean difference is the loss's slope at
the fit, zero at a minimum)."""
MIN_RATIO = 1e-12
"""A loss that did not rise widens a standard deviation by 1e6 (finite: a derived quantity that
does not depend on that parameter keeps its own)."""


def checked_covariance(rows: Callable[[np.ndarray], np.ndarray], q, r, J, cov, lo, hi, *, names: Sequence[str],
                       k: float = PROBE_SDS, prefetch: Callable[[list], object] | None = None,
                       rounds: int = EXTEND_ROUNDS) -> tuple[np.ndarray, dict]:
    """The covariance ``cov`` of the fit ``q``, widened along each of its principal axes where the
    loss rises less than its quadratic model ``|r + J d|^2`` (module docstring).

    Args:
        rows: the weighted residual rows at a parameter vector (``(n,)``; non-finite where the
            model failed: the loss there counts as infinitely high).
        q: ``(p,)`` the fit; ``r``: ``(n,)`` its rows; ``J``: ``(n, p)`` the Jacobian the
            covariance came from; ``cov``: ``(p, p)``.
        lo, hi: ``(p,)`` bounds; a probe beyond one is moved back along its axis onto it (the
            step it takes is used).
        names: the parameters' names, for the report.
        k: distance of the first probes, in the axis's standard deviations.
        prefetch: called with every probe point of a round before ``rows`` is (a batched model
            evaluates them together).
        rounds: further probes of an axis at most (:data:`EXTEND_ROUNDS`; 0: the first only).
    Returns:
        ``(cov', report)``: ``cov' = V diag(s^2) V^T`` over the axes ``V`` of ``cov``, ``s`` the
        largest of the Laplace standard deviation and the secant ones of the axis's rounds of probes,
        ``sd sqrt(predicted / measured)`` with the rise of the chi-square on the flatter side (at most
        ``1 / sqrt(MIN_RATIO)`` times the Laplace sd, where the loss never rose; :func:`open_share`
        says how much of a quantity's variance is only a lower bound);
        ``report``: per axis its ``direction``, ``laplace_sd``, ``sd``, ``widened_by``, ``open``,
        ``probes`` (round, step, predicted and measured rise) and ``sd_per_round``; ``roughness``;
        ``lower``: the probe with the lowest loss where one lies below the fit (else ``None``), and
        whether that is ``significant`` (:data:`LOWER_SDS`, :data:`ROUGH_SDS`).
    """
    q, r, J, cov = (np.asarray(a, float) for a in (q, r, J, cov))
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    p = len(q)
    chi0 = float(r @ r)
    lam, V = np.linalg.eigh(0.5 * (cov + cov.T))
    sd = np.sqrt(np.clip(lam, 0.0, None))
    g = np.einsum("ij,ij->j", J @ V, J @ V)  # the model's rise per squared step along each axis
    axes = [{"direction": V[:, j].tolist(), "laplace_sd": float(sd[j]), "probes": []} for j in range(p)]
    lower = None

    def probe(todo, n):  # [(axis, t)] in round n: both sides of each axis, one batch; then the profiled points
        pts = [(j, s * _reach(q, s * V[:, j], t, lo, hi)) for j, t in todo for s in (-1.0, 1.0)]
        pts = [(j, h, q + h * V[:, j]) for j, h in pts if h != 0.0]
        prof = []
        for (j, h, x), (rx, chi) in zip(pts, _evaluate(rows, [x for _, _, x in pts], prefetch)):
            e = {"round": n, "step": float(h), "step_sds": float(abs(h) / sd[j]), "predicted_rise": float(h * h * g[j]),
                 "measured_rise": chi - chi0, "on_axis_rise": chi - chi0}
            axes[j]["probes"].append(e)
            note(j, e, x, chi)
            if math.isfinite(chi):  # re-fit the other axes by the model (one Gauss-Newton step): the profile
                Vo = np.delete(V, j, axis=1)
                d = np.linalg.lstsq(J @ Vo, -rx, rcond=None)[0]
                if chi - float(np.sum((rx + J @ Vo @ d) ** 2)) > k * k * lam[j] * g[j]:
                    prof.append((j, e, np.clip(x + Vo @ d, lo, hi)))
        for (j, e, xo), (_, chi) in zip(prof, _evaluate(rows, [x for _, _, x in prof], prefetch)):
            e["profiled_q"], e["profiled_rise"] = xo.tolist(), chi - chi0
            e["measured_rise"] = min(e["measured_rise"], chi - chi0)
            note(j, e, xo, chi)

    def note(j, e, x, chi):
        nonlocal lower
        if chi < chi0 and (lower is None or chi < lower["chi_square"]):
            lower = {"axis": j, "direction": axes[j]["direction"], "step_sds": e["step_sds"], "q": x.tolist(),
                     "chi_square": chi, "fit_chi_square": chi0, "within": float(LOWER_SDS**2 * lam[j] * g[j])}

    def est(j, n):  # the secant sd of round n's probes of axis j, of the flatter side (a valley can be one-sided)
        pr = [e for e in axes[j]["probes"] if e["round"] == n]
        return max(sd[j] * math.sqrt(e["predicted_rise"] / e["measured_rise"]) if e["measured_rise"] > 0 else math.inf
                   for e in pr)

    def growing(j, n):  # on while the estimate grows by GROW (or the loss has not yet risen): roughness set it
        e, before = est(j, n), [est(j, m) for m in range(n) if 0 < est(j, m) < math.inf]
        return not math.isfinite(e) or (e > 0 and (not before or e >= GROW * before[-1]))

    ok = [j for j in range(p) if np.isfinite(sd[j]) and sd[j] > 0 and g[j] > 0]
    probe([(j, k * sd[j]) for j in ok], 0)
    last = {j: 0 for j in ok if axes[j]["probes"]}
    grow = list(last)  # every axis at least once further out: one distance cannot tell curvature from roughness
    t = {j: k * sd[j] for j in grow}
    opened = set()
    for n in range(1, int(rounds) + 1):
        stuck = [j for j in grow if max(_reach(q, s * V[:, j], EXTEND_FACTOR * t[j], lo, hi) for s in (-1.0, 1.0))
                 <= max(_reach(q, s * V[:, j], t[j], lo, hi) for s in (-1.0, 1.0))]
        opened |= set(stuck)  # wants more room than the bounds leave: its sd is a lower bound
        grow = [j for j in grow if j not in stuck]
        t = {j: EXTEND_FACTOR * t[j] for j in grow}
        if not grow:
            break
        probe([(j, t[j]) for j in grow], n)
        last.update({j: n for j in grow})
        grow = [j for j in grow if growing(j, n)]
    opened |= set(grow) if int(rounds) > 0 else set()
    s = sd.copy()
    for j, n in last.items():  # the widest secant of any round: further out a curved valley's wall may rise
        e = [est(j, m) for m in range(n + 1)]
        fin = [x for x in e if math.isfinite(x)]
        s[j] = max([sd[j]] + fin) if fin else sd[j] / math.sqrt(MIN_RATIO)
        opened |= set() if fin else {j}
    for j in range(p):
        axes[j].update(sd=float(s[j]), widened_by=float(s[j] / sd[j]) if sd[j] > 0 else 1.0, open=j in opened,
                       sd_per_round=[float(est(j, n)) for n in range(last.get(j, -1) + 1)])
    pairs = [a["probes"][0]["on_axis_rise"] - a["probes"][1]["on_axis_rise"] for a in axes
             if len(a["probes"]) >= 2 and a["probes"][1]["round"] == 0]
    pairs = [d for d in pairs if math.isfinite(d)]
    rough = math.sqrt(0.5 * float(np.mean(np.square(pairs)))) if pairs else 0.0
    if lower is not None:  # below the fit by more than the model's 1-sd rise and the loss's roughness
        lower["within"] = max(lower["within"], ROUGH_SDS * rough)
        lower["significant"] = bool(lower["fit_chi_square"] - lower["chi_square"] > lower["within"])
    report = {"probe_sds": k, "parameters": list(names[:p]), "axes": _json(axes), "roughness": rough,
              "lower": lower}
    return (V * s**2) @ V.T, report


def scatter_covariance(J, deviations, cov, r=None) -> tuple[np.ndarray, dict]:
    """The covariance the model's own scatter adds to a least-squares fit, and its report.

    A buckled forming run answers a law with a part that depends chaotically on small things (the
    blank's imperfections, a law a little off), so the data are matched by a dip of a rough loss: the
    fit's error has a part the measurement noise does not explain, correlated across many rows (a
    wrinkle that shifts moves all of them), which a reduced chi-square scaling, made for independent
    rows, understates. ``deviations`` ``(S, n)``: samples of that scatter, the weighted rows of the
    same law from ``S`` imperfect blanks minus the fit's own rows. Each moves the fit by ``-A d`` with
    ``A = (J^T J)^-1 J^T`` (the fit's own linear map), so the scatter adds ``A (d^T d / S) A^T``. A
    deviation is the difference of two draws, so its second moment is twice the scatter's own
    covariance, which is what the fit meets: the model's part scatters, and so did the measured one
    (a real blank's imperfections; the synthetic truth's own chaotic realisation).

    Returns ``(cov + that, report)``; report: ``samples``, ``rows_rms`` (the deviations' rms per row),
    ``share`` (per parameter, the scatter's share of the total variance), the scatter's own
    ``covariance`` and, given the fit's rows ``r``, ``chi_squares``: the fitted law's chi-square from
    each imperfect blank (a fit far below all of them fits its own blank's chaotic detail).

    Measured on the joint wrinkle benchmark (record 20261205T-qs-joint-chaos; four blanks, 0.03 mm
    imperfections): the scatter moves the fit by about the Laplace sds (B_init 0.26 % against 0.24 %)
    but widens the checked ones by 1-5 % only, while the fitted law scores 285-440 from the imperfect
    blanks against its own 255 and the truth's 320: the fit's error lies along the curved valley of
    equal M, which a linear map cannot see (:func:`checked_covariance` widens that axis)."""
    J, d, cov = (np.asarray(a, float) for a in (J, deviations, cov))
    d = d.reshape(-1, J.shape[0])
    rep = {"samples": len(d), "rows_rms": float(np.sqrt(np.mean(d**2))) if len(d) else 0.0}
    A = np.linalg.pinv(J.T @ J) @ J.T
    extra = A @ (d.T @ d / max(len(d), 1)) @ A.T
    total = cov + extra
    rep.update(share=(np.diag(extra) / np.maximum(np.diag(total), 1e-300)).tolist(), covariance=extra.tolist())
    if r is not None:
        rep["chi_squares"] = [float(np.sum((np.asarray(r, float) + x) ** 2)) for x in d]
    return total, rep


def open_share(report: dict, T=None) -> np.ndarray:
    """Per row of ``T`` (default: the parameters), the share of its variance under the checked
    covariance that comes from ``open`` axes (where that variance is only a lower bound)."""
    V = np.array([a["direction"] for a in report["axes"]]).T
    s = np.array([a["sd"] for a in report["axes"]])
    A = ((np.eye(len(s)) if T is None else np.asarray(T, float)) @ V) * s
    var = A**2
    opened = np.array([a["open"] for a in report["axes"]], bool)
    return var[:, opened].sum(axis=1) / np.maximum(var.sum(axis=1), 1e-300)


def _evaluate(rows, xs, prefetch) -> list:
    """``(rows, chi-square)`` at each of ``xs`` (``inf`` where the model failed), the batch prefetched."""
    if prefetch is not None and xs:
        prefetch(list(xs))
    out = []
    for x in xs:
        rx = np.asarray(rows(x), float)
        out.append((rx, float(rx @ rx) if np.all(np.isfinite(rx)) else math.inf))
    return out


def describe_axis(v, names) -> str:
    """A direction in (log) parameter space in words: its components over 0.1, the largest first."""
    return "(" + ", ".join(f"{c:+.2f} log {n}" for c, n in sorted(zip(v, names), key=lambda t: -abs(t[0]))
                           if abs(c) > 0.1) + ")"


def _reach(q, v, t, lo, hi) -> float:
    """The step along the unit vector ``v`` from ``q`` up to ``t`` that stays within the bounds."""
    with np.errstate(divide="ignore", invalid="ignore"):
        room = np.where(v > 0, (hi - q) / v, np.where(v < 0, (lo - q) / v, np.inf))
    return float(max(0.0, min(t, float(np.min(room)))))


def _json(v):
    """Non-finite floats as ``None`` (JSON has neither NaN nor infinity; ``None``: a probe whose
    run failed), through lists and dicts."""
    if isinstance(v, dict):
        return {k: _json(x) for k, x in v.items()}
    if isinstance(v, list):
        return [_json(x) for x in v]
    if isinstance(v, bool) or not isinstance(v, float):
        return v
    return v if math.isfinite(v) else None


def misfit(chi2: float, mean: float, var: float) -> dict:
    """How likely the measurement noise alone leaves a chi-square of at least ``chi2`` at the true
    law, where the rows' chi-square has mean ``mean`` and variance ``var`` there (correlated rows:
    smoothed sections): a scaled chi-square ``a chi2_k`` with those moments (``a = var / 2 mean``,
    ``k = 2 mean^2 / var``; ``scale`` is ``a``: the chi-square of one effective degree of freedom, 1
    for independent rows). ``consistent``: ``p_value >= MISFIT_P``. A fit far above it sits in a
    local minimum, has the wrong form of law, or was given too little noise; its Laplace standard
    deviations then describe that minimum only."""
    from scipy.stats import chi2 as scaled

    a, k = var / (2.0 * mean), 2.0 * mean * mean / var
    p = float(scaled.sf(chi2 / a, k))
    return {"chi_square": float(chi2), "expected": float(mean), "sd": math.sqrt(var), "scale": float(a), "p_value": p,
            "limit": MISFIT_P, "consistent": p >= MISFIT_P}


def block_misfit(r, blocks: Sequence[tuple]) -> dict:
    """:func:`misfit` of the residual rows ``r`` as a whole and of each block of data apart.

    ``blocks``: ``(name, rows, mean, var)`` per block (``rows`` a slice or index array into ``r``;
    ``mean``, ``var`` its chi-square's moments at the true law). A joint fit can pass the test as a
    whole while one block fails it: the sections' loss, rough and of many rows, can buy a better fit
    with a law that a few dozen cantilever rows reject (the joint wrinkle fit at 62.5 mm/s with a
    0.0125 log step: chi-square 401 against 205 +- 75, p = 0.014, while its profile, 0.081 mm RMS
    against 0.05 mm noise, is 156 on 60 rows, p = 2e-10; its B_init was 5.8 % off). The whole is
    consistent where its own test passes at :data:`MISFIT_P` and every block's at ``MISFIT_P / n``
    with ``n`` blocks (Bonferroni: at the true law the test as a whole still fails with at most twice
    :data:`MISFIT_P`). Returns :func:`misfit`'s dict for the whole with ``blocks`` (each block's)
    and ``failed`` (the names of the blocks that fail)."""
    r = np.asarray(r, float)
    out = misfit(float(r @ r), sum(b[2] for b in blocks), sum(b[3] for b in blocks))
    lim = MISFIT_P / len(blocks)
    each = {}
    for name, rows, mean, var in blocks:
        m = misfit(float(np.sum(r[rows] ** 2)), mean, var)
        each[name] = dict(m, limit=lim, consistent=m["p_value"] >= lim)
    failed = [k for k, m in each.items() if not m["consistent"]]
    return dict(out, consistent=out["consistent"] and not failed, blocks=each, failed=failed)


__all__ = ["PROBE_SDS", "EXTEND_FACTOR", "EXTEND_ROUNDS", "GROW", "LOWER_SDS", "ROUGH_SDS", "MISFIT_P", "MIN_RATIO",
           "checked_covariance", "scatter_covariance", "open_share", "describe_axis", "misfit", "block_misfit"]
