"""PNG maps of the wrinkle metric (host side, matplotlib Agg, no global pyplot state)."""
from __future__ import annotations

import pathlib

import numpy as np

from jaxform.geometry import quads_to_triangles

__all__ = ["plot_node_field", "plot_zones", "plot_density"]


def _triangles(faces) -> np.ndarray:
    return np.asarray(quads_to_triangles(faces))


def _figure():
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(6.4, 5.4), dpi=110)
    FigureCanvasAgg(fig)
    return fig


def _finish_map(fig, ax, title: str, path) -> pathlib.Path:
    """Label a top-view map (x, y in mm), write it as PNG and return the path."""
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_title(title)
    path = pathlib.Path(path)
    fig.savefig(path)
    return path


def plot_node_field(path, nodes, faces, values, *, title: str, label: str, scale: float = 1.0,
                    cmap: str = "viridis", vmin=None, vmax=None) -> pathlib.Path:
    """Top view (x, y in mm) of a nodal field, Gouraud-shaded. ``scale`` multiplies the values
    (e.g. 1e3 to show m as mm). ``faces=None`` draws the nodes as points (a point cloud)."""
    x = np.asarray(nodes) * 1e3
    v = np.asarray(values, dtype=float) * scale
    fig = _figure()
    ax = fig.add_subplot(1, 1, 1)
    if faces is None:
        art = ax.scatter(x[:, 0], x[:, 1], c=v, s=2, cmap=cmap, vmin=vmin, vmax=vmax)
    else:
        art = ax.tripcolor(x[:, 0], x[:, 1], _triangles(faces), v, shading="gouraud", cmap=cmap,
                           vmin=vmin, vmax=vmax)
    fig.colorbar(art, ax=ax, label=label)
    return _finish_map(fig, ax, title, path)


def plot_zones(path, nodes, faces, labels, *, title: str = "Zones") -> pathlib.Path:
    """Top view of the zone labels (0 conforming, 1 bridging, 2 wrinkle)."""
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    x = np.asarray(nodes) * 1e3
    lab = np.asarray(labels)
    tri = _triangles(faces)
    face_label = lab[tri].max(axis=1)  # a face takes its worst corner's zone
    colors = ["#d9d9d9", "#4f8fd1", "#d1493f"]
    fig = _figure()
    ax = fig.add_subplot(1, 1, 1)
    ax.tripcolor(x[:, 0], x[:, 1], tri, facecolors=face_label, cmap=ListedColormap(colors),
                 vmin=-0.5, vmax=2.5)
    ax.legend(handles=[Patch(color=c, label=n) for c, n in
                       zip(colors, ("conforming", "bridging", "wrinkle"))], loc="upper right")
    return _finish_map(fig, ax, title, path)


def plot_density(path, density, edges, *, title: str, label: str, scale: float = 1.0) -> pathlib.Path:
    """Probability density (histogram) as a step curve; ``scale`` multiplies the abscissa."""
    e = np.asarray(edges) * scale
    d = np.asarray(density) / scale
    fig = _figure()
    ax = fig.add_subplot(1, 1, 1)
    ax.stairs(d, e)
    ax.set_xlabel(label)
    ax.set_ylabel("probability density")
    ax.set_title(title)
    path = pathlib.Path(path)
    fig.savefig(path)
    return path
