"""read_mesh: a small mesh written with meshio comes back as the same Mesh (quads and triangles)."""
import meshio
import numpy as np
import pytest

from jaxform.io.mesh_file import read_mesh
from jaxform.mesh import Mesh


@pytest.mark.parametrize("quads", [True, False])
def test_round_trip(tmp_path, quads):
    ref = Mesh.rectangle(0.04, 0.03, 0.01)
    faces = ref.faces if quads else np.asarray(ref.tris)
    kind = "quad" if quads else "triangle"
    pts_mm = np.asarray(ref.nodes) * 1000.0
    path = tmp_path / "blank.vtu"
    meshio.write(path, meshio.Mesh(pts_mm, [(kind, faces), ("line", faces[:2, :2])]))
    m = read_mesh(path, units="mm")
    np.testing.assert_allclose(np.asarray(m.nodes), np.asarray(ref.nodes), atol=1e-12)
    np.testing.assert_array_equal(np.asarray(m.tris), np.asarray(ref.tris))
    np.testing.assert_allclose(np.asarray(m.node_area), np.asarray(ref.node_area), rtol=1e-12)
    assert m.quads == quads
    m_m = read_mesh(path)  # metres: coordinates taken as they are
    np.testing.assert_allclose(np.asarray(m_m.nodes), pts_mm)


def test_refusals(tmp_path):
    with pytest.raises(ValueError, match="units"):
        read_mesh(tmp_path / "x.vtu", units="inch")
    with pytest.raises(FileNotFoundError):
        read_mesh(tmp_path / "missing.vtu")
    path = tmp_path / "lines.vtu"
    meshio.write(path, meshio.Mesh(np.zeros((3, 3)), [("line", np.array([[0, 1], [1, 2]]))]))
    with pytest.raises(ValueError, match="no triangle or quad"):
        read_mesh(path)
