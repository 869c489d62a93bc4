"""The intersection checker (issue 19): a fold through itself is found, a fold lying on itself at
the contact distance is not, neighbouring faces are never counted; warped quads as the solver
split them; the CLI on files and runs."""
import json
import pathlib

import meshio
import numpy as np
import pytest

from jaxform.cli import main
from jaxform.io.frames import FrameWriter
from jaxform.metrics.intersections import intersecting_pairs, segments_cross_triangles, triangulate


def folded_strip(gap, *, tilt=0.0, length=1.0, width=0.3, ns=41, ny=7, quads=True):
    """A strip folded back over itself about a half circle of diameter ``gap``: the lower layer at
    z = 0, the upper at z = gap, descending by ``tilt`` per unit length as it runs back (a tilt
    large enough takes it through the lower layer). Returns ``(nodes (N, 3), faces, layer (F,))``."""
    r = 0.5 * gap
    arc = np.pi * r
    s = np.linspace(0.0, 2 * length + arc, ns)
    x = np.where(s <= length, s, np.where(s <= length + arc, length + r * np.sin((s - length) / max(r, 1e-30)),
                                          length - (s - length - arc)))
    z = np.where(s <= length, 0.0, np.where(s <= length + arc, r - r * np.cos((s - length) / max(r, 1e-30)),
                                            gap - tilt * (s - length - arc)))
    y = np.linspace(0.0, width, ny)
    X = np.repeat(x, ny)
    nodes = np.column_stack([X, np.tile(y, ns), np.repeat(z, ny)])
    idx = np.arange(ns * ny).reshape(ns, ny)
    q = np.column_stack([idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()])
    layer = np.repeat(np.where(s[:-1] < length, 1, np.where(s[:-1] >= length + arc, 2, 0)), ny - 1)
    if quads:
        return nodes, q, layer
    t, owner = triangulate(q)
    return nodes, t, layer[owner]


def test_fold_through_itself_is_found_fold_on_itself_is_not():
    h = 0.02
    for quads in (True, False):
        nodes, faces, layer = folded_strip(h, quads=quads)
        assert len(intersecting_pairs(nodes, faces)) == 0  # layers h apart
        nodes, faces, layer = folded_strip(h, tilt=0.1, quads=quads)
        pairs = intersecting_pairs(nodes, faces)
        assert len(pairs) > 0
        assert set(layer[pairs].ravel().tolist()) <= {1, 2}  # the upper layer through the lower
        assert np.all(layer[pairs[:, 0]] != layer[pairs[:, 1]])
    # the lower layer crossed along the line z = 0 of the descending upper layer, x = 1 - h / 0.1
    x_cross = 1.0 - h / 0.1
    cen = nodes[faces].mean(axis=1)
    assert np.all(np.abs(cen[pairs[:, 0], 0] - x_cross) < 0.1)


def test_touching_and_neighbouring_faces_are_not_intersections():
    # a fold closed flat (gap 1e-9 of the length) and a sharp crease: faces meet, never cross
    for gap in (1e-9, 1e-3):
        nodes, faces, _ = folded_strip(gap, ns=21)
        assert len(intersecting_pairs(nodes, faces)) == 0
    # two triangles sharing a corner: crossing beyond it is found, meeting only at it is not
    a = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    through = np.array([[0.0, 0, 0], [0.3, 0.3, 1], [0.3, 0.3, -1]])
    beside = np.array([[0.0, 0, 0], [-1, -1, 1], [-1, 0, -1]])
    for other, expected in ((through, 1), (beside, 0)):
        nodes = np.vstack([a, other[1:]])
        faces = np.array([[0, 1, 2], [0, 3, 4]])
        assert len(intersecting_pairs(nodes, faces)) == expected
    # sharing an edge: a fin folded flat onto its neighbour is not counted
    nodes = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0.2, 0.9, 0]])
    assert len(intersecting_pairs(nodes, np.array([[0, 1, 2], [0, 1, 3]]))) == 0


def test_broad_phase_misses_nothing_on_a_triangle_soup():
    rng = np.random.default_rng(0)
    n = 120
    cen = rng.uniform(0, 1, (n, 3))
    nodes = (cen[:, None, :] + rng.normal(0, 0.08, (n, 3, 3))).reshape(-1, 3)
    faces = np.arange(3 * n).reshape(n, 3)
    found = {tuple(p) for p in intersecting_pairs(nodes, faces).tolist()}
    i, j = np.triu_indices(n, 1)
    p = nodes[faces]
    hit = np.zeros(len(i), bool)
    for k in range(3):
        hit |= segments_cross_triangles(p[i, k], p[i, (k + 1) % 3], p[j, 0], p[j, 1], p[j, 2])
        hit |= segments_cross_triangles(p[j, k], p[j, (k + 1) % 3], p[i, 0], p[i, 1], p[i, 2])
    brute = set(zip(i[hit].tolist(), j[hit].tolist()))
    assert found == brute and len(brute) > 10


def test_check_intersections_command(tmp_path, capsys):
    h = 0.02
    ok, faces, _ = folded_strip(h)
    bad, _, _ = folded_strip(h, tilt=0.1)
    good_file, bad_file = tmp_path / "ok.vtu", tmp_path / "bad.obj"
    meshio.write(good_file, meshio.Mesh(ok, [("quad", faces)]))
    t, _ = triangulate(faces)
    meshio.write(bad_file, meshio.Mesh(bad * 1e3, [("triangle", t)]))  # any units: scale-free
    assert main(["check-intersections", str(good_file)]) == 0
    assert "0 intersecting pairs" in capsys.readouterr().out
    report = tmp_path / "r.json"
    assert main(["check-intersections", str(bad_file), "--json", str(report)]) == 1
    assert "intersecting pairs" in capsys.readouterr().out
    assert json.loads(report.read_text())["intersecting_pairs"] > 0
    # a run folder: its last frame (by time) is checked, ply pairs named
    run = tmp_path / "run"
    run.mkdir()
    w = FrameWriter(run, faces)
    ply = np.ones(len(ok))
    w.write(0.0, ok, point_data={"ply_id": ply})
    w.write(1.0, bad, point_data={"ply_id": ply})
    assert main(["check-intersections", str(run)]) == 1
    out = capsys.readouterr().out
    assert "frames_00001.vtu" in out and "ply 1:" in out
    # bad input: exit 2 with a message
    assert main(["check-intersections", str(tmp_path / "missing.vtu")]) == 2
    assert main(["check-intersections", str(tmp_path)]) == 2
    assert "frames.pvd" in capsys.readouterr().err


@pytest.mark.parametrize("n", [0, 1])
def test_tiny_meshes(n):
    nodes = np.zeros((3, 3))
    nodes[1, 0] = nodes[2, 1] = 1.0
    faces = np.zeros((0, 3), int) if n == 0 else np.array([[0, 1, 2]])
    assert intersecting_pairs(nodes, faces).shape == (0, 2)


def test_a_warped_quad_is_checked_as_the_solver_split_it():
    # quad A with corners 1 and 3 raised: split along 0-2 it is a valley, along 1-3 a ridge; a
    # vertical fin over the 0-2 diagonal crosses the ridge only
    nodes = np.array([[0.0, 0, 0], [1, 0, 1], [1, 1, 0], [0, 1, 1],
                      [0.1, 0.1, 0.25], [0.9, 0.9, 0.25], [0.9, 0.9, 0.75], [0.1, 0.1, 0.75]])
    quads = np.array([[0, 1, 2, 3], [4, 5, 6, 7]])
    assert len(intersecting_pairs(nodes, quads)) == 0
    split = np.array([[0, 1, 3], [1, 2, 3], [4, 5, 6], [4, 6, 7]])
    assert intersecting_pairs(nodes, quads, triangles=split).tolist() == [[0, 1]]
    with pytest.raises(ValueError, match="triangles of shape"):
        intersecting_pairs(nodes, quads, triangles=split[:3])


def test_a_run_folder_is_checked_with_the_rig_triangles():
    from jaxform import cases
    from jaxform.cli.check import _run_triangles
    from jaxform.forming import rig

    case = cases.with_element_size(cases.load("case-b-woven-nlbm"), 25e-3)
    mesh = rig.build_mesh(case)
    n = int(round(np.sqrt(mesh.n_nodes / 2)))
    quads = rig.grid_quads(n, n, 2)
    ply = np.repeat([1, 2], mesh.n_nodes // 2)
    tris = _run_triangles(pathlib.Path("."), np.asarray(mesh.nodes), quads, ply)
    np.testing.assert_array_equal(tris, np.asarray(mesh.tris))
    assert _run_triangles(pathlib.Path("."), np.asarray(mesh.nodes), quads[::-1], ply) is None  # not a rig grid
