"""Plots of a sweep (host side): each per-member scalar against each varied key."""
from __future__ import annotations

import pathlib

import matplotlib.pyplot as plt
import numpy as np

from jaxform.plots.fields import save

LABELS = {"max_shear_angle_deg": "max shear angle, °", "draw_in_edge_mid_mm": "draw-in, edge mid-sides, mm",
          "draw_in_corner_mm": "draw-in, corners, mm", "flange_wrinkles": "flange wrinkles",
          "max_ke_ie": "max KE/IE"}


def _numbers(values):
    try:
        return np.array([float(v) for v in values]), True
    except (TypeError, ValueError):
        return np.arange(len(values), dtype=float), False


def key_figure(key: str, rows, scalars):
    """One panel per scalar against ``key``'s values (rows: dicts with ``key``, the scalars and
    ``complete``); members differing in other keys are drawn as separate series; failed members
    are drawn as open markers at the values they reached."""
    levels = list(dict.fromkeys(r[key] for r in rows))
    xs, numeric = _numbers(levels)
    pos = dict(zip(levels, xs))
    fig, axes = plt.subplots(1, len(scalars), figsize=(3.2 * len(scalars), 3.0), squeeze=False)
    series: dict = {}
    for r in rows:
        tag = tuple((k, r[k]) for k in r.get("_varied", ()) if k != key)
        series.setdefault(tag, []).append(r)
    for ax, name in zip(axes[0], scalars):
        for tag, rs in series.items():
            rs = sorted(rs, key=lambda r: pos[r[key]])
            x = np.array([pos[r[key]] for r in rs])
            y = np.array([np.nan if r.get(name) in (None, "") else float(r[name]) for r in rs])
            ok = np.array([bool(r["complete"]) for r in rs])
            label = ", ".join(f"{k.rsplit('.', 1)[-1]}={v}" for k, v in tag) or None
            line, = ax.plot(x, y, "-", alpha=0.6, label=label)
            ax.plot(x[ok], y[ok], "o", color=line.get_color())
            ax.plot(x[~ok], y[~ok], "o", mfc="none", color=line.get_color())
        ax.set_xlabel(key)
        ax.set_ylabel(LABELS.get(name, name))
        if not numeric:
            ax.set_xticks(xs, levels, rotation=30)
        ax.grid(alpha=0.3)
    if len(series) > 1:
        axes[0][-1].legend(fontsize=7)
    fig.suptitle(f"sweep over {key} (open markers: failed members)", fontsize=9)
    fig.tight_layout()
    return fig


def sweep_plots(out, vary, rows, scalars) -> list[pathlib.Path]:
    """``sweep_<key>.png`` in ``out`` for each varied key (``vary``: ``[(key, values), ...]``)."""
    keys = [k for k, _ in vary]
    tagged = [dict(r, _varied=keys) for r in rows]
    paths = []
    for key in keys:
        safe = key.replace("/", "_")
        paths.append(save(key_figure(key, tagged, scalars), pathlib.Path(out) / f"sweep_{safe}.png"))
    return paths


__all__ = ["LABELS", "key_figure", "sweep_plots"]
