"""Plots of the material laws (the source paper's Figures 1 and 2), host side."""
from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from jaxform.materials import AsymmetricBending, Fabric

_LBM_STYLE = {"init": ("--", "B_init"), "41.5": (":", "B_41.5"), "inf": ("-.", "B_inf")}


def _sides(fabric: Fabric):
    law = fabric.bending[0]
    if isinstance(law, AsymmetricBending):
        return [("pos", law.pos, 0), ("neg", law.neg, 1)]
    return [("", law, 0)]


def bending_figure(fabric: Fabric, lbm: dict[str, tuple[float, float]], *, kappa_max: float | None = None):
    """Moment–curvature and stiffness–curvature of a fabric's fibre bending law.

    Args:
        fabric: a fabric with a bending law (the first family's law is plotted; the paper's
            fabrics use one law for both families).
        lbm: the linear-model constants to draw, ``{"init": (pos, neg), "41.5": ..., "inf": ...}``
            in N·m (e.g. ``jaxform.materials.TABLE1_LBM[fabric.name]``).
        kappa_max: upper end of the curvature axis, 1/m (default 5 × the largest ``kappa0``).

    Returns:
        The matplotlib figure (two panels, (a) M–kappa and (b) B–kappa; curvature in 1/m).
    """
    sides = _sides(fabric)
    if kappa_max is None:
        kappa_max = 5.0 * max(float(getattr(law, "kappa0", 20.0)) for _, law, _ in sides)
    k = np.linspace(0.0, kappa_max, 400)
    fig, (ax_m, ax_b) = plt.subplots(1, 2, figsize=(11, 4.2))
    colours = ["C0", "C3"]
    for (label, law, idx), colour in zip(sides, colours):
        suffix = f" ({label})" if label else ""
        ax_m.plot(k, np.asarray(law.moment(k)), color=colour, lw=2, label=f"NLBM{suffix}")
        ax_b.plot(k, np.asarray(law.stiffness(k)), color=colour, lw=2, label=f"NLBM{suffix}")
        for key, (style, name) in _LBM_STYLE.items():
            b = lbm[key][idx]
            ax_m.plot(k, b * k, color=colour, ls=style, lw=1, label=f"{name}{suffix} = {b:.2g} N·m")
            ax_b.axhline(b, color=colour, ls=style, lw=1, label=f"{name}{suffix}")
    ax_m.set_ylim(0, 1.15 * float(np.max([np.max(np.asarray(law.moment(k))) for _, law, _ in sides])))
    ax_m.set_xlabel("curvature κ (1/m)")
    ax_m.set_ylabel("bending moment per width M (N)")
    ax_m.set_title(f"(a) {fabric.name}: moment vs curvature")
    ax_b.set_xlabel("curvature κ (1/m)")
    ax_b.set_ylabel("bending stiffness B = dM/dκ (N·m)")
    ax_b.set_yscale("log")
    ax_b.set_title(f"(b) {fabric.name}: stiffness vs curvature")
    ax_m.legend(fontsize=7, loc="upper left")
    ax_b.legend(fontsize=7, loc="upper right")
    for ax in (ax_m, ax_b):
        ax.grid(alpha=0.3)
    fig.tight_layout()
    return fig


def shear_figure(fabrics: list[Fabric], *, gamma_max_deg: float = 60.0):
    """Normalised shear force against shear angle for several fabrics (positive and negative shear)."""
    g = np.radians(np.linspace(-gamma_max_deg, gamma_max_deg, 481))
    fig, ax = plt.subplots(figsize=(6, 4.2))
    for fabric in fabrics:
        ax.plot(np.degrees(g), np.asarray(fabric.shear.force(g)), lw=2, label=fabric.name)
    ax.axhline(0, color="k", lw=0.5)
    ax.axvline(0, color="k", lw=0.5)
    ax.set_xlabel("shear angle γ (°)")
    ax.set_ylabel("normalised shear force F_norm (N/m)")
    ax.set_title("In-plane shear laws (positive shear stretches the NCF stitch)")
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    return fig

