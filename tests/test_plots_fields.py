"""Field maps draw what they are given and refuse mismatched data."""
import numpy as np
import pytest

from jaxform.plots.fields import curve, field_map, save


def _mesh():
    x, y = np.meshgrid(np.linspace(-0.05, 0.05, 6), np.linspace(-0.05, 0.05, 6), indexing="ij")
    nodes = np.stack([x.ravel(), y.ravel(), 0 * x.ravel()], 1)
    i = np.arange(36).reshape(6, 6)
    faces = np.stack([i[:-1, :-1].ravel(), i[1:, :-1].ravel(), i[1:, 1:].ravel(), i[:-1, 1:].ravel()], 1)
    return nodes, faces


def test_field_map_nodal_and_face_values(tmp_path):
    nodes, faces = _mesh()
    fig = field_map(nodes, faces, nodes[:, 0], title="x", label="m")
    coll = fig.axes[0].collections[0]
    np.testing.assert_allclose(coll.get_array(), nodes[faces, 0].mean(1))
    p = save(fig, tmp_path / "a.png")
    assert p.read_bytes()[:4] == b"\x89PNG"
    fig = field_map(nodes, faces, np.arange(len(faces)))
    np.testing.assert_allclose(fig.axes[0].collections[0].get_array(), np.arange(len(faces)))
    with pytest.raises(ValueError, match="match neither"):
        field_map(nodes, faces, np.zeros(7))
    save(curve([0, 1], [0, 2], xlabel="d (mm)", ylabel="F (N)"), tmp_path / "c.png")
