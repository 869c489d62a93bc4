"""Shear-law fit (jaxform.calibrate.fit_shear_*) and calibration/fit_shear.py."""
import json
import pathlib
import re
import subprocess
import sys

import numpy as np
import pytest

from jaxform import calibrate as C
from jaxform.io import calibration_files as cf
from jaxform.materials import NCF_FCIM359, WOVEN_38616
from helpers import run_calibration_script

ROOT = pathlib.Path(__file__).resolve().parents[1]


def test_recovers_woven_polynomial_with_noise():
    rng = np.random.default_rng(0)
    g = np.linspace(0.005, np.radians(60), 120)
    f = np.asarray(WOVEN_38616.shear.force(g)) * (1 + 0.01 * rng.normal(size=g.size))
    fit = C.fit_shear_polynomial(g, f, degree=7)
    gg = np.linspace(0.0, np.radians(60), 500)
    true, got = np.asarray(WOVEN_38616.shear.force(gg)), np.asarray(fit.law.force(gg))
    assert fit.monotone
    assert np.max(np.abs(got - true)) < 0.02 * true.max()  # measured 1.2 %
    big = gg > np.radians(2)
    assert np.max(np.abs(got - true)[big] / true[big]) < 0.02


def test_monotone_constraint_is_enforced():
    g = np.linspace(0.01, 1.0, 80)
    f = 100 * g - 300 * g**2 + 250 * g**3  # decreasing between 0.24 and 0.56 rad
    free = C.fit_shear_polynomial(g, f, degree=3, monotone=False)
    assert not free.monotone
    con = C.fit_shear_polynomial(g, f, degree=3, monotone=True)
    assert con.monotone
    gg = np.linspace(0, 1.0, 1000)
    assert np.all(np.diff(np.asarray(con.law.force(gg))) >= -1e-9)


def test_recovers_ncf_law_with_stitch_term():
    rng = np.random.default_rng(1)
    g = np.concatenate([np.linspace(-0.8, -0.01, 60), np.linspace(0.01, 0.8, 120)])
    f = np.asarray(NCF_FCIM359.shear.force(g))
    f = f + 0.01 * np.abs(f) * rng.normal(size=g.size)
    fit = C.fit_shear_ncf(g, f)
    np.testing.assert_allclose(fit.stitch_gamma_knots, [0.06, 0.5, 0.75], atol=0.01)
    assert fit.stitch_force_knots[1] == pytest.approx(880.0, rel=0.02)
    gg = np.linspace(-0.8, 0.8, 1000)
    true, got = np.asarray(NCF_FCIM359.shear.force(gg)), np.asarray(fit.law.force(gg))
    assert np.max(np.abs(got - true)) < 0.02 * np.abs(true).max()


def test_picture_frame_normalisation_round_trip():
    L = 0.145
    gamma = np.linspace(0, 1.0, 50)
    d = 2 * L * np.cos(np.pi / 4 - gamma / 2) - np.sqrt(2) * L
    np.testing.assert_allclose(C.picture_frame_shear_angle(d, L), gamma, atol=1e-12)
    fn = 30 * gamma
    force = fn * 2 * L * np.cos(np.pi / 4 - gamma / 2)
    np.testing.assert_allclose(C.picture_frame_normalised_force(force, gamma, L), fn, atol=1e-12)


def test_bad_shear_data_is_refused():
    with pytest.raises(ValueError, match="radians"):
        C.fit_shear_polynomial(np.linspace(0, 60, 10), np.linspace(0, 10, 10))
    with pytest.raises(ValueError, match="equal length"):
        C.fit_shear_polynomial([0.1, 0.2], [1.0, 2.0, 3.0])


def test_toml_round_trip(tmp_path):
    g = np.linspace(0.01, 1.0, 60)
    fit = C.fit_shear_polynomial(g, np.asarray(WOVEN_38616.shear.force(g)), degree=7)
    path = cf.write_shear_toml(tmp_path / "s.toml", fit.as_dict())
    law = cf.read_shear_toml(path)
    np.testing.assert_allclose(np.asarray(law.force(g)), np.asarray(fit.law.force(g)), rtol=1e-12)
    # its [fabric] table, merged into a case, gives the formed fabric the measured frame force as its resultant
    import tomllib

    from jaxform import cases

    fab = tomllib.loads(path.read_text())["fabric"]
    case = cases.apply_overrides(cases.load("case-a-woven-nlbm"), [f"fabric.{k}={json.dumps(v)}" for k, v in fab.items()])
    assert case.fabric.shear_reading == "conjugate" and case.fabric.shear_poly == pytest.approx(fit.coeffs)
    with pytest.raises(FileExistsError):
        cf.write_shear_toml(path, fit.as_dict())


def test_fit_shear_command_raw_frame_data(tmp_path):
    L = 0.145
    gamma = np.radians(np.linspace(1, 55, 40))
    fn = np.asarray(WOVEN_38616.shear.force(gamma))
    force = fn * 2 * L * np.cos(np.pi / 4 - gamma / 2)
    csv = tmp_path / "frame.csv"
    csv.write_text("gamma_deg,force_N\n" + "\n".join(f"{a:.6f},{b:.8f}" for a, b in zip(np.degrees(gamma), force)))
    out = tmp_path / "shear.toml"
    cmd = [sys.executable, str(ROOT / "calibration" / "fit_shear.py"), "--data", str(csv), "--frame-side-mm", "145",
           "--out", str(out), "--json", str(tmp_path / "fit.json"), "--plot", str(tmp_path / "fit.png")]
    r = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT)
    assert r.returncode == 0, r.stderr
    law = cf.read_shear_toml(out)
    np.testing.assert_allclose(np.asarray(law.force(gamma)), fn, rtol=0.02, atol=0.02 * fn.max())
    r2 = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT)
    assert r2.returncode != 0 and "refusing to overwrite" in r2.stderr


# ----- no plausible wrong answer with exit 0 (issue 14 item 3) ---------------------------------


def _cli(argv, capsys):
    return run_calibration_script("fit_shear", argv, capsys)


def _woven_rows(n=40, deg_max=55):
    g = np.radians(np.linspace(1, deg_max, n))
    return g, np.asarray(WOVEN_38616.shear.force(g))


def _raw_frame_csv(path, *, sign=1.0, n=40):
    L = 0.145
    g, fn = _woven_rows(n)
    force = sign * fn * 2 * L * np.cos(np.pi / 4 - g / 2)
    path.write_text("gamma_deg,force_N\n" + "\n".join(f"{a:.6f},{b:.8f}" for a, b in zip(np.degrees(g), force)) + "\n")
    return path


def _bad_input(tmp_path, case):
    """(argv after --data, file) of one refused input."""
    p = tmp_path / "frame.csv"
    g, fn = _woven_rows()
    if case == "negative_force":
        return ["--frame-side-mm", 145], _raw_frame_csv(p, sign=-1.0)
    if case in ("negative_side", "side_in_metres"):
        return ["--frame-side-mm", -145 if case == "negative_side" else 0.145], _raw_frame_csv(p)
    if case == "radians_as_degrees":
        p.write_text("gamma_deg,f_norm_N_per_m\n" + "\n".join(f"{a:.6f},{b:.6f}" for a, b in zip(g, fn)) + "\n")
    elif case == "degrees_as_radians":
        p.write_text("gamma_rad,f_norm_N_per_m\n" + "\n".join(f"{a:.6f},{b:.6f}" for a, b in zip(np.degrees(g), fn)) + "\n")
    elif case == "missing_value":
        rows = [f"{a:.6f},{b:.6f}" for a, b in zip(np.degrees(g), fn)]
        rows[6] = f"{np.degrees(g[6]):.6f},"
        p.write_text("gamma_deg,f_norm_N_per_m\n" + "\n".join(rows) + "\n")
    elif case == "displacement_in_metres_side":
        d_mm = np.linspace(1, 60, 20)
        p.write_text("displacement_mm,force_N\n" + "\n".join(f"{a},{0.1 * a}" for a in d_mm) + "\n")
        return ["--frame-side-mm", 50], p
    elif case == "few_points_for_degree":
        p.write_text("gamma_deg,f_norm_N_per_m\n" + "\n".join(f"{a:.6f},{b:.6f}" for a, b in zip(np.degrees(g[::8]), fn[::8])) + "\n")
        return ["--degree", 7], p
    else:
        p.write_text("gamma_deg,f_norm_N_per_m\n" + "\n".join(f"{a:.6f},{b:.6f}" for a, b in zip(np.degrees(g), fn)) + "\n")
        return ["--degree", {"degree_40": 40, "degree_0": 0, "degree_negative": -3}[case]], p
    return [], p


@pytest.mark.parametrize("case,match", [
    ("negative_force", r"39 of 40 rows have a force of the opposite sign to the shear angle \(lines 3, 4, .*flip the sign of force_N"),
    ("negative_side", r"--frame-side-mm -145: must be > 0"),
    ("side_in_metres", r"--frame-side-mm 0.145: .* looks like metres"),
    ("radians_as_degrees", r"gamma_deg reaches only 0.96° .* look like radians: name the column gamma_rad"),
    ("degrees_as_radians", r"gamma_rad reaches 55 rad .* look like degrees"),
    ("missing_value", r"1 row with a missing or non-numeric value in gamma_deg,f_norm_N_per_m \(line 8\)"),
    ("displacement_in_metres_side", r"displacement_mm reaches .* travels at most 29.29 mm"),
    ("few_points_for_degree", r"5 distinct shear angles for 7 unknowns .* use degree <= 4"),
    ("degree_40", r"--degree 40: must be an integer from 1 to 9"),
    ("degree_0", r"--degree 0: must be an integer from 1 to 9"),
    ("degree_negative", r"--degree -3: must be an integer from 1 to 9"),
])
def test_fit_shear_command_refuses_input(tmp_path, capsys, case, match):
    """Each input that used to give a meaningless law with exit 0 (an all-zero law for negative
    forces or side, coefficients of 3e15 for radians under gamma_deg, a wild degree-40 fit, degree
    0 silently 7, -3 a crash) is refused at the edge: exit 2, the reason, nothing written."""
    extra, data = _bad_input(tmp_path, case)
    outs = [tmp_path / "shear.toml", tmp_path / "fit.json", tmp_path / "fit.png"]
    rc, out, err = _cli(["--data", data, *extra, "--out", outs[0], "--json", outs[1], "--plot", outs[2]], capsys)
    assert rc == 2, (out, err)
    assert "fit_shear.py: error: " in err and "Traceback" not in err
    assert re.search(match, err), err
    assert not any(p.exists() for p in outs)


def test_fit_shear_command_unconverged_fit_is_not_success(tmp_path, capsys):
    """A straight line through the woven law: the fit runs, but its rmse is ~40x the data's
    scatter; the command says so, records it in both files and exits 1."""
    data = _raw_frame_csv(tmp_path / "frame.csv")
    toml, js = tmp_path / "shear.toml", tmp_path / "fit.json"
    rc, out, err = _cli(["--data", data, "--frame-side-mm", 145, "--degree", 1, "--out", toml, "--json", js], capsys)
    assert rc == 1
    assert "fit_shear.py: the fit did not converge: rmse" in err and "far above the data's scatter" in err
    d = json.loads(js.read_text())
    assert d["converged"] is False and "far above the data's scatter" in d["reason"]
    assert "converged = false" in toml.read_text() and "NOT A VALID FIT" in toml.read_text()
    with pytest.raises(ValueError, match="did not converge"):
        cf.read_shear_toml(toml)


def test_fit_reports_unmet_constraint_and_poor_rmse():
    g = np.linspace(0.01, 1.0, 80)
    f = 100 * g - 300 * g**2 + 250 * g**3  # a drop the non-decreasing law cannot follow
    fit = C.fit_shear_polynomial(g, f, degree=3, monotone=True)
    assert not fit.converged and "far above the data's scatter" in fit.reason
    free = C.fit_shear_polynomial(g, f, degree=3, monotone=False)
    assert free.converged and free.reason == ""  # exact data, exact form
    good = C.fit_shear_polynomial(*_woven_rows(), degree=7)
    assert good.converged and good.as_dict()["converged"] is True


@pytest.mark.parametrize("degree,match", [(0, "from 1 to 9"), (-3, "from 1 to 9"), (40, "from 1 to 9"),
                                          (2.5, "must be an integer"), (7, "for 7 unknowns")])
def test_fit_degree_is_checked(degree, match):
    g = np.linspace(0.1, 0.8, 6)
    with pytest.raises(ValueError, match=match):
        C.fit_shear_polynomial(g, 10 * g, degree=degree)
    with pytest.raises(ValueError, match="stitch peak and 3 knots"):
        C.fit_shear_ncf(g, 10 * g, degree=3)


def test_data_scatter_estimates_the_noise():
    rng = np.random.default_rng(4)
    g = np.sort(rng.uniform(0.01, 1.0, 400))
    f = np.asarray(WOVEN_38616.shear.force(g))
    s = C.shear_fit.data_scatter(g, f + 0.3 * rng.normal(size=g.size))
    assert s == pytest.approx(0.3, rel=0.15)
