"""Material laws against the source paper's Table 1 and their own calculus (issue 2)."""
import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from jaxform import units
from helpers import central_difference
from jaxform.materials import (
    NCF_FCIM359,
    TABLE1_LBM,
    WOVEN_38616,
    AsymmetricBending,
    CompositeShear,
    Fabric,
    LinearBending,
    PiecewiseLinearShear,
    PolynomialShear,
    VoceBending,
    laminate_moduli,
    lbm_variant,
    membrane_only,
    ply_properties,
    preset,
)

KAPPAS = np.concatenate([-np.geomspace(1e-3, 2e3, 40)[::-1], [0.0], np.geomspace(1e-3, 2e3, 40)])

WOVEN_VOCE = WOVEN_38616.bending[0]
NCF_POS = NCF_FCIM359.bending[0].pos
NCF_NEG = NCF_FCIM359.bending[0].neg


def _round_sig(x, ndigits_after_point_in_table):
    return round(x, ndigits_after_point_in_table)


# --- Table 1 ---------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "law, table, decimals",
    [
        # Table 1 prints N·m with these many decimals: 0.00039 / 0.00002; 0.0080 / 0.0002; 0.0057 / 0.0001.
        (WOVEN_VOCE, (3.9e-4, 2e-5), 5),
        (NCF_POS, (8.0e-3, 2e-4), 4),
        (NCF_NEG, (5.7e-3, 1e-4), 4),
    ],
    ids=["woven", "ncf-pos", "ncf-neg"],
)
def test_derived_stiffnesses_match_table1_to_its_rounding(law, table, decimals):
    b_init, b_inf = table
    assert round(float(law.b_init), decimals) == pytest.approx(b_init, abs=1e-12)
    assert round(float(law.b_inf), decimals) == pytest.approx(b_inf, abs=1e-12)
    # and the printed LBM table of the module agrees
    assert b_init in TABLE1_LBM[("woven-38616" if law is WOVEN_VOCE else "ncf-fcim359")]["init"]


def test_presets_are_si_values_of_spec_section_3():
    assert WOVEN_VOCE.b_inf == pytest.approx(1.549e-5)
    assert WOVEN_VOCE.m0 == pytest.approx(7.57e-3)
    assert WOVEN_VOCE.kappa0 == pytest.approx(20.0)
    assert (NCF_POS.b_inf, NCF_POS.m0, NCF_POS.kappa0) == pytest.approx((1.9457e-4, 3.139e-2, 4.0))
    assert (NCF_NEG.b_inf, NCF_NEG.m0, NCF_NEG.kappa0) == pytest.approx((1.0279e-4, 3.619e-2, 6.5))
    assert WOVEN_38616.thickness == pytest.approx(0.3e-3)
    assert WOVEN_38616.areal_mass == pytest.approx(0.210)
    assert NCF_FCIM359.thickness == pytest.approx(0.4e-3)
    assert NCF_FCIM359.areal_mass == pytest.approx(0.440)
    assert WOVEN_38616.fibre_modulus == pytest.approx(3.0e9)
    assert WOVEN_38616.friction_tool == 0.23 and WOVEN_38616.friction_fabric == 0.36
    assert np.degrees(NCF_FCIM359.fibre_angles) == pytest.approx([45.0, -45.0])
    assert np.degrees(WOVEN_38616.fibre_angles) == pytest.approx([0.0, 90.0])
    assert NCF_FCIM359.stitch_angle == 0.0


# --- bending calculus ------------------------------------------------------------------------

LAWS = {
    "linear": LinearBending(2.2e-4),
    "woven-voce": WOVEN_VOCE,
    "ncf-asym": NCF_FCIM359.bending[0],
    "asym-mixed": AsymmetricBending(VoceBending(1e-4, 2e-2, 5.0), LinearBending(3e-3)),
}


@pytest.mark.parametrize("name", LAWS)
def test_stiffness_is_grad_of_moment_and_moment_is_grad_of_energy(name):
    law = LAWS[name]
    k = jnp.asarray(KAPPAS)
    dm = jax.vmap(jax.grad(law.moment))(k)
    de = jax.vmap(jax.grad(law.energy))(k)
    np.testing.assert_allclose(dm, law.stiffness(k), rtol=1e-12, atol=0)
    # d(energy)/dk evaluates 1 - exp(-a/k0) where moment uses expm1: round-off near zero only,
    # bounded relative to the moment's scale over the range.
    scale = float(jnp.max(jnp.abs(law.moment(k))))
    np.testing.assert_allclose(de, law.moment(k), rtol=1e-12, atol=1e-14 * scale)


@pytest.mark.parametrize("name", LAWS)
def test_moment_continuous_monotone_odd_and_energy_nonnegative(name):
    law = LAWS[name]
    k = np.linspace(-500.0, 500.0, 200001)
    m = np.asarray(law.moment(k))
    assert np.all(np.diff(m) > 0), "moment must increase strictly with curvature"
    # continuity: jumps between neighbouring samples bounded by max stiffness * step
    assert np.max(np.abs(np.diff(m))) <= float(np.max(law.stiffness(k))) * (k[1] - k[0]) * (1 + 1e-9)
    assert float(law.moment(0.0)) == 0.0
    assert np.all(np.asarray(law.energy(k)) >= 0)
    if not isinstance(law, AsymmetricBending):
        np.testing.assert_allclose(law.moment(-k), -law.moment(k), rtol=1e-14)


def test_voce_stiffness_at_zero_is_b_init_from_both_sides():
    law = WOVEN_VOCE
    g = jax.grad(law.moment)
    assert float(g(0.0)) == pytest.approx(float(law.b_init), rel=1e-14)
    assert float(g(-0.0)) == pytest.approx(float(law.b_init), rel=1e-14)
    assert float(g(-1e-12)) == pytest.approx(float(law.b_init), rel=1e-9)
    assert float(law.stiffness(1e9)) == pytest.approx(float(law.b_inf), rel=1e-12)


def test_asymmetric_law_uses_pos_and_neg_sides():
    law = NCF_FCIM359.bending[0]
    assert float(law.moment(10.0)) == pytest.approx(float(NCF_POS.moment(10.0)))
    assert float(law.moment(-10.0)) == pytest.approx(float(NCF_NEG.moment(-10.0)))
    assert law.b_init == pytest.approx((NCF_POS.b_init, NCF_NEG.b_init))


# --- parameter gradients vs finite differences (float64) ---------------------------------


def _fd_grad(f, params, eps_rel=1e-6):
    return np.array([central_difference(lambda p: f(*p), params, eps_rel * abs(params[i]), index=i)
                     for i in range(len(params))])


@pytest.mark.parametrize("kappa", [0.0, -3.0, 0.5, 20.0, 400.0])
def test_voce_parameter_gradients_match_finite_differences(kappa):
    params = (1.549e-5, 7.57e-3, 20.0)

    def scalar(b_inf, m0, kappa0):
        law = VoceBending(b_inf, m0, kappa0)
        return float(law.moment(kappa)) + 1e-3 * float(law.energy(kappa)) + float(law.stiffness(kappa))

    def scalar_jax(law):
        return law.moment(kappa) + 1e-3 * law.energy(kappa) + law.stiffness(kappa)

    g = jax.grad(scalar_jax)(VoceBending(*params))
    auto = np.array([g.b_inf, g.m0, g.kappa0])
    fd = _fd_grad(scalar, params)
    np.testing.assert_allclose(auto, fd, rtol=1e-6, atol=1e-12 * np.max(np.abs(fd)))


def test_shear_parameter_gradients_match_finite_differences():
    coeffs = np.array([112.19, 94.73, 137.06, -65.56, 29.56])
    knots_f = np.array([0.0, 880.0, 0.0])

    def value(c, f):
        law = CompositeShear((PolynomialShear(c), PiecewiseLinearShear([0.06, 0.5, 0.75], f)))
        g = 0.37
        return law.force(g) + law.integral(g) + law.integral2(g) + law.tangent(g)

    gc, gf = jax.grad(value, argnums=(0, 1))(jnp.asarray(coeffs), jnp.asarray(knots_f))
    for grad, base, which in ((gc, coeffs, 0), (gf, knots_f, 1)):
        for i in range(base.size):
            fd = central_difference(lambda b: value(*((b, knots_f) if which == 0 else (coeffs, b))), base, 1e-4,
                                    index=i)
            assert float(grad[i]) == pytest.approx(fd, rel=1e-6, abs=1e-9)


def test_finite_gradients_at_zero_curvature_and_zero_shear():
    for law in LAWS.values():
        g = jax.grad(lambda lw: lw.moment(0.0) + lw.energy(0.0) + lw.stiffness(0.0))(law)
        assert all(np.all(np.isfinite(leaf)) for leaf in jax.tree_util.tree_leaves(g))
    for fabric in (WOVEN_38616, NCF_FCIM359):
        for fn in ("force", "tangent", "integral", "integral2"):
            g = jax.grad(lambda s: getattr(s, fn)(0.0))(fabric.shear)
            assert all(np.all(np.isfinite(leaf)) for leaf in jax.tree_util.tree_leaves(g))
            assert np.isfinite(float(jax.grad(getattr(fabric.shear, fn))(0.0)))


def test_laws_jit_and_vmap_over_parameter_sets():
    batch = VoceBending(
        b_inf=jnp.array([1e-5, 2e-5, 1e-4]), m0=jnp.array([1e-3, 7e-3, 3e-2]), kappa0=jnp.array([10.0, 20.0, 4.0])
    )
    per_set = jax.jit(jax.vmap(lambda law: law.moment(jnp.array([0.0, 5.0, 50.0]))))(batch)
    for i in range(3):
        single = VoceBending(float(batch.b_inf[i]), float(batch.m0[i]), float(batch.kappa0[i]))
        np.testing.assert_allclose(per_set[i], single.moment(jnp.array([0.0, 5.0, 50.0])), rtol=1e-12)


# --- shear laws ------------------------------------------------------------------------------


def _woven_printed(g):
    return (
        37.35 * g - 322.61 * g**2 + 1458.51 * g**3 - 3539.56 * g**4 + 4727.84 * g**5 - 3275.20 * g**6 + 930.53 * g**7
    )


def _ncf_printed(g):
    yarn = 29.56 * g**5 - 65.56 * g**4 + 137.06 * g**3 + 94.73 * g**2 + 112.19 * g
    if 0.06 <= g < 0.5:
        stitch = 2000 * g - 120
    elif 0.5 <= g < 0.75:
        stitch = -3520 * g + 2640
    else:
        stitch = 0.0
    return yarn + stitch


@pytest.mark.parametrize("g", [0.0, 0.01, 0.1, 0.25, 0.5, 0.7, 1.0])
def test_shear_laws_match_printed_polynomials(g):
    assert float(WOVEN_38616.shear.force(g)) == pytest.approx(_woven_printed(g), rel=1e-12, abs=1e-12)
    assert float(WOVEN_38616.shear.force(-g)) == pytest.approx(-_woven_printed(g), rel=1e-12, abs=1e-12)
    assert float(NCF_FCIM359.shear.force(g)) == pytest.approx(_ncf_printed(g), rel=1e-12, abs=1e-12)


def test_ncf_stitch_continuous_at_half_and_zero_for_negative_shear():
    stitch = NCF_FCIM359.shear.terms[1]
    below, at = float(stitch.force(0.5 - 1e-12)), float(stitch.force(0.5))
    assert below == pytest.approx(880.0, rel=1e-9) and at == pytest.approx(880.0, rel=1e-12)
    assert float(stitch.force(0.06)) == pytest.approx(0.0, abs=1e-9)
    assert float(stitch.force(0.75)) == 0.0
    for g in (-0.01, -0.3, -0.5, -0.7):
        assert float(stitch.force(g)) == 0.0
        assert float(NCF_FCIM359.shear.force(g)) == pytest.approx(-_ncf_printed(-g) + _stitch_only(-g), rel=1e-12)


def _stitch_only(g):
    return _ncf_printed(g) - (29.56 * g**5 - 65.56 * g**4 + 137.06 * g**3 + 94.73 * g**2 + 112.19 * g)


@pytest.mark.parametrize("fabric", [WOVEN_38616, NCF_FCIM359], ids=["woven", "ncf"])
def test_shear_integrals_are_antiderivatives(fabric):
    law = fabric.shear
    g = jnp.linspace(-0.9, 0.9, 181)
    np.testing.assert_allclose(jax.vmap(jax.grad(law.integral))(g), law.force(g) * jnp.where(g >= 0, 1, 1), atol=1e-9)
    # integral2 is the antiderivative of integral over |gamma| (even): d/dg = sign(g) * integral(g)
    np.testing.assert_allclose(
        jax.vmap(jax.grad(law.integral2))(g), jnp.where(g >= 0, 1.0, -1.0) * law.integral(g), atol=1e-9
    )
    # a quadrature check that shares no code with the closed forms
    from scipy.integrate import quad

    for gv in (0.2, 0.55, 0.8):
        ref, _ = quad(lambda x: float(law.force(x)), 0.0, gv, points=[0.06, 0.5, 0.75], limit=200)
        assert float(law.integral(gv)) == pytest.approx(ref, rel=1e-9)


# --- laminate conversion -----------------------------------------------------------------


def test_laminate_conversion_round_trips_and_matches_a1():
    h, t_core, e_ply, b = 0.3e-3, 0.2e-3, 3.0e9, 2.2e-4
    e_surf, e_core = laminate_moduli(e_ply, b, h, t_core)
    # (A.1) by hand
    assert e_surf == pytest.approx(16 * b / ((h - t_core) * (h + t_core) ** 2), rel=1e-14)
    e_ply2, b2 = ply_properties(e_surf, e_core, h, t_core)
    assert e_ply2 == pytest.approx(e_ply, rel=1e-12)
    assert b2 == pytest.approx(b, rel=1e-12)
    # and the other way round
    e_surf3, e_core3 = laminate_moduli(*ply_properties(5e9, 1e9, h, t_core), h, t_core)
    assert (e_surf3, e_core3) == pytest.approx((5e9, 1e9), rel=1e-12)


def test_laminate_rejects_bending_too_stiff_for_the_ply_modulus():
    with pytest.raises(ValueError, match="core modulus would be negative"):
        laminate_moduli(1.0e6, 8e-3, 0.4e-3, 0.1e-3)


# --- variants ------------------------------------------------------------------------------


def test_lbm_variants_and_membrane_only():
    w = lbm_variant(WOVEN_38616, "init")
    assert isinstance(w.bending[0], LinearBending)
    assert float(w.bending[0].b) == pytest.approx(float(WOVEN_VOCE.b_init))
    assert float(lbm_variant(WOVEN_38616, "41.5").bending[1].b) == pytest.approx(2.2e-4)
    n = lbm_variant(NCF_FCIM359, "inf").bending[0]
    assert isinstance(n, AsymmetricBending)
    assert (float(n.pos.b), float(n.neg.b)) == pytest.approx((1.9457e-4, 1.0279e-4))
    n41 = lbm_variant(NCF_FCIM359, "41.5").bending[0]
    assert (float(n41.pos.b), float(n41.neg.b)) == pytest.approx((3.8e-3, 3.2e-3))
    m = membrane_only(NCF_FCIM359)
    assert m.membrane_only and m.bending is None and m.shear is NCF_FCIM359.shear
    with pytest.raises(ValueError, match="membrane-only"):
        lbm_variant(m, "init")
    with pytest.raises(ValueError, match="which"):
        lbm_variant(WOVEN_38616, "42")


def test_fabric_is_a_pytree_with_gradients_through_every_parameter():
    def f(fab):
        return (
            fab.bending[0].moment(30.0)
            + fab.shear.force(0.3)
            + fab.tension_stiffness * 1e-9
            + fab.areal_mass
            + fab.friction_tool
        )

    g = jax.grad(f)(WOVEN_38616)
    assert float(g.bending[0].m0) != 0.0 and float(g.shear.coeffs[0]) == pytest.approx(0.3)
    assert float(g.fibre_modulus) == pytest.approx(WOVEN_38616.thickness * 1e-9)
    assert float(g.areal_mass) == 1.0 and float(g.friction_tool) == 1.0


def test_paper_unit_conversions():
    assert units.n_mm_to_n_m(0.01549) == pytest.approx(1.549e-5)
    assert units.per_mm_to_per_m(0.02) == pytest.approx(20.0)
    assert units.gsm_to_kg_per_m2(440) == pytest.approx(0.44)
    assert units.mm_to_m(0.4) == pytest.approx(4e-4)
    assert units.m_to_mm(units.mm_to_m(7.0)) == pytest.approx(7.0)


# --- invalid input -----------------------------------------------------------------------


@pytest.mark.parametrize(
    "build, match",
    [
        (lambda: VoceBending(1e-5, 1e-3, 0.0), r"VoceBending\.kappa0 = 0\.0: must be > 0"),
        (lambda: VoceBending(1e-5, 1e-3, -4.0), r"VoceBending\.kappa0 = -4\.0: must be > 0"),
        (lambda: VoceBending(-1e-5, 1e-3, 4.0), r"VoceBending\.b_inf = -1e-05: must be >= 0"),
        (lambda: VoceBending(1e-5, float("nan"), 4.0), r"VoceBending\.m0 = nan: must be finite"),
        (lambda: VoceBending(0.0, 0.0, 4.0), r"no stiffness"),
        (lambda: LinearBending(-2.2e-4), r"LinearBending\.b = -0\.00022: must be > 0"),
        (lambda: LinearBending(float("inf")), r"LinearBending\.b = inf: must be finite"),
        (lambda: PolynomialShear([1.0, float("nan")]), r"PolynomialShear\.coeffs .*must be finite"),
        (lambda: PolynomialShear([]), r"PolynomialShear\.coeffs has shape"),
        (lambda: PiecewiseLinearShear([0.5, 0.2], [0, 1]), r"strictly increasing"),
        (lambda: WOVEN_38616.replace(thickness=-0.3e-3), r"thickness = -0\.0003: must be > 0"),
        (lambda: WOVEN_38616.replace(thickness=0.0), r"thickness = 0\.0: must be > 0"),
        (lambda: WOVEN_38616.replace(thickness=0.3), r"did you give millimetres"),
        (lambda: WOVEN_38616.replace(areal_mass=float("nan")), r"areal_mass = nan: must be finite"),
        (lambda: WOVEN_38616.replace(fibre_modulus=-3e9), r"fibre_modulus = -3000000000\.0: must be > 0"),
        (lambda: WOVEN_38616.replace(friction_tool=-0.1), r"friction_tool = -0\.1: must be >= 0"),
        (lambda: WOVEN_38616.replace(fibre_angles=(0.0, math.pi)), r"parallel"),
        (lambda: WOVEN_38616.replace(bending=(WOVEN_VOCE,)), r"pair of bending laws"),
        (lambda: laminate_moduli(3e9, 2e-4, 0.3e-3, 0.3e-3), r"t_core = 0\.0003 m >= h"),
        (lambda: laminate_moduli(3e9, 2e-4, 0.3e-3, 0.5e-3), r"core must be thinner than the ply"),
        (lambda: laminate_moduli(3e9, 2e-4, -0.3e-3, 0.1e-3), r"h = -0\.0003: must be > 0"),
        (lambda: ply_properties(3e9, 1e9, 0.3e-3, 0.4e-3), r"core must be thinner"),
        (lambda: preset("woven-3861"), r"unknown fabric preset 'woven-3861': known presets are"),
        (lambda: VoceBending.from_stiffnesses(1e-5, 2e-5, 4.0), r"b_init .* must be >= b_inf"),
    ],
)
def test_invalid_input_raises_clear_error(build, match):
    with pytest.raises(ValueError, match=match):
        build()


def test_validation_is_not_applied_to_cotangents_or_tracers():
    # gradients may be negative: they must not trip the constructor's checks
    g = jax.grad(lambda law: -law.moment(1.0) * law.kappa0)(WOVEN_VOCE)
    assert float(g.kappa0) < 0 or float(g.b_inf) < 0
    # building a law from traced values inside jit works (checked at the user's edge instead)
    out = jax.jit(lambda b: LinearBending(b).moment(2.0))(3.0)
    assert float(out) == 6.0
    # a user-built Fabric keeps its name in errors
    with pytest.raises(ValueError, match=r"Fabric\('mine'\)"):
        Fabric(
            name="mine", thickness=-1.0, areal_mass=0.2, fibre_modulus=3e9, shear=WOVEN_38616.shear, bending=None
        )
