"""Maps of nodal or element fields on a fabric mesh, and simple curves, host side (matplotlib).

Used by the forming run (shear-angle map, out-of-plane deviation, punch force) and any script that
wants a quick top view of a field on a deformed ply.
"""
from __future__ import annotations

import pathlib

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.collections import PolyCollection


def field_map(nodes, faces, values, *, title: str = "", label: str = "", cmap: str = "viridis",
              vmin=None, vmax=None, ax=None, scale: float = 1e3, unit: str = "mm"):
    """Top view (x–y) of a field on a mesh.

    Args:
        nodes: (N, 3) node positions, m (deformed positions for a formed ply).
        faces: (F, 3) or (F, 4) connectivity.
        values: (N,) nodal values (averaged per face) or (F,) face values.
        scale: factor applied to coordinates for the axes (1e3: mm).
    Returns:
        The matplotlib figure.
    """
    nodes = np.asarray(nodes, dtype=float)
    faces = np.asarray(faces)
    values = np.asarray(values, dtype=float)
    if values.shape[0] == nodes.shape[0]:
        face_values = values[faces].mean(axis=1)
    elif values.shape[0] == faces.shape[0]:
        face_values = values
    else:
        raise ValueError(
            f"field_map: values of length {values.shape[0]} match neither the {nodes.shape[0]} nodes "
            f"nor the {faces.shape[0]} faces"
        )
    if ax is None:
        fig, ax = plt.subplots(figsize=(6.2, 5.2))
    else:
        fig = ax.figure
    polys = nodes[faces][..., :2] * scale
    coll = PolyCollection(polys, array=face_values, cmap=cmap, edgecolors="none")
    coll.set_clim(vmin if vmin is not None else np.nanmin(face_values), vmax if vmax is not None else np.nanmax(face_values))
    ax.add_collection(coll)
    ax.autoscale_view()
    ax.set_aspect("equal")
    ax.set_xlabel(f"x ({unit})")
    ax.set_ylabel(f"y ({unit})")
    ax.set_title(title)
    fig.colorbar(coll, ax=ax, label=label)
    return fig


def curve(x, y, *, xlabel: str, ylabel: str, title: str = "", label: str | None = None, ax=None):
    """A simple line plot (e.g. punch force against displacement)."""
    if ax is None:
        fig, ax = plt.subplots(figsize=(6, 4))
    else:
        fig = ax.figure
    ax.plot(np.asarray(x), np.asarray(y), lw=2, label=label)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.grid(alpha=0.3)
    if label:
        ax.legend()
    fig.tight_layout()
    return fig


def save(fig, path, dpi: int = 130) -> pathlib.Path:
    """Write a figure as PNG and close it."""
    path = pathlib.Path(path)
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    return path
