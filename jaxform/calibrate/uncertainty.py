"""A least-squares fit's Laplace (Gauss-Newton) covariance, checked against the loss itself.

``cov = c (J^T J)^-1`` holds where the loss is quadratic over the parameters' spread. Through a
buckled forming run it need not be: the run is chaotically sensitive to the law, the loss is rough
on the scale of a finite-difference step, and a Jacobian taken there can be much steeper than the
loss one or two standard deviations away (the joint wrinkle fit reported ``b_inf`` 1.66e-5 ± 0.06e-5
N·m against a truth of 3e-5: 22 of its own sds). :func:`checked_covariance` probes the loss at
``k`` standard deviations either side of the fit along each parameter, compares the measured rise
of the chi-square with the quadratic model's, and widens the covariance where the loss is flatter
than the model says (its secant curvature instead of the Jacobian's). A probe below the fit means
the fit is not at a minimum; that is reported, not hidden. Host-side numpy, no physics.
"""
from __future__ import annotations

import math
from typing import Callable, Sequence

import numpy as np

PROBE_SDS = 2.0
"""The probes lie this many (Laplace) standard deviations either side of the fit."""
MISFIT_P = 1e-3
"""A fit is consistent with its noise where the noise alone, at the true law, would leave a
chi-square at least as large with this probability or more (:func:`misfit`)."""
MIN_RATIO = 1e-12
"""A loss that did not rise widens a standard deviation by 1e6 (finite: a derived quantity that
does not depend on that parameter keeps its own)."""


def checked_covariance(rows: Callable[[np.ndarray], np.ndarray], q, r, J, cov, lo, hi, *, names: Sequence[str],
                       k: float = PROBE_SDS, prefetch: Callable[[list], object] | None = None) -> tuple[np.ndarray, dict]:
    """The covariance ``cov`` of the fit ``q``, widened where the loss rises less than its
    quadratic model ``|r + J d|^2`` between the fit and ``k`` standard deviations along a parameter.

    Args:
        rows: the weighted residual rows at a parameter vector (``(n,)``; non-finite where the
            model failed: the loss there counts as infinitely high).
        q: ``(p,)`` the fit; ``r``: ``(n,)`` its rows; ``J``: ``(n, p)`` the Jacobian the
            covariance came from; ``cov``: ``(p, p)``.
        lo, hi: ``(p,)`` bounds; a probe beyond one is moved onto it (the step it takes is used).
        names: the parameters' names, for the report.
        k: probe distance in standard deviations.
        prefetch: called once with every probe point before ``rows`` is (a batched model
            evaluates them together).
    Returns:
        ``(cov', report)``: ``cov' = D cov D`` with ``D_i = 1 / sqrt(ratio_i)`` where the smaller
        of the two measured rises is ``ratio_i < 1`` of the predicted one (``D_i = 1`` otherwise:
        a steeper loss keeps the Laplace figure; at most ``1 / sqrt(MIN_RATIO)``, where the loss
        did not rise at all);
        ``report`` holds, per parameter, the probe steps, the predicted and measured rises of the
        chi-square and the ratio, whether it was widened, and ``lower``: the probe with the lowest
        loss where one lies below the fit (else ``None``).
    """
    q, r, J, cov = (np.asarray(a, float) for a in (q, r, J, cov))
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    p = len(q)
    chi0 = float(r @ r)
    sd = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    probes = []  # (i, step, point)
    for i in range(p):
        if not (np.isfinite(sd[i]) and sd[i] > 0):
            continue
        for sign in (-1.0, 1.0):
            x = q.copy()
            x[i] = float(np.clip(q[i] + sign * k * sd[i], lo[i], hi[i]))
            if x[i] != q[i]:
                probes.append((i, x[i] - q[i], x))
    if prefetch is not None and probes:
        prefetch([x for _, _, x in probes])
    jtj = np.diag(J.T @ J)
    measured = [[math.nan, math.nan] for _ in range(p)]
    predicted = [[math.nan, math.nan] for _ in range(p)]
    steps = [[0.0, 0.0] for _ in range(p)]
    lower = None
    for i, h, x in probes:
        rx = np.asarray(rows(x), float)
        chi = float(rx @ rx) if np.all(np.isfinite(rx)) else math.inf
        side = int(h > 0)
        steps[i][side] = float(h)
        measured[i][side] = chi - chi0
        predicted[i][side] = float(h * h * jtj[i])
        if chi < chi0 and (lower is None or chi < lower["chi_square"]):
            lower = {"parameter": names[i], "q": x.tolist(), "chi_square": chi, "fit_chi_square": chi0}
    ratio = []
    for i in range(p):
        rs = [m / pr for m, pr in zip(measured[i], predicted[i]) if np.isfinite(pr) and pr > 0 and not math.isnan(m)]
        ratio.append(min(rs) if rs else math.nan)
    scale = np.ones(p)
    for i, rho in enumerate(ratio):
        if math.isnan(rho) or rho >= 1.0:
            continue
        scale[i] = 1.0 / math.sqrt(max(rho, MIN_RATIO))
    out = cov * np.outer(scale, scale)
    report = {"probe_sds": k, "parameters": list(names[:p]), "steps": steps, "predicted_rise": _json(predicted),
              "measured_rise": _json(measured), "ratio": _json(ratio), "widened_by": _json(scale.tolist()),
              "lower": lower}
    return out, report


def _json(v):
    """Non-finite floats as ``None`` (JSON has neither NaN nor infinity; ``None``: not probed,
    or a probe whose run failed / a loss that did not rise)."""
    if isinstance(v, list):
        return [_json(x) for x in v]
    return float(v) if math.isfinite(v) else None


def misfit(chi2: float, mean: float, var: float) -> dict:
    """How likely the measurement noise alone leaves a chi-square of at least ``chi2`` at the true
    law, where the rows' chi-square has mean ``mean`` and variance ``var`` there (correlated rows:
    smoothed sections): a scaled chi-square ``a chi2_k`` with those moments (``a = var / 2 mean``,
    ``k = 2 mean^2 / var``). ``consistent``: ``p_value >= MISFIT_P``. A fit far above it sits in a
    local minimum, has the wrong form of law, or was given too little noise; its Laplace standard
    deviations then describe that minimum only."""
    from scipy.stats import chi2 as scaled

    a, k = var / (2.0 * mean), 2.0 * mean * mean / var
    p = float(scaled.sf(chi2 / a, k))
    return {"chi_square": float(chi2), "expected": float(mean), "sd": math.sqrt(var), "p_value": p,
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


__all__ = ["PROBE_SDS", "MISFIT_P", "MIN_RATIO", "checked_covariance", "misfit", "block_misfit"]
