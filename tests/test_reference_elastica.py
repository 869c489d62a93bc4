"""The independent reference solutions (tests/reference/elastica.py) against closed forms.

The reference must be trustworthy on its own: small-deflection limit, equilibrium of the sampled
shape, two independent numerical methods, convergence with tolerance, the Peirce/ISO round trip,
and the pin-jointed-net kinematics by virtual work.
"""
import math

import numpy as np
import pytest
from scipy.integrate import cumulative_trapezoid

from reference import elastica as E  # tests/ is on sys.path (rootdir conftest)

M_WOVEN = 0.210  # kg/m²
M_NCF = 0.440
VOCE = dict(b_inf=3.0e-5, m0=5.0e-3, kappa0=25.0)  # unlike the presets


def test_does_not_import_jaxform():
    import reference.elastica as mod

    src = open(mod.__file__).read()
    assert "import jaxform" not in src and "from jaxform" not in src


@pytest.mark.parametrize("b", [3.9e-4, 8.0e-3])
def test_small_deflection_limit_linear(b):
    w = M_WOVEN * E.GRAVITY
    L = (0.01 * b / w) ** (1 / 3)  # w L^3 / B = 0.01: tiny deflection
    r = E.solve_cantilever(b, L, M_WOVEN)
    tip = -r["z"][-1]
    assert tip == pytest.approx(E.small_deflection_tip(b, L, M_WOVEN), rel=5e-3)
    # and the first large-deflection correction is small and negative (the strip shortens in x)
    assert tip < E.small_deflection_tip(b, L, M_WOVEN)
    # small-deflection slope at the tip: w L^3 / (6 B)
    assert r["tip_angle"] == pytest.approx(w * L**3 / (6 * b), rel=5e-3)


def test_small_deflection_limit_voce_uses_b_init():
    law = E.voce_moment(**VOCE)
    b_init = VOCE["b_inf"] + VOCE["m0"] / VOCE["kappa0"]
    w = M_WOVEN * E.GRAVITY
    L = (0.004 * b_init / w) ** (1 / 3)
    r = E.solve_cantilever(law, L, M_WOVEN)
    assert np.max(r["kappa"]) < 0.05 * VOCE["kappa0"]
    assert -r["z"][-1] == pytest.approx(E.small_deflection_tip(b_init, L, M_WOVEN), rel=5e-3)


@pytest.mark.parametrize("which", ["linear", "voce"])
def test_equilibrium_and_inextensibility_of_sampled_shape(which):
    law = E.linear_moment(2e-4) if which == "linear" else E.voce_moment(**VOCE)
    L = 0.12
    r = E.solve_cantilever(law, L, M_WOVEN, n=4001)
    assert 0.3 < r["tip_angle"] < 1.4  # a large deflection
    s, x, z = r["s"], r["x"], r["z"]
    # arc length from the coordinates equals s (inextensible)
    ds = np.hypot(np.diff(x), np.diff(z))
    assert np.sum(ds) == pytest.approx(L, rel=1e-6)
    # M(kappa(s)) = ∫_s^L w (x(s') - x(s)) ds', evaluated by quadrature on the sampled shape
    w = M_WOVEN * E.GRAVITY
    first = cumulative_trapezoid(x, s, initial=0.0)
    tail_x = first[-1] - first  # ∫_s^L x ds'
    moment_from_weight = w * (tail_x - x * (L - s))
    np.testing.assert_allclose(law(r["kappa"]), moment_from_weight, atol=1e-6 * moment_from_weight[0])
    assert r["z"][-1] < 0 and np.all(np.diff(r["theta"]) > 0)


@pytest.mark.parametrize("which,L", [("linear", 0.1), ("voce", 0.1)])
def test_shooting_and_collocation_agree(which, L):
    law = E.linear_moment(2e-4) if which == "linear" else E.voce_moment(**VOCE)
    a = E.solve_cantilever(law, L, M_WOVEN, method="shooting")
    b = E.solve_cantilever(law, L, M_WOVEN, method="bvp")
    np.testing.assert_allclose(a["z"], b["z"], atol=1e-9 * L)
    np.testing.assert_allclose(a["x"], b["x"], atol=1e-9 * L)
    assert a["tip_angle"] == pytest.approx(b["tip_angle"], rel=1e-8)


def test_converges_with_tolerance():
    law = E.voce_moment(**VOCE)
    tips = [E.solve_cantilever(law, 0.1, M_WOVEN, n=2, rtol=r)["z"][-1] for r in (1e-6, 1e-9, 1e-12)]
    e1, e2 = abs(tips[0] - tips[2]), abs(tips[1] - tips[2])
    assert e2 < e1 or e1 < 1e-13
    assert e2 < 1e-9 * 0.1


def test_peirce_round_trip_linear():
    # The ISO formula B = w (L/2)^3 at the 41.5° overhang gives back the linear stiffness.
    for b, m in ((3.9e-4, M_WOVEN), (8.0e-3, M_NCF)):
        L = E.peirce_overhang(b, m)
        r = E.solve_cantilever(b, L, m, n=2)
        assert math.degrees(r["chord_angle"]) == pytest.approx(41.5, abs=1e-8)
        assert E.standard_test_b(L, m) == pytest.approx(b, rel=0.01)  # measured: +0.052 %


def test_peirce_overhang_scales_as_cube_root():
    L1 = E.peirce_overhang(1e-4, M_WOVEN)
    L8 = E.peirce_overhang(8e-4, M_WOVEN)
    assert L8 / L1 == pytest.approx(2.0, rel=1e-9)


def test_voce_inverse_round_trip():
    law = E.voce_moment(**VOCE)
    k = np.array([-300.0, -25.0, -1e-3, 0.0, 1e-6, 3.0, 25.0, 1e4])
    np.testing.assert_allclose(law.inverse(law(k)), k, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(law.stiffness(0.0), VOCE["b_inf"] + VOCE["m0"] / VOCE["kappa0"])


def test_picture_frame_kinematics_and_virtual_work():
    L = 0.145
    gamma = np.linspace(0.0, 1.1, 200)
    d = E.picture_frame_displacement(gamma, L)
    np.testing.assert_allclose(E.picture_frame_shear_angle(d, L), gamma, atol=1e-12)
    assert d[0] == 0.0 and np.all(np.diff(d) > 0)
    # square frame closed to a line: gamma = pi/2 when the diagonal reaches 2L
    assert E.picture_frame_shear_angle(2 * L - math.sqrt(2) * L, L) == pytest.approx(math.pi / 2)

    def f_norm(g):
        return 37.35 * g + 500.0 * g**3

    force = E.picture_frame_force(f_norm, gamma, L)
    # virtual work: F dd/dgamma = L^2 cos(gamma) F_norm(gamma)
    ddg = np.gradient(d, gamma, edge_order=2)
    np.testing.assert_allclose(force * ddg, L**2 * np.cos(gamma) * f_norm(gamma), rtol=1e-4, atol=1e-9)
    np.testing.assert_allclose(E.picture_frame_normalised_force(force, gamma, L), f_norm(gamma), rtol=1e-12)


def test_bias_extension_kinematics_and_virtual_work():
    H, W = 0.2, 0.1
    gamma = np.linspace(0.0, 1.0, 300)
    d = E.bias_extension_displacement(gamma, H, W)
    np.testing.assert_allclose(E.bias_extension_shear_angle(d, H, W), gamma, atol=1e-12)
    a, b, c = E.bias_extension_zone_areas(H, W)
    assert a + b + c == pytest.approx(H * W)
    assert (a, b, c) == pytest.approx((W**2 / 2, W**2, W**2 / 2))  # 2:1 specimen

    def f_norm(g):
        return 37.35 * g + 500.0 * g**3

    force = E.bias_extension_force(f_norm, gamma, H, W)
    ddg = np.gradient(d, gamma, edge_order=2)
    power = a * np.cos(gamma) * f_norm(gamma) + b * np.cos(gamma / 2) * f_norm(gamma / 2) / 2
    np.testing.assert_allclose(force * ddg, power, rtol=1e-4, atol=1e-9)
    # small-strain: zone A's axial stretch d/D = gamma/2
    assert d[1] / (H - W) == pytest.approx(gamma[1] / 2, rel=1e-2)
