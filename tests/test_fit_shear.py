"""Shear-law fit (jaxform.calibrate.fit_shear_*) and calibration/fit_shear.py."""
import pathlib
import subprocess
import sys

import numpy as np
import pytest

from jaxform import calibrate as C
from jaxform.io import calibration_files as cf
from jaxform.materials import NCF_FCIM359, WOVEN_38616

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
