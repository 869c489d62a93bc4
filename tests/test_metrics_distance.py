"""Distance from fabric nodes to a tool surface, checked against independent references.

The reference is a brute-force point-to-triangle distance written here from Ericson's Voronoi-region
method (Real-Time Collision Detection, section 5.1.5), a different algorithm from the library's.
"""
import warnings

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from jaxform import tools
from jaxform.io.tool_mesh import hemisphere_rig_mesh
from jaxform.metrics import ToolWarning, build_tool_index, tool_distance
from helpers import central_difference


def _ericson_closest(p, a, b, c):
    """Closest point on triangles (a, b, c) (T,3) to one point p (3,), numpy, Voronoi regions."""
    ab, ac, ap = b - a, c - a, p - a
    d1, d2 = (ab * ap).sum(1), (ac * ap).sum(1)
    bp = p - b
    d3, d4 = (ab * bp).sum(1), (ac * bp).sum(1)
    cp = p - c
    d5, d6 = (ab * cp).sum(1), (ac * cp).sum(1)
    vc = d1 * d4 - d3 * d2
    vb = d5 * d2 - d1 * d6
    va = d3 * d6 - d5 * d4
    out = np.empty_like(a)
    done = np.zeros(len(a), bool)

    def put(mask, val):
        nonlocal done
        m = mask & ~done
        out[m] = val[m]
        done |= m

    with np.errstate(divide="ignore", invalid="ignore"):
        put((d1 <= 0) & (d2 <= 0), a)
        put((d3 >= 0) & (d4 <= d3), b)
        put((vc <= 0) & (d1 >= 0) & (d3 <= 0), a + (d1 / (d1 - d3))[:, None] * ab)
        put((d6 >= 0) & (d5 <= d6), c)
        put((vb <= 0) & (d2 >= 0) & (d6 <= 0), a + (d2 / (d2 - d6))[:, None] * ac)
        put((va <= 0) & ((d4 - d3) >= 0) & ((d5 - d6) >= 0),
            b + ((d4 - d3) / ((d4 - d3) + (d5 - d6)))[:, None] * (c - b))
        denom = 1.0 / (va + vb + vc)
        v = vb * denom
        w = vc * denom
        put(np.ones(len(a), bool), a + v[:, None] * ab + w[:, None] * ac)
    return out


def brute_distance(nodes, verts, faces):
    a, b, c = verts[faces[:, 0]], verts[faces[:, 1]], verts[faces[:, 2]]
    return np.array([np.sqrt(((_ericson_closest(p, a, b, c) - p) ** 2).sum(1).min()) for p in nodes])


@pytest.fixture(scope="module")
def small_tool():
    return hemisphere_rig_mesh(size=0.008)


@pytest.fixture(scope="module")
def tool20k():
    v, f = hemisphere_rig_mesh(size=0.002)
    assert 19_000 <= len(f) <= 22_000
    return v, f


def _query_points(rng, n):
    """Points near the rig surface (the use case), points far above and below, and exact hits."""
    xy = rng.uniform(-0.12, 0.12, (n, 2))
    r = np.hypot(xy[:, 0], xy[:, 1])
    z = np.sqrt(np.maximum(0.05**2 - r**2, 0.0)) + rng.uniform(-0.002, 0.004, n)
    near = np.column_stack([xy, z])
    far = rng.uniform([-0.2, -0.2, -0.1], [0.2, 0.2, 0.15], (n // 4, 3))
    centre = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 0.01]])  # equidistant from the whole cap
    return np.concatenate([near, far, centre])


def test_distance_matches_brute_force_on_20k_face_tool(tool20k):
    v, f = tool20k
    x = _query_points(np.random.default_rng(1), 600)
    d = np.asarray(tool_distance(x, v, f))
    ref = brute_distance(x, v, f)
    assert d.shape == (len(x),) and d.dtype == np.float64
    assert np.max(np.abs(d - ref)) <= 1e-9


def test_distance_closest_point_need_not_be_a_vertex():
    v = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    f = np.array([[0, 1, 2]])
    x = np.array([[0.25, 0.25, 0.3], [0.5, 0.5, 0.0], [2.0, -1.0, 0.0], [-0.5, 0.5, 1.0]])
    d = np.asarray(tool_distance(x, v, f))
    np.testing.assert_allclose(d, [0.3, 0.0, np.sqrt(2.0), np.sqrt(0.25 + 1.0)], atol=1e-14)


# 13 s of the default run (the search compiled again in float32): -m slow
@pytest.mark.slow
def test_distance_float32_and_int32(small_tool):
    v, f = small_tool
    x = _query_points(np.random.default_rng(2), 200)
    d64 = np.asarray(tool_distance(x, v, f))
    d32 = tool_distance(x.astype(np.float32), v, f.astype(np.int32))
    assert d32.dtype == jnp.float32
    np.testing.assert_allclose(np.asarray(d32), d64, atol=2e-6)


def test_distance_jit_vmap_grad(small_tool):
    v, f = small_tool
    rng = np.random.default_rng(3)
    frames = np.stack([_query_points(rng, 100)[:100] for _ in range(3)])
    fn = jax.jit(jax.vmap(lambda x: tool_distance(x, v, f)))
    d = np.asarray(fn(frames))
    np.testing.assert_allclose(d[1], np.asarray(tool_distance(frames[1], v, f)), atol=1e-14)
    # Gradient of the distance is the unit vector from the closest point; finite differences agree.
    x = frames[0]
    g = np.asarray(jax.grad(lambda y: jnp.sum(tool_distance(y, v, f)))(x))
    assert np.all(np.isfinite(g))
    for i in (0, 17, 42):
        for k in range(3):
            fd = central_difference(lambda p: brute_distance(p, v, f), x[i:i + 1], 1e-7, index=(0, k))[0]
            assert abs(fd - g[i, k]) < 1e-5


def test_distance_traced_tool_uses_exact_exhaustive_search(small_tool):
    v, f = small_tool
    x = _query_points(np.random.default_rng(4), 40)
    d = jax.jit(tool_distance)(x, jnp.asarray(v), jnp.asarray(f))
    np.testing.assert_allclose(np.asarray(d), np.asarray(tool_distance(x, v, f)), atol=1e-12)


def test_distance_gradient_finite_on_the_surface():
    v = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    f = np.array([[0, 1, 2]])
    x = np.array([[0.2, 0.2, 0.0], [0.0, 0.0, 0.0]])
    g = jax.grad(lambda y: jnp.sum(tool_distance(y, v, f)))(x)
    assert np.all(np.isfinite(np.asarray(g)))


def test_hemisphere_rig_closed_form():
    rig = tools.hemisphere_rig(radius=0.05)
    x = np.array([
        [0.0, 0.0, 0.08],     # above the pole: 30 mm
        [0.0, 0.0, 0.0],      # centre of the sphere: R
        [0.1, 0.0, 0.004],    # over the base plane: 4 mm
        [0.03, 0.04, 0.0],    # rim circle
        [0.04, 0.0, 0.03],    # on the cap
        [0.06, 0.0, -0.002],  # below the base plane, outside the rim: 2 mm
    ])
    d = np.asarray(tool_distance(x, rig))
    np.testing.assert_allclose(d, [0.03, 0.05, 0.004, 0.0, 0.0, 0.002], atol=1e-15)
    g = jax.grad(lambda y: jnp.sum(tool_distance(y, rig)))(x)
    assert np.all(np.isfinite(np.asarray(g)))
    # Off the z axis, and agreement with a fine mesh of the rig (nodes outside the tool).
    c = np.array([0.01, -0.02, 0.003])
    np.testing.assert_allclose(np.asarray(tool_distance(x + c, tools.hemisphere_rig(0.05, tuple(c)))), d,
                               atol=1e-15)
    v, f = hemisphere_rig_mesh(0.05, size=0.002, extent=0.12)
    x2 = _query_points(np.random.default_rng(5), 300)
    x2 = x2[(np.hypot(x2[:, 0], x2[:, 1]) < 0.11) & (x2[:, 2] > 0.0) & (np.linalg.norm(x2, axis=1) > 0.05)]
    dm = np.asarray(tool_distance(x2, v, f))
    # chordal error of a 2 mm faceting of a 50 mm sphere: about s^2/(8R) ~ 1e-5 m
    np.testing.assert_allclose(np.asarray(tool_distance(x2, rig)), dm, atol=3e-5)


def test_analytic_tools_and_their_union():
    x = np.array([[1.0, 2.0, 0.003], [0.0, 0.0, -0.002]])
    np.testing.assert_allclose(np.asarray(tool_distance(x, tools.Plane(point=(0.0, 0.0, 0.0)))), [0.003, 0.002])
    tilted = tools.Plane(point=(0.0, 0.0, 0.0), normal=(0.0, 0.0, 5.0))
    np.testing.assert_allclose(np.asarray(tool_distance(x, [tilted])), [0.003, 0.002])
    # The forming rig at its reference pose: distance to the nearest of punch, die and holder.
    rig = tools.FormingTools(punch=tools.Punch(0.05, apex_z=0.01), die=tools.Die(0.053, 0.006),
                             holder=tools.BlankHolder(0.053, bottom_z=0.004))
    y = np.array([[0.0, 0.0, 0.007], [0.08, 0.0, 0.001], [0.08, 0.0, 0.0035]])
    np.testing.assert_allclose(np.asarray(tool_distance(y, rig)), [0.003, 0.001, 0.0005], atol=1e-15)
    with pytest.raises(ValueError, match="tool_faces is required"):
        tool_distance(x, np.zeros((3, 3)))


def test_bad_input_is_refused_or_warned():
    v = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    f = np.array([[0, 1, 2]])
    with pytest.raises(ValueError, match="empty"):
        tool_distance(np.zeros((2, 3)), v, np.zeros((0, 3), int))
    with pytest.raises(ValueError, match="non-finite"):
        tool_distance(np.array([[0.0, 0.0, np.nan]]), v, f)
    with pytest.raises(ValueError, match="non-finite"):
        tool_distance(np.zeros((1, 3)), np.array([[0, 0, np.nan], [1, 0, 0], [0, 1, 0.0]]), f)
    with pytest.raises(ValueError, match="refer to vertices"):
        tool_distance(np.zeros((1, 3)), v, np.array([[0, 1, 3]]))
    with pytest.raises(ValueError, match="triangles"):
        tool_distance(np.zeros((1, 3)), v, np.array([[0, 1, 2, 0]]))
    fabric = np.random.default_rng(0).uniform(0, 0.1, (50, 3))
    with pytest.warns(ToolWarning, match="units"):
        tool_distance(fabric, v * 1000.0 + 500.0, f)  # a tool in mm, far from a fabric in m
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        tool_distance(fabric, v * 0.1, f)


def test_degenerate_tool_triangles_act_as_segments():
    v = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]])  # collinear: zero area
    f = np.array([[0, 1, 2]])
    x = np.array([[0.5, 0.3, 0.4], [3.0, 0.0, 0.0]])
    d = np.asarray(tool_distance(x, v, f))
    np.testing.assert_allclose(d, [0.5, 1.0], atol=1e-14)


def test_index_is_exact_for_every_node_even_when_not_certified(tool20k):
    """Tiny first-pass budget: most nodes go through the second and exhaustive passes."""
    v, f = tool20k
    x = _query_points(np.random.default_rng(6), 150)
    idx = build_tool_index(v, f, ks=1, k=1, ks2=1, k2=2, batch=64)
    np.testing.assert_allclose(np.asarray(tool_distance(x, idx)), brute_distance(x, v, f), atol=1e-12)
