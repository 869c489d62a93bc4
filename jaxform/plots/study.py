"""Figures of the paper study (``jaxform study paper``), the analogues of the paper's figures.

Each function takes the arrays of :func:`jaxform.study.measures.measure_frame` (``x``, ``faces``,
``data``, ``kappa_max``, ``sections``) keyed by run name, draws one figure and returns it.
"""
from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from jaxform.plots.fields import field_map

_LABELS = {"nlbm": "NLBM", "lbm-init": "LBM B_init", "lbm-41": "LBM B_41.5", "lbm-inf": "LBM B_inf",
           "membrane": "membrane only"}


def label(name: str) -> str:
    """``case-a-woven-lbm-41`` -> ``LBM B_41.5``."""
    for key, text in _LABELS.items():
        if name.endswith("-" + key):
            return text
    return name


def _draw_sections(ax, sections):
    for name, (a, b) in sections.items():
        ax.plot([1e3 * a[0], 1e3 * b[0]], [1e3 * a[1], 1e3 * b[1]], "w-", lw=1.2)
        ax.plot([1e3 * a[0], 1e3 * b[0]], [1e3 * a[1], 1e3 * b[1]], "k--", lw=0.8)
        ax.annotate(name, (1e3 * b[0], 1e3 * b[1]), fontsize=8)


def deviation_maps(arrays: dict, sections: dict, *, title: str):
    """Deviation from the tool (mm) of every run side by side, one colour scale, the sections drawn
    (the paper's Fig. 7 and 10)."""
    names = list(arrays)
    vmax = max(float(np.max(a["data"]["deviation_m"])) for a in arrays.values()) * 1e3
    fig, axes = plt.subplots(1, len(names), figsize=(4.2 * len(names), 3.9), squeeze=False)
    for ax, n in zip(axes[0], names):
        a = arrays[n]
        field_map(a["x"], a["faces"], 1e3 * a["data"]["deviation_m"], title=label(n), label="deviation, mm",
                  cmap="viridis", vmin=0.0, vmax=vmax, ax=ax)
        _draw_sections(ax, sections)
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def section_plots(arrays: dict, *, title: str):
    """The sections A-A' and B-B' of every run (the paper's Fig. 8 and 11): deviation (mm) along
    the section (mm from its start), gaps where the section leaves the ply."""
    first = next(iter(arrays.values()))
    keys = list(first["sections"])
    fig, axes = plt.subplots(1, len(keys), figsize=(6.0 * len(keys), 3.8), squeeze=False)
    for ax, key in zip(axes[0], keys):
        for n, a in arrays.items():
            s, v, valid = a["sections"][key]
            ax.plot(1e3 * s, np.where(valid, 1e3 * v, np.nan), lw=1.3, label=label(n))
        ax.set_xlabel(f"position along {key}, mm")
        ax.set_ylabel("deviation from the tool, mm")
        ax.set_title(key)
        ax.grid(alpha=0.3)
    axes[0][0].legend(fontsize=8)
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def moment_figure(lbm: dict, nlbm: dict, *, names=("LBM B_41.5", "NLBM"), title: str):
    """M_f^RMS maps of two runs and their probability densities (the paper's Fig. 9 and 13)."""
    from jaxform.metrics import probability_density

    fig, axes = plt.subplots(1, 3, figsize=(14.0, 4.0))
    vmax = 1e3 * max(float(np.max(a["data"]["M_f_rms_N"])) for a in (lbm, nlbm))
    for ax, a, n in zip(axes[:2], (lbm, nlbm), names):
        field_map(a["x"], a["faces"], 1e3 * a["data"]["M_f_rms_N"], title=n, label="M_f^RMS, mN", cmap="magma",
                  vmin=0.0, vmax=vmax, ax=ax)
    for a, n in zip((lbm, nlbm), names):
        v = 1e3 * a["data"]["M_f_rms_N"]
        dens, edges = (np.asarray(z) for z in probability_density(v, bins=40, value_range=(0.0, vmax)))
        axes[2].plot(0.5 * (edges[1:] + edges[:-1]), dens, lw=1.5, label=n)
    axes[2].set_yscale("log")
    axes[2].set_xlabel("M_f^RMS, mN")
    axes[2].set_ylabel("probability density, 1/mN")
    axes[2].legend()
    axes[2].grid(alpha=0.3)
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def stroke_figure(frames: dict, *, title: str):
    """Shear angle (deg) and deviation (mm) at several strokes (the paper's Fig. 12); ``frames``:
    ``{"30 mm": arrays, ...}``."""
    fig, axes = plt.subplots(2, len(frames), figsize=(4.3 * len(frames), 7.6), squeeze=False)
    gmax = max(float(np.max(np.abs(a["data"]["shear_angle_deg"]))) for a in frames.values())
    dmax = 1e3 * max(float(np.max(a["data"]["deviation_m"])) for a in frames.values())
    for j, (key, a) in enumerate(frames.items()):
        field_map(a["x"], a["faces"], a["data"]["shear_angle_deg"], title=f"shear angle, {key}", label="deg",
                  cmap="coolwarm", vmin=-gmax, vmax=gmax, ax=axes[0][j])
        field_map(a["x"], a["faces"], 1e3 * a["data"]["deviation_m"], title=f"deviation, {key}", label="mm",
                  vmin=0.0, vmax=dmax, ax=axes[1][j])
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def case_b_figure(arrays: dict, *, title: str):
    """Deviation (mm), kappa_max (1/m) and the smaller fibre strain of ply 1 of each Case B run
    (the paper's Fig. 14 and 15)."""
    fig, axes = plt.subplots(len(arrays), 3, figsize=(13.5, 4.0 * len(arrays)), squeeze=False)
    for i, (n, a) in enumerate(arrays.items()):
        strain = a["data"]["fibre_strain"]
        strain = strain.min(axis=1) if strain.ndim == 2 else strain
        field_map(a["x"], a["faces"], 1e3 * a["data"]["deviation_m"], title=f"{n}: deviation", label="mm",
                  vmin=0.0, ax=axes[i][0])
        if a.get("kappa_max") is not None:
            field_map(a["x"], a["faces"], a["kappa_max"], title=f"{n}: kappa_max", label="1/m", cmap="inferno",
                      vmin=0.0, vmax=1500.0, ax=axes[i][1])
        s = float(np.max(np.abs(strain))) or 1.0
        field_map(a["x"], a["faces"], strain, title=f"{n}: fibre strain (smaller)", label="-", cmap="coolwarm",
                  vmin=-s, vmax=s, ax=axes[i][2])
    fig.suptitle(title)
    fig.tight_layout()
    return fig


__all__ = ["label", "deviation_maps", "section_plots", "moment_figure", "stroke_figure", "case_b_figure"]
