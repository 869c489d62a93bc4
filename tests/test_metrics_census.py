"""The wrinkle census on constructed flanges with known ridges (issue 15): k ridges give k
wrinkles where they are, with their extent, width and amplitude; merged and forked ridges count
once, ridges apart count apart; a lifted flange, broad lobes and short bumps count nothing."""
import numpy as np
import pytest

from jaxform.metrics.census import Wrinkle, wrinkle_census

R_IN = 59e-3  # die opening 53 mm + fillet 6 mm
SIDE, H = 0.25, 4e-3  # the Case A blank, 4 mm elements


def _blank():
    g = np.arange(-SIDE / 2, SIDE / 2 + 1e-9, H)
    X, Y = np.meshgrid(g, g, indexing="xy")
    return np.stack([X.ravel(), Y.ravel(), np.zeros(X.size)], 1)


def _quads():
    n = int(round(SIDE / H)) + 1
    i, j = np.meshgrid(np.arange(n - 1), np.arange(n - 1), indexing="xy")
    p = (j * n + i).ravel()
    return np.stack([p, p + 1, p + n + 1, p + n], 1)


def _ridge(x, angle_deg, amp, sigma, r0, r1):
    """A ridge of height ``amp`` along the ray at ``angle_deg`` between radii r0 and r1 (smooth
    ends), Gaussian across it with standard deviation ``sigma`` (m, arc length)."""
    r = np.hypot(x[:, 0], x[:, 1])
    th = np.arctan2(x[:, 1], x[:, 0])
    d = (th - np.radians(angle_deg) + np.pi) % (2 * np.pi) - np.pi
    along = np.clip(np.minimum(r - r0, r1 - r) / 4e-3, 0.0, 1.0)
    return amp * along * np.exp(-0.5 * (r * d / sigma) ** 2)


def _lift(x):
    r = np.hypot(x[:, 0], x[:, 1])
    return np.where(r > R_IN, 2e-3 + 0.03 * (r - R_IN), 0.0)


def test_k_ridges_are_k_wrinkles_where_they_are():
    x = _blank()
    angles = [45.0, 135.0, 225.0, 315.0, 80.0]
    dev = _lift(x) + sum(_ridge(x, a, 3e-3, 4e-3, 80e-3, 120e-3) for a in angles)
    ws = wrinkle_census(x, dev, r_inner=R_IN)
    assert len(ws) == 5
    # the same on the blank's own faces (the highest face over each sample)
    on_faces = wrinkle_census(x, dev, faces=_quads(), r_inner=R_IN)
    np.testing.assert_allclose(sorted(w.angle_deg for w in on_faces), sorted(angles), atol=1.0)
    assert all(isinstance(w, Wrinkle) for w in ws)
    found = sorted(w.angle_deg for w in ws)
    np.testing.assert_allclose(found, sorted(angles), atol=1.0)
    for w in ws:
        assert w.quadrant == int(w.angle_deg // 90) + 1
        assert w.r_inner_m == pytest.approx(81e-3, abs=3e-3) and w.r_outer_m == pytest.approx(119e-3, abs=3e-3)
        assert w.length_m == pytest.approx(w.r_outer_m - w.r_inner_m, rel=0.1)
        assert w.width_m == pytest.approx(2.355 * 4e-3, rel=0.25)  # full width at half height
        assert w.amplitude_m == pytest.approx(3e-3, rel=0.15)
        assert w.max_deviation_m > 3e-3  # on top of the lift
    assert set(ws[0].to_dict()) >= {"angle_deg", "quadrant", "length_m", "width_m", "amplitude_m"}


def test_a_lifted_flange_lobes_and_bumps_are_not_wrinkles():
    x = _blank()
    r = np.hypot(x[:, 0], x[:, 1])
    th = np.arctan2(x[:, 1], x[:, 0])
    assert wrinkle_census(x, _lift(x), r_inner=R_IN) == []
    # four broad lobes (80 mm wide at r = 100 mm), 5 mm high: ridges, lobes where a width is set
    lobes = _lift(x) + np.where(r > R_IN, 2.5e-3 * (1 + np.cos(4 * th)), 0.0)
    assert len(wrinkle_census(x, lobes, r_inner=R_IN)) == 4
    assert wrinkle_census(x, lobes, r_inner=R_IN, max_width=30e-3) == []
    # a bump 4 mm long radially
    bump = _lift(x) + _ridge(x, 30.0, 3e-3, 3e-3, 100e-3, 104e-3)
    assert wrinkle_census(x, bump, r_inner=R_IN) == []
    # ripples below the prominence
    assert wrinkle_census(x, _lift(x) + _ridge(x, 30.0, 0.3e-3, 4e-3, 70e-3, 120e-3), r_inner=R_IN) == []


def test_merged_forked_and_separate_ridges():
    x = _blank()
    base = _lift(x)
    # two ridges 1.2 sigma apart: no dip between them, one wrinkle
    merged = base + _ridge(x, 40.0, 3e-3, 6e-3, 70e-3, 120e-3) + _ridge(x, 44.0, 3e-3, 6e-3, 70e-3, 120e-3)
    assert len(wrinkle_census(x, merged, r_inner=R_IN)) == 1
    # the same two ridges 25 mm apart at r = 100 mm: a deep dip between them, two wrinkles
    apart = base + _ridge(x, 30.0, 3e-3, 3e-3, 70e-3, 120e-3) + _ridge(x, 45.0, 3e-3, 3e-3, 70e-3, 120e-3)
    ws = wrinkle_census(x, apart, r_inner=R_IN)
    assert len(ws) == 2 and sorted(round(w.angle_deg) for w in ws) == [30, 45]
    # a ridge that forks into two at r = 100 mm stays one wrinkle, spanning both parts
    fork = (base + _ridge(x, 45.0, 3e-3, 3e-3, 70e-3, 102e-3) + _ridge(x, 42.0, 3e-3, 3e-3, 98e-3, 125e-3)
            + _ridge(x, 48.0, 3e-3, 3e-3, 98e-3, 125e-3))
    ws = wrinkle_census(x, fork, r_inner=R_IN)
    assert len(ws) == 1
    assert ws[0].r_inner_m < 75e-3 and ws[0].r_outer_m > 120e-3
    # a ridge across the square blank's corner, where the rings leave the part
    corner = base + _ridge(x, 45.0, 3e-3, 3e-3, 130e-3, 170e-3)
    ws = wrinkle_census(x, corner, r_inner=R_IN)
    assert len(ws) == 1 and ws[0].angle_deg == pytest.approx(45.0, abs=1.0)


def test_bad_input_is_refused_at_the_edge():
    x = _blank()
    with pytest.raises(ValueError, match="deviation"):
        wrinkle_census(x, np.zeros(3), r_inner=R_IN)
    with pytest.raises(ValueError, match="finite"):
        wrinkle_census(x, np.full(len(x), np.nan), r_inner=R_IN)
    with pytest.raises(ValueError, match="faces"):
        wrinkle_census(x, np.zeros(len(x)), faces=np.array([[0, 1, len(x)]]), r_inner=R_IN)
    with pytest.raises(ValueError, match="inside r_inner"):
        wrinkle_census(x, np.zeros(len(x)), r_inner=1.0)
