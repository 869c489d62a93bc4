"""``jaxform wrinkles`` end to end on files, including bad input."""
import json
import re

import meshio
import numpy as np
import pytest

from jaxform.cli import main
from helpers import FAST_SET
from jaxform.io.surface import UnitsWarning, read_point_cloud, read_surface, write_vtu
from _surfaces import draped_sheet


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


# ---------------------------------------------------------------------------------------------
# Issue 14 item 2: on jaxform's own output the tool is the run's rig, where it was at that frame
# ---------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def small_run(tmp_path_factory):
    """A 4 mm stroke of case A (25 mm elements, 3 frames): frames_00002.vtu is the last."""
    out = tmp_path_factory.mktemp("run") / "a"
    assert main(["run", "case-a-woven-nlbm", "--out", str(out), "--element-size-mm", "25", *FAST_SET,
                 "--set", "process.stroke_mm=4", "--set", "process.frames=3", "--quiet"]) == 0
    return out


def test_frame_of_a_run_is_measured_on_its_own_rig(small_run, tmp_path, capsys):
    frame = small_run / "frames_00002.vtu"
    run_summary = json.loads((small_run / "summary.json").read_text())
    h = 0.3e-3  # woven 38616
    # The README workflow: no --tool, no --ply-thickness-mm.
    out = tmp_path / "w"
    assert main(["wrinkles", str(frame), "--out", str(out)]) == 0
    assert "the rig of run" in capsys.readouterr().out
    s = json.loads((out / "summary.json").read_text())
    assert s["ply_thickness_m"] == pytest.approx(h) and s["d_crit_m"] == pytest.approx(h / 2)
    assert s["rig"]["punch_displacement_m"] == pytest.approx(4e-3, rel=1e-5)
    assert s["rig"]["time_s"] == run_summary["frame_times_s"][-1] and s["forced"] == []
    # Independent check: the run's own deviation_m (ply face to punch/die) is d - h/2.
    dev = meshio.read(frame).point_data["deviation_m"]
    d = meshio.read(out / "wrinkles.vtu").point_data["distance_m"]
    err = np.abs(d - h / 2 - dev).max()
    assert err < 1e-6, err  # 7.5e-9 m on this run (float32 frames)
    assert dev.max() > 3e-3  # the part does leave the tools (a real check, not all zeros)
    # Explicit --tool run, the run folder, and the run's thickness given again: the same numbers.
    for extra in (["--tool", "run"], ["--tool", str(small_run), "--ply-thickness-mm", "0.3"]):
        assert main(["wrinkles", str(frame), "--out", str(out)] + extra) == 0
        np.testing.assert_array_equal(meshio.read(out / "wrinkles.vtu").point_data["distance_m"], d)
    # A copy of the frame elsewhere with --tool RUN_DIR: the punch at the run's last frame.
    copy = tmp_path / "part.vtu"
    copy.write_bytes(frame.read_bytes())
    assert main(["wrinkles", str(copy), "--tool", str(small_run), "--out", str(out)]) == 0
    np.testing.assert_array_equal(meshio.read(out / "wrinkles.vtu").point_data["distance_m"], d)
    # The first frame: the flat ply on the die (d = h/2: conforming, though float32 puts it ~1e-8 m
    # higher), the punch apex on it, bridging over the die opening.
    first = small_run / "frames_00000.vtu"
    assert main(["wrinkles", str(first), "--out", str(out)]) == 0
    m = meshio.read(out / "wrinkles.vtu")
    d0, zone = m.point_data["distance_m"], m.point_data["zone"]
    np.testing.assert_allclose(d0 - h / 2, meshio.read(first).point_data["deviation_m"], atol=1e-6)
    on_die = np.hypot(m.points[:, 0], m.points[:, 1]) > 0.053 + 0.006
    assert on_die.sum() > 50 and np.all(zone[on_die] == 0)
    assert np.all(zone[d0 > h] == 1)


@pytest.mark.slow
def test_each_ply_of_a_stack_against_the_tool_it_lies_on(tmp_path):
    """Case B (two plies): ply i lies at (i - 1/2) h from the punch and (n - i + 1/2) h from the die;
    one d_crit for both sides called the whole flange of ply 1 bridging (61876 of 62500 mm^2)."""
    run = tmp_path / "b"
    assert main(["run", "case-b-woven-nlbm", "--out", str(run), "--element-size-mm", "25", *FAST_SET,
                 "--set", "process.stroke_mm=4", "--set", "process.frames=3", "--quiet"]) == 0
    frame = meshio.read(run / "frames_00002.vtu")
    ply_id = frame.point_data["ply_id"].ravel()
    for ply in (1, 2):
        out = tmp_path / f"w{ply}"
        assert main(["wrinkles", str(run / "frames_00002.vtu"), "--ply-index", str(ply), "--out", str(out)]) == 0
        w = meshio.read(out / "wrinkles.vtu")
        np.testing.assert_array_equal(w.points, frame.points[ply_id == ply])
        excess = w.point_data["excess_over_d_crit_m"]
        assert np.abs(excess - frame.point_data["deviation_m"][ply_id == ply]).max() < 1e-6  # 4e-9 m
        s = json.loads((out / "summary.json").read_text())
        assert s["zone_area_m2"]["bridging"] < 0.25 * 0.25 / 4  # the die opening, not the flange


def test_a_frame_with_a_tool_that_is_not_its_rig(small_run, tmp_path, capsys):
    frame = small_run / "frames_00002.vtu"
    out = tmp_path / "w"
    # The original problem: the hemisphere preset (apex up at z = 0) is not the run's punch (apex
    # down, on the stack, moved down by the stroke). It used to measure tens of mm with exit 0.
    args = ["wrinkles", str(frame), "--tool", "hemisphere", "--ply-thickness-mm", "0.3", "--out", str(out)]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert "disagrees with the rig" in err and "inside the tool" in err and "--force" in err
    assert not out.exists()  # nothing written
    assert main(args + ["--force"]) == 0
    assert "warning (--force)" in capsys.readouterr().err
    s = json.loads((out / "summary.json").read_text())
    assert len(s["forced"]) == 2
    d = meshio.read(out / "wrinkles.vtu").point_data["distance_m"]
    dev = meshio.read(frame).point_data["deviation_m"]
    assert np.abs(d - 0.15e-3 - dev).max() > 0.03  # what the preset measures on this part
    # A ply thickness other than the run's; a ply the run does not have; --tool run elsewhere.
    assert main(["wrinkles", str(frame), "--ply-thickness-mm", "0.5", "--out", str(out)]) == 2
    assert "0.3 mm thick" in capsys.readouterr().err
    assert main(["wrinkles", str(frame), "--ply-index", "2", "--out", str(out)]) == 2
    assert "has 1 ply" in capsys.readouterr().err
    copy = tmp_path / "part.vtu"
    copy.write_bytes(frame.read_bytes())
    assert main(["wrinkles", str(copy), "--tool", "run", "--out", str(out)]) == 2
    assert "not a frame of a 'jaxform run' folder" in capsys.readouterr().err
    assert main(["wrinkles", str(copy), "--out", str(out)]) == 2  # no run: the tool is required
    assert "--tool is required" in capsys.readouterr().err


# ---------------------------------------------------------------------------------------------
# Issue 14 item 7: no plausible wrong answer with exit 0
# ---------------------------------------------------------------------------------------------


def test_geometry_that_cannot_be_right_is_refused(sheet_mm, tmp_path, capsys):
    path, x, f, _ = sheet_mm
    out = tmp_path / "o"
    base = ["wrinkles", str(path), "--ply-thickness-mm", "0.3", "--out", str(out)]
    cases = {
        "probably in mm": ["--tool", "hemisphere", "--units", "m"],  # a mm file read as m
        "more than": ["--tool", "plane:z_mm=10000"],  # a tool 10 m away
        "inside the tool": ["--tool", "hemisphere:z_mm=5"],  # the part 5 mm inside the dome
    }
    for said, extra in cases.items():
        assert main(base + extra) == 2, said
        err = capsys.readouterr().err
        assert said in err and "--force" in err, err
        assert not out.exists()
        assert main(base + extra + ["--force"]) == 0  # --force measures anyway, and says so
        assert json.loads((out / "summary.json").read_text())["forced"]
        assert "warning (--force)" in capsys.readouterr().err
        for p in out.iterdir():
            p.unlink()
        out.rmdir()


def test_arguments_are_checked_before_any_work(sheet_mm, tmp_path, capsys):
    path, x, f, _ = sheet_mm
    out = tmp_path / "o"
    base = ["wrinkles", str(path), "--tool", "hemisphere", "--out", str(out)]
    bad = {
        "--kappa-threshold-per-m": (["--ply-thickness-mm", "0.3", "--kappa-threshold-per-m", "-5"],
                                    ["--ply-thickness-mm", "0.3", "--kappa-threshold-per-m", "0"]),
        "--ply-thickness-mm": (["--ply-thickness-mm", "0"], ["--ply-thickness-mm", "-0.3"],
                               ["--ply-thickness-mm", "nan"]),
        "--ply-index": (["--ply-thickness-mm", "0.3", "--ply-index", "0"],),
        "--section": (["--ply-thickness-mm", "0.3", "--section", "1,2,3"],
                      ["--ply-thickness-mm", "0.3", "--section=-34,0,34,0", "--section", "a,0,1,0"],
                      ["--ply-thickness-mm", "0.3", "--section", "5,5,5,5"]),
        "no such point-cloud": (["--ply-thickness-mm", "0.3", "--cloud", str(tmp_path / "none.csv")],),
    }
    for said, variants in bad.items():
        for extra in variants:
            assert main(base + extra) == 2, extra
            assert said in capsys.readouterr().err
            assert not out.exists(), extra  # nothing written, nothing to block the rerun
    assert main(base + ["--ply-thickness-mm", "0.3", "--section=-34,0,34,0", "--section=0,-34,0,34"]) == 0
    assert (out / "section_1.csv").exists()
    # A rerun into its own folder replaces what the first one wrote (no stale section_1.csv).
    assert main(base + ["--ply-thickness-mm", "0.3", "--section=-34,0,34,0"]) == 0
    assert (out / "section_0.csv").exists() and not (out / "section_1.csv").exists()


def test_empty_and_cellless_meshes_are_named(tmp_path, capsys):
    out = tmp_path / "o"
    files = {}
    files["empty.vtu"] = b""
    files["garbage.vtu"] = b"not xml at all"  # meshio calls sys.exit on this one
    files["nothing.stl"] = b"solid x\nendsolid x\n"
    files["points.obj"] = b"v 0 0 0\nv 1 0 0\nv 0 1 0\n"
    meshio.write(tmp_path / "lines.vtu", meshio.Mesh(np.eye(3), [("line", np.array([[0, 1], [1, 2]]))]))
    files["lines.vtu"] = (tmp_path / "lines.vtu").read_bytes()
    said = {"empty.vtu": "is empty (0 bytes)", "garbage.vtu": "could not read",
            "nothing.stl": "has no points", "points.obj": "no cells", "lines.vtu": "no surface cells"}
    for name, content in files.items():
        p = tmp_path / name
        p.write_bytes(content)
        assert main(["wrinkles", str(p), "--tool", "plane", "--ply-thickness-mm", "0.3", "--out", str(out)]) == 2
        err = capsys.readouterr().err
        assert err.startswith("jaxform wrinkles: error:") and str(p) in err and said[name] in err, err
        with pytest.raises(ValueError, match=re.escape(said[name])):
            read_surface(p)
    assert not out.exists()
