"""``jaxform wrinkles`` end to end on files, including bad input."""
import json

import meshio
import numpy as np
import pytest

from jaxform.cli import main
from jaxform.io.surface import UnitsWarning, read_point_cloud, read_surface, write_vtu
from test_metrics_wrinkles import draped_sheet


@pytest.fixture(scope="module")
def sheet_mm(tmp_path_factory):
    """The draped sheet with a wrinkle and a bridged region, written in mm as VTU."""
    x, f, bump, _ = draped_sheet(h=0.0015)
    path = tmp_path_factory.mktemp("mesh") / "sheet_mm.vtu"
    meshio.write(path, meshio.Mesh(x * 1e3, [("quad", f)]))
    return path, x, f, bump.max()


def test_wrinkles_command_on_a_mesh_in_mm(sheet_mm, tmp_out, capsys):
    path, x, f, bump_max = sheet_mm
    rc = main(["wrinkles", str(path), "--tool", "hemisphere:radius_mm=50", "--ply-thickness-mm",
               "0.3", "--out", str(tmp_out), "--section=-34,0,34,0"])
    assert rc == 0
    printed = capsys.readouterr().out
    assert "wrinkles.vtu" in printed and "summary.json" in printed
    s = json.loads((tmp_out / "summary.json").read_text())
    assert s["wrinkle_count"] == 1
    assert s["d_crit_m"] == pytest.approx(0.15e-3)
    assert s["zone_area_m2"]["bridging"] > s["zone_area_m2"]["wrinkle"] > 0
    assert s["max_wrinkle_amplitude_m"] == pytest.approx(0.45 * 0.3e-3 + bump_max, rel=1e-6)
    assert s["sections"][0]["wrinkle_count"] == 2  # the section crosses the bump and the lift
    for name in ("wrinkles.vtu", "distance.png", "kappa_max.png", "zones.png", "section_0.csv"):
        assert (tmp_out / name).stat().st_size > 0
    m = meshio.read(tmp_out / "wrinkles.vtu")
    np.testing.assert_allclose(m.points, x, atol=1e-12)  # read in mm, written in m
    assert {"distance_m", "kappa_max_per_m", "zone", "k1_per_m"} <= set(m.point_data)
    assert np.all(np.isfinite(m.point_data["kappa_max_per_m"]))
    # A rerun into its own folder replaces it (the section file of the first run goes); a folder
    # the command did not write is refused unless --force.
    args = ["wrinkles", str(path), "--tool", "hemisphere", "--ply-thickness-mm", "0.3", "--out", str(tmp_out)]
    assert main(args) == 0
    assert not (tmp_out / "section_0.csv").exists()
    other = tmp_out.parent / "theirs"
    other.mkdir()
    (other / "notes.txt").write_text("keep")
    args[-1] = str(other)
    assert main(args) == 2
    assert "not empty" in capsys.readouterr().err
    assert main(args + ["--force"]) == 0
    assert (other / "notes.txt").read_text() == "keep"


def test_tool_mesh_and_point_cloud(sheet_mm, tmp_path, capsys):
    from jaxform.io.tool_mesh import hemisphere_rig_mesh

    path, x, f, _ = sheet_mm
    tv, tf = hemisphere_rig_mesh(size=0.002, extent=0.06)
    tool_path = tmp_path / "tool.stl"
    meshio.write(tool_path, meshio.Mesh(tv * 1e3, [("triangle", tf)]))
    # a "scan": points 0.2 mm outside the simulated surface, along the sphere's radius (the
    # surface normal away from the bump and the lifted region)
    cloud = x[::7] * (1.0 + 0.0002 / np.linalg.norm(x[::7], axis=1, keepdims=True))
    cloud_path = tmp_path / "scan.csv"
    np.savetxt(cloud_path, cloud * 1e3, delimiter=",", header="x,y,z", comments="")
    out = tmp_path / "o"
    rc = main(["wrinkles", str(path), "--tool", str(tool_path), "--ply-thickness-mm", "0.3",
               "--out", str(out), "--cloud", str(cloud_path)])
    assert rc == 0
    s = json.loads((out / "summary.json").read_text())
    assert s["wrinkle_count"] == 1
    d = s["cloud"]["distance_m"]
    assert s["cloud"]["n_points"] == len(cloud)
    assert d["max"] <= 0.0002 + 1e-12 and d["median"] == pytest.approx(0.0002, rel=1e-3)
    assert (out / "cloud_distance.vtu").exists() and (out / "cloud_distance.png").exists()


def test_bad_input_messages(sheet_mm, tmp_path, capsys):
    path, x, f, _ = sheet_mm
    base = ["--ply-thickness-mm", "0.3", "--out", str(tmp_path / "o")]
    assert main(["wrinkles", str(path), "--tool", "cone"] + base) == 2
    assert "neither an existing file nor a preset" in capsys.readouterr().err
    assert main(["wrinkles", str(tmp_path / "missing.vtu"), "--tool", "plane"] + base) == 2
    # A tool file 1000 times smaller than the part (mixed units that the size guess cannot see).
    tv, tf = np.array([[0, 0, 0.05], [1e-4, 0, 0.05], [0, 1e-4, 0.05]]), np.array([[0, 1, 2]])
    tool_path = tmp_path / "tool.obj"
    meshio.write(tool_path, meshio.Mesh(tv, [("triangle", tf)]))
    rc = main(["wrinkles", str(path), "--tool", str(tool_path), "--tool-units", "m"] + base)
    assert rc == 2 and "mixed units" in capsys.readouterr().err
    # NaN coordinates
    bad = x.copy()
    bad[5, 2] = np.nan
    nan_path = tmp_path / "nan.vtu"
    meshio.write(nan_path, meshio.Mesh(bad, [("quad", f)]))
    assert main(["wrinkles", str(nan_path), "--tool", "hemisphere"] + base) == 2
    assert "non-finite" in capsys.readouterr().err
    # A volume mesh
    tet = tmp_path / "tet.vtu"
    meshio.write(tet, meshio.Mesh(np.eye(4, 3), [("tetra", np.array([[0, 1, 2, 3]]))]))
    assert main(["wrinkles", str(tet), "--tool", "hemisphere"] + base) == 2
    assert "volume mesh" in capsys.readouterr().err


def test_read_surface_formats_and_units(tmp_path):
    pts = np.array([[0, 0, 0], [10, 0, 0], [10, 10, 0], [0, 10, 0], [20, 0, 0.0], [99, 99, 99.0]])
    mesh = meshio.Mesh(pts, [("quad", np.array([[0, 1, 2, 3]])), ("triangle", np.array([[1, 4, 2]]))])
    for ext in ("vtu", "obj", "ply", "inp"):
        p = tmp_path / f"m.{ext}"
        meshio.write(p, mesh)
        with pytest.warns(UnitsWarning):
            read_surface(p, units="m")
        nodes, faces = read_surface(p, units="auto")
        assert faces.shape == (3, 3)  # mixed cells: quads split into triangles
        assert nodes.shape == (5, 3)  # the unused node is dropped
        np.testing.assert_allclose(np.ptp(nodes, axis=0), [0.02, 0.01, 0.0])
    stl = tmp_path / "m.stl"
    meshio.write(stl, meshio.Mesh(pts[:4] * 1e-3, [("triangle", np.array([[0, 1, 2], [0, 2, 3]]))]))
    nodes, faces = read_surface(stl)
    assert faces.shape == (2, 3) and nodes.max() == pytest.approx(0.01)
    quads = meshio.Mesh(pts[:4] * 1e-3, [("quad", np.array([[0, 1, 2, 3]]))])
    meshio.write(tmp_path / "q.vtu", quads)
    assert read_surface(tmp_path / "q.vtu")[1].shape == (1, 4)
    # point clouds
    np.savetxt(tmp_path / "c.xyz", pts * 1e-3)
    assert read_point_cloud(tmp_path / "c.xyz").shape == (6, 3)
    np.savetxt(tmp_path / "c.csv", pts[:, [2, 0, 1]], delimiter=",", header="z,x,y", comments="")
    np.testing.assert_allclose(read_point_cloud(tmp_path / "c.csv", units="mm"), pts * 1e-3)
    write_vtu(tmp_path / "cloud.vtu", pts * 1e-3, None, point_data={"d": np.arange(6.0)})
    meshio.write(tmp_path / "c.ply", meshio.Mesh(pts * 1e-3, []))
    assert read_point_cloud(tmp_path / "c.ply").shape == (6, 3)
