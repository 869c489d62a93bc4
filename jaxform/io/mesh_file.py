"""Fabric blanks from mesh files (meshio: Gmsh .msh, VTK/VTU, Abaqus .inp, OBJ, ...).

Host side: the file is read, its length unit converted to metres and its cells checked here, once;
the result is a :class:`jaxform.mesh.Mesh` built by :meth:`Mesh.from_arrays`.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from jaxform import units as _units
from jaxform.mesh import Mesh

_UNITS = {"m": 1.0, "mm": _units.MM}


def read_mesh(path, *, units: str = "m") -> Mesh:
    """Read a blank's surface mesh (triangles or quads, one kind) and return a one-ply :class:`Mesh`.

    Args:
        path: any format meshio reads.
        units: length unit of the file's coordinates, ``"m"`` (default) or ``"mm"``.

    Nodes not used by any surface cell are dropped (faces renumbered). Line and vertex cells are
    ignored; a file with both triangles and quads, or with no surface cells, is refused.
    """
    import meshio

    if units not in _UNITS:
        raise ValueError(f"read_mesh: units = {units!r}: must be one of {sorted(_UNITS)}")
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"read_mesh: no such file {path}")
    m = meshio.read(path)
    blocks = {}
    for block in m.cells:
        if block.type in ("triangle", "quad"):
            blocks.setdefault(block.type, []).append(np.asarray(block.data))
    if not blocks:
        kinds = sorted({b.type for b in m.cells})
        raise ValueError(f"read_mesh: {path} has no triangle or quad cells (found {kinds}); a blank needs a surface mesh")
    if len(blocks) > 1:
        raise ValueError(f"read_mesh: {path} mixes triangles and quads; convert it to one kind (e.g. all triangles)")
    (kind, parts), = blocks.items()
    faces = np.concatenate(parts, axis=0).astype(np.int64)
    pts = np.asarray(m.points, dtype=np.float64)
    if pts.shape[1] == 2:
        pts = np.concatenate([pts, np.zeros((len(pts), 1))], axis=1)
    used = np.unique(faces)
    remap = np.full(len(pts), -1, np.int64)
    remap[used] = np.arange(len(used))
    return Mesh.from_arrays(pts[used] * _UNITS[units], remap[faces])


__all__ = ["read_mesh"]
