"""Figures of the calibration fits (host side). The backend is the session's: importing this module
never switches it (a notebook keeps showing figures inline; a script without a display gets
matplotlib's own fallback, Agg)."""
from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from jaxform.plots.fields import save


def _finish(fig, axes, title: str):
    """Grid on every axis, the title over the figure, tight layout."""
    for a in axes:
        a.grid(alpha=0.3)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return fig


def cantilever_fit_figure(fit, profiles, *, title: str = ""):
    """Measured and fitted profiles (mm), and the fitted M–kappa and B–kappa curves.

    Args:
        fit: a :class:`jaxform.calibrate.CantileverFit`.
        profiles: the fitted :class:`jaxform.calibrate.Profile` list (m).
    """
    fig, axes = plt.subplots(1, 3, figsize=(14, 4.2))
    ax = axes[0]
    for i, (p, (xs, zs)) in enumerate(zip(profiles, fit.simulated)):
        c = f"C{i}"
        ax.plot(p.x * 1e3, p.z * 1e3, ".", color=c, ms=3, label=f"measured L={p.overhang * 1e3:.0f} mm")
        ax.plot(np.asarray(xs) * 1e3, np.asarray(zs) * 1e3, "-", color=c, lw=1.5, label="fitted")
    ax.set_xlabel("x, mm")
    ax.set_ylabel("z, mm")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_title(f"profiles (rmse {fit.rmse * 1e3:.3f} mm)")
    ax.legend(fontsize=7)
    kmax = max(fit.kappa_max, 1e-9)
    k = np.linspace(0.0, 1.5 * kmax, 400)
    law = fit.law
    axes[1].plot(k, np.asarray(law.moment(k)), lw=2)
    axes[1].axvline(kmax, color="grey", ls=":", label="largest curvature in the data")
    axes[1].set_xlabel("curvature, 1/m")
    axes[1].set_ylabel("moment per width M, N")
    axes[1].set_title("fitted M–kappa")
    axes[1].legend(fontsize=7)
    axes[2].plot(k, np.asarray(law.stiffness(k)) * 1e3, lw=2)
    axes[2].axvline(kmax, color="grey", ls=":")
    axes[2].set_xlabel("curvature, 1/m")
    axes[2].set_ylabel("B = dM/dkappa, N·mm")
    det = "determined" if fit.b_inf_determined else "NOT determined"
    det_init = "" if getattr(fit, "b_init_determined", True) else " NOT determined"
    axes[2].set_title(f"B_init {fit.b_init:.3g} N·m ± {100 * fit.sigma['b_init'] / fit.b_init:.1f} %{det_init}, "
                      f"B_inf {fit.b_inf:.3g} N·m ({det})", fontsize=9)
    return _finish(fig, axes, title)


def shear_fit_figure(fit, gamma, force, *, title: str = ""):
    """Picture-frame data and the fitted normalised shear force against shear angle (degrees)."""
    fig, ax = plt.subplots(figsize=(6, 4.2))
    g = np.asarray(gamma)
    ax.plot(np.degrees(g), force, ".", ms=3, label="data")
    gg = np.linspace(min(g.min(), 0.0), g.max(), 400)
    ax.plot(np.degrees(gg), np.asarray(fit.law.force(gg)), lw=2, label=f"fit ({fit.kind}), rmse {fit.rmse:.3g} N/m")
    ax.set_xlabel("shear angle, deg")
    ax.set_ylabel("normalised shear force, N/m")
    ax.grid(alpha=0.3)
    ax.legend()
    ax.set_title(title)
    fig.tight_layout()
    return fig


def wrinkle_fit_figure(fit, sections, *, truth=None, title: str = ""):
    """Measured, starting and fitted sections (mm), and the starting and fitted M–kappa and
    B–kappa curves up to past the curvature the wrinkles reach.

    Args:
        fit: a :class:`jaxform.calibrate.WrinkleFit`.
        sections: the fitted :class:`jaxform.calibrate.Section` list (m).
        truth: optional bending law to draw (a round trip's).
    """
    n = len(sections)
    fig, axes = plt.subplots(1, n + 2, figsize=(4.6 * (n + 2), 4.0))
    for ax, sec, y, y0, rms, rms0 in zip(axes, sections, fit.fitted, fit.initial, fit.rms_per_section,
                                         fit.rms_initial_per_section):
        ax.plot(sec.s * 1e3, sec.amplitude * 1e3, ".", ms=3, color="k", label="measured")
        ax.plot(sec.s * 1e3, np.asarray(y0) * 1e3, "-", lw=1, color="C1", label=f"starting law, RMS {rms0 * 1e3:.2f} mm")
        ax.plot(sec.s * 1e3, np.asarray(y) * 1e3, "-", lw=1.5, color="C0", label=f"fitted, RMS {rms * 1e3:.2f} mm")
        ax.set_xlabel("s along the section, mm")
        ax.set_ylabel("amplitude d_P, mm")
        ax.set_title(sec.name or "section", fontsize=9)
        ax.legend(fontsize=7)
    k = np.linspace(0.0, 1.5 * max(fit.kappa_reach, 1e-9), 400)
    laws = [("starting", fit.law_initial, "C1"), ("fitted", fit.law, "C0")] + ([("truth", truth, "k")] if truth else [])
    for name, law, c in laws:
        axes[n].plot(k, np.asarray(law.moment(k)), color=c, lw=1.5, ls="--" if name == "truth" else "-", label=name)
        axes[n + 1].plot(k, np.asarray(law.stiffness(k)) * 1e3, color=c, lw=1.5, ls="--" if name == "truth" else "-")
    band = getattr(fit, "moment_band", None) or {}
    if band:  # M and 2 sds where the fit reports them (up to kappa_reach)
        axes[n].errorbar(band["kappa_per_m"], band["moment_N"], yerr=2.0 * np.asarray(band["sd_N"]), fmt="none",
                         ecolor="C0", capsize=3, label="fitted M ± 2 sd" + ("" if band["determined"] else " (not determined)"))
    for ax, lab in ((axes[n], "moment per width M, N"), (axes[n + 1], "B = dM/dkappa, N·mm")):
        ax.axvline(fit.kappa_reach, color="grey", ls=":", label="curvature the wrinkles reach")
        ax.set_xlabel("curvature, 1/m")
        ax.set_ylabel(lab)
    axes[n].legend(fontsize=7)
    det = {k: "" if getattr(fit, "determined", {}).get(k, True) else " (not det.)" for k in ("b_init", "b_inf")}
    axes[n + 1].set_title(f"B_init {fit.values['b_init']:.3g} N·m{det['b_init']}, B_inf {fit.values['b_inf']:.3g} "
                          f"N·m{det['b_inf']}", fontsize=9)
    return _finish(fig, axes, title)


__all__ = ["cantilever_fit_figure", "shear_fit_figure", "wrinkle_fit_figure", "save"]
