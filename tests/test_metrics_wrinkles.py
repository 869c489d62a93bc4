"""Zones, sections, counts and densities of the wrinkle metric on constructed cases."""
import jax
import jax.numpy as jnp
import numpy as np
import pytest

from _surfaces import draped_sheet, grid_faces
from jaxform.tools import hemisphere_rig
from jaxform.metrics import (
    BRIDGING,
    CONFORMING,
    WRINKLE,
    classify_zones,
    count_section_wrinkles,
    count_wrinkle_regions,
    d_crit,
    kappa_max,
    node_areas,
    principal_curvatures,
    probability_density,
    rms_fibre_moment,
    section_nrmse,
    section_profile,
    tool_distance,
    wrinkle_radius,
    zone_areas,
)

R = 0.05
H_PLY = 0.3e-3


def test_d_crit():
    assert float(d_crit(H_PLY)) == pytest.approx(0.15e-3)
    assert float(d_crit(0.4e-3, 2)) == pytest.approx(0.6e-3)
    with pytest.raises(ValueError):
        d_crit(0.4e-3, 0)


def test_zones_on_constructed_case():
    x, f, bump, lift = draped_sheet()
    d = np.asarray(tool_distance(x, hemisphere_rig(radius=R)))
    np.testing.assert_allclose(d[(bump == 0) & (lift == 0)], 0.45 * H_PLY, atol=1e-12)
    km = kappa_max(*principal_curvatures(x, f))
    labels = np.asarray(classify_zones(d, km, d_crit(H_PLY), kappa_threshold=100.0, faces=f))
    tiny = 1e-9
    assert np.all(labels[(bump < tiny) & (lift < tiny)] == CONFORMING)
    assert np.all(labels[bump > 0.05e-3] == WRINKLE)
    assert np.all(labels[lift > 0.05e-3] == BRIDGING)
    # No node of the bump is called bridging or of the lifted region wrinkle.
    assert not np.any(labels[bump > tiny] == BRIDGING)
    assert not np.any(labels[lift > tiny] == WRINKLE)
    areas = node_areas(x, f)
    za = np.asarray(zone_areas(labels, areas))
    assert za.sum() == pytest.approx(float(jnp.sum(areas)))
    assert za[BRIDGING] > za[WRINKLE] > 0.0
    count, region = count_wrinkle_regions(labels, f, areas, min_area=1e-6)
    assert int(count) == 1
    assert np.all(np.asarray(region)[labels == WRINKLE] == np.asarray(region)[labels == WRINKLE][0])
    # Per-frame evaluation vmaps: the sheet pushed 1 mm further out is all bridging/defect.
    frames = jnp.stack([jnp.asarray(x), jnp.asarray(x) * (1 + 0.001 / R)])
    lab2 = jax.vmap(lambda y: classify_zones(tool_distance(y, hemisphere_rig(radius=R)),
                                             kappa_max(*principal_curvatures(y, f)),
                                             d_crit(H_PLY), faces=f))(frames)
    np.testing.assert_array_equal(np.asarray(lab2[0]), labels)
    assert np.all(np.asarray(lab2[1]) != CONFORMING)


def test_wrinkle_radius_is_finite():
    r = np.asarray(wrinkle_radius(jnp.array([0.0, 1000.0, 20.0])))
    np.testing.assert_allclose(r, [1000.0, 1e-3, 0.05])
    g = jax.grad(lambda k: jnp.sum(wrinkle_radius(k)))(jnp.array([0.0, 1000.0]))
    assert np.all(np.isfinite(np.asarray(g)))


def test_section_profile_interpolates_on_the_projected_surface():
    n = 41
    s = np.linspace(-0.02, 0.02, n)
    X, Y = np.meshgrid(s, s, indexing="ij")
    Z = 0.3 * X - 0.1 * Y + 0.01  # a plane: linear interpolation is exact
    x = np.stack([X, Y, Z], -1).reshape(-1, 3)
    f = grid_faces(n, n, "tri")
    field = 2.0 * x[:, 0] + 5.0 * x[:, 1]
    pos, val, valid, height = section_profile(x, f, field, (-0.015, -0.01), (0.015, 0.012), 57)
    q = np.array([-0.015, -0.01]) + np.linspace(0, 1, 57)[:, None] * np.array([0.03, 0.022])
    assert np.all(np.asarray(valid))
    np.testing.assert_allclose(np.asarray(val), 2.0 * q[:, 0] + 5.0 * q[:, 1], atol=1e-12)
    np.testing.assert_allclose(np.asarray(height), 0.3 * q[:, 0] - 0.1 * q[:, 1] + 0.01, atol=1e-12)
    np.testing.assert_allclose(np.asarray(pos)[-1], np.hypot(0.03, 0.022))
    # A section running off the surface: samples outside are marked, never NaN.
    pos, val, valid, _ = section_profile(x, f, field, (0.0, 0.0), (0.04, 0.0), 21)
    assert np.asarray(valid).sum() == 11 and np.all(np.isfinite(np.asarray(val)))


def test_section_over_the_draped_sheet_sees_both_defects_and_the_nrmse():
    x, f, bump, lift = draped_sheet()
    d = tool_distance(x, hemisphere_rig(radius=R))
    pos, amp, valid, _ = section_profile(x, f, d, (-0.034, 0.0), (0.034, 0.0), 341)
    amp = np.asarray(amp)
    assert np.all(np.asarray(valid))
    assert amp.max() == pytest.approx(0.45 * H_PLY + 0.002, rel=2e-3)  # the lifted region
    near_bump = np.abs(np.asarray(pos) - 0.052) < 0.002
    assert amp[near_bump].max() == pytest.approx(0.45 * H_PLY + 0.0015, rel=2e-2)
    assert int(count_section_wrinkles(amp, valid, min_amplitude=float(d_crit(H_PLY)))) == 2
    # NRMSE: a copy shifted by 0.1 mm, against a range of ~2 mm.
    e = float(section_nrmse(pos, amp, pos, amp + 1e-4))
    assert e == pytest.approx(1e-4 / (amp.max() - amp.min()), rel=1e-9)
    assert float(section_nrmse(pos, amp, pos, amp)) == 0.0
    g = jax.grad(lambda o: section_nrmse(pos, amp, pos, o))(jnp.asarray(amp))
    assert np.all(np.isfinite(np.asarray(g)))


def test_count_section_wrinkles_like_an_engineer():
    s = np.linspace(0, 0.1, 1001)
    bumps = lambda centres, a=2e-3, w=3e-3: sum(a * np.exp(-((s - c) / w) ** 2) for c in centres)  # noqa: E731
    assert int(count_section_wrinkles(bumps([0.02, 0.05, 0.08]))) == 3
    # Two crests 3.8 mm apart, the dip between them 0.44 mm deep and far above the tool: one wrinkle at a
    # 0.5 mm prominence, two when the engineer accepts 0.2 mm dips.
    two = bumps([0.0481, 0.0519], w=2e-3)
    dip = two[np.argmin(np.abs(s - 0.05))]
    assert two.max() - dip < 0.5e-3 and two.max() - dip > 0.2e-3
    assert int(count_section_wrinkles(two)) == 1
    assert int(count_section_wrinkles(two, min_prominence=0.2e-3)) == 2
    # Noise below the prominence is not a wrinkle; small bumps below the amplitude do not count.
    noise = 1e-5 * np.sin(s * 3000)
    assert int(count_section_wrinkles(noise)) == 0
    assert int(count_section_wrinkles(bumps([0.03]) + bumps([0.07], a=0.6e-3), min_amplitude=1e-3)) == 1
    # A crest cut by the end of the section still counts; a gap closes a wrinkle.
    assert int(count_section_wrinkles(bumps([0.1]))) == 1
    valid = np.ones_like(s, bool)
    valid[500:520] = False
    assert int(count_section_wrinkles(bumps([0.0495]), valid)) == 1
    # jit / vmap over frames
    frames = jnp.stack([bumps([0.02]), bumps([0.02, 0.06])])
    np.testing.assert_array_equal(np.asarray(jax.jit(jax.vmap(count_section_wrinkles))(frames)), [1, 2])


def test_rms_moment_and_density():
    m1 = jnp.array([0.0, 3e-3, -4e-3])
    m2 = jnp.array([0.0, 4e-3, 3e-3])
    np.testing.assert_allclose(np.asarray(rms_fibre_moment(m1, m2)), [0.0, 5e-3 / np.sqrt(2), 5e-3 / np.sqrt(2)])
    g = jax.grad(lambda a: jnp.sum(rms_fibre_moment(a, a)))(jnp.zeros(3))
    assert np.all(np.isfinite(np.asarray(g)))
    v = np.random.default_rng(0).normal(1e-3, 2e-4, 5000)
    dens, edges = probability_density(v, bins=40, value_range=(0.0, 2e-3))
    ref, ref_edges = np.histogram(v, bins=40, range=(0.0, 2e-3), density=True)
    np.testing.assert_allclose(np.asarray(dens), ref, rtol=1e-10)
    np.testing.assert_allclose(np.asarray(edges), ref_edges)
    assert float(jnp.sum(dens * jnp.diff(edges))) == pytest.approx(1.0)
    dj, _ = jax.jit(lambda a: probability_density(a, 40, (0.0, 2e-3)))(v)
    np.testing.assert_allclose(np.asarray(dj), ref, rtol=1e-10)


def test_node_areas_sum_to_surface_area():
    n = 11
    s = np.linspace(0, 0.01, n)
    X, Y = np.meshgrid(s, s, indexing="ij")
    x = np.stack([X, Y, 0 * X], -1).reshape(-1, 3)
    for kind in ("quad", "tri"):
        a = np.asarray(node_areas(x, grid_faces(n, n, kind)))
        assert a.sum() == pytest.approx(1e-4)
        if kind == "quad":
            assert a.reshape(n, n)[5, 5] == pytest.approx(1e-6)
