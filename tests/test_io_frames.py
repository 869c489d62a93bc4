"""Frames for ParaView stay readable after every write (issue 4 infrastructure)."""
import json
import xml.etree.ElementTree as ET

import meshio
import numpy as np
import pytest

from jaxform.io.frames import FrameWriter, write_json


def _grid(n=4):
    x, y = np.meshgrid(np.linspace(0, 1e-2, n), np.linspace(0, 1e-2, n), indexing="ij")
    pts = np.stack([x.ravel(), y.ravel(), np.zeros(n * n)], axis=1)
    idx = np.arange(n * n).reshape(n, n)
    quads = np.stack([idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()], axis=1)
    return pts, quads


def test_each_frame_is_listed_in_a_valid_pvd_as_soon_as_written(tmp_path):
    pts, quads = _grid()
    w = FrameWriter(tmp_path, quads, stem="ply")
    for k in range(3):
        moved = pts + np.array([0, 0, 1e-3 * k])
        w.write(0.1 * k, moved, point_data={"shear_angle": np.full(len(pts), 0.1 * k)}, cell_data={"ply": np.zeros(len(quads))})
        tree = ET.parse(w.pvd_path)
        files = [d.attrib["file"] for d in tree.iter("DataSet")]
        assert len(files) == k + 1
        m = meshio.read(tmp_path / files[-1])
        np.testing.assert_allclose(m.points[:, 2], 1e-3 * k)
        np.testing.assert_allclose(m.point_data["shear_angle"], 0.1 * k)
    assert not list(tmp_path.glob(".*tmp*"))


def test_non_finite_frames_are_refused_and_earlier_frames_kept(tmp_path):
    pts, quads = _grid()
    w = FrameWriter(tmp_path, quads)
    w.write(0.0, pts)
    bad = pts.copy()
    bad[3, 2] = np.nan
    with pytest.raises(ValueError, match="non-finite"):
        w.write(0.1, bad)
    files = [d.attrib["file"] for d in ET.parse(w.pvd_path).iter("DataSet")]
    assert files == ["frames_00000.vtu"]


def test_write_json_is_atomic_and_converts_numpy(tmp_path):
    p = write_json(tmp_path / "summary.json", {"a": np.float32(1.5), "b": np.arange(3), "ok": True})
    assert json.loads(p.read_text()) == {"a": 1.5, "b": [0, 1, 2], "ok": True}
    with pytest.raises(ValueError):
        write_json(tmp_path / "bad.json", {"x": float("nan")})
