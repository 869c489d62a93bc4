"""Writing simulation frames for ParaView, and JSON summaries, so that partial runs stay readable.

``FrameWriter`` writes each frame as a VTU file (meshio) as soon as it is available and rewrites
the ``.pvd`` time-series index after every frame, each file written to a temporary name and
renamed into place. A run that is interrupted or fails therefore leaves a valid ``.pvd`` listing
every frame written so far. ``write_json`` is atomic in the same way.
"""
from __future__ import annotations

import json
import os
import pathlib
import xml.sax.saxutils as sax

import numpy as np

_CELL_TYPES = {3: "triangle", 4: "quad"}


def _atomic_write_bytes(path: pathlib.Path, data: bytes) -> None:
    tmp = path.with_name(f".{path.name}.tmp")
    tmp.write_bytes(data)
    os.replace(tmp, path)


def write_json(path, payload: dict) -> pathlib.Path:
    """Write ``payload`` as indented JSON, atomically (numpy scalars/arrays converted)."""
    path = pathlib.Path(path)

    def default(o):
        if isinstance(o, np.ndarray):
            return o.tolist()
        if isinstance(o, np.generic):
            return o.item()
        if hasattr(o, "__array__"):
            return np.asarray(o).tolist()
        raise TypeError(f"not JSON serialisable: {type(o).__name__}")

    _atomic_write_bytes(path, (json.dumps(payload, indent=2, default=default, allow_nan=False) + "\n").encode())
    return path


def read_frame_index(path) -> dict[str, float]:
    """The frames a ``.pvd`` index lists: ``{file name: time (s)}`` (what :class:`FrameWriter` wrote).

    Raises ValueError (naming the file) when the index cannot be read.
    """
    import xml.etree.ElementTree as ET

    path = pathlib.Path(path)
    try:
        return {ds.get("file"): float(ds.get("timestep")) for ds in ET.parse(path).getroot().iter("DataSet")}
    except (OSError, ET.ParseError, TypeError, ValueError) as err:
        raise ValueError(f"{path} is not a readable frame index ({err})") from None


class FrameWriter:
    """Write frames of one mesh as ``<stem>_<k>.vtu`` plus ``<stem>.pvd`` in a directory.

    Args:
        out_dir: directory (must exist).
        faces: (F, 3) or (F, 4) int connectivity (all cells of one kind).
        stem: file name stem.
    """

    def __init__(self, out_dir, faces, *, stem: str = "frames"):
        import meshio  # host side only

        self._meshio = meshio
        self.out_dir = pathlib.Path(out_dir)
        faces = np.asarray(faces)
        if faces.ndim != 2 or faces.shape[1] not in _CELL_TYPES:
            raise ValueError(f"FrameWriter: faces of shape {faces.shape}: need (F, 3) triangles or (F, 4) quads")
        self.cells = [(_CELL_TYPES[faces.shape[1]], faces.astype(np.int64))]
        self.stem = stem
        self.entries: list[tuple[float, str]] = []

    @property
    def pvd_path(self) -> pathlib.Path:
        return self.out_dir / f"{self.stem}.pvd"

    def write(self, time: float, points, point_data: dict | None = None, cell_data: dict | None = None) -> pathlib.Path:
        """Write one frame; ``points`` (N, 3) m at their deformed positions.

        ``point_data`` values are (N,) or (N, k) arrays; ``cell_data`` values (F,) or (F, k).
        Non-finite values are refused (a frame that cannot be opened helps nobody).
        """
        points = np.asarray(points, dtype=np.float64)
        if not np.all(np.isfinite(points)):
            raise ValueError(f"FrameWriter: frame at t = {time!r} s has non-finite node positions; not written")
        name = f"{self.stem}_{len(self.entries):05d}.vtu"
        mesh = self._meshio.Mesh(
            points,
            self.cells,
            point_data={k: np.asarray(v, dtype=np.float64) for k, v in (point_data or {}).items()},
            cell_data={k: [np.asarray(v, dtype=np.float64)] for k, v in (cell_data or {}).items()},
        )
        path = self.out_dir / name
        tmp = self.out_dir / f".{name}.tmp.vtu"
        self._meshio.write(tmp, mesh, file_format="vtu")
        os.replace(tmp, path)
        self.entries.append((float(time), name))
        self._write_pvd()
        return path

    def _write_pvd(self) -> None:
        rows = "\n".join(
            f'    <DataSet timestep="{t!r}" group="" part="0" file={sax.quoteattr(name)}/>' for t, name in self.entries
        )
        xml = (
            '<?xml version="1.0"?>\n'
            '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">\n'
            "  <Collection>\n"
            f"{rows}\n"
            "  </Collection>\n"
            "</VTKFile>\n"
        )
        _atomic_write_bytes(self.pvd_path, xml.encode())
