"""jaxform.geometry against independent references, in float64.

- The closest point of a triangle against a brute-force minimisation over the triangle: a dense
  barycentric grid, refined by scipy's bounded minimiser, in every Voronoi region (face, three
  edges, three vertices) and for a zero-area triangle.
- The safe helpers: exact values away from zero and finite (zero) gradients at zero.
- The certified nearest-triangle search against an exhaustive search on a random mesh, with the
  cluster index, its second pass and exhaustive fallback forced, and the brute-force mode.
"""
import jax
import jax.numpy as jnp
import numpy as np
import pytest
from scipy.optimize import minimize

from jaxform import geometry as G

TRI = np.array([[0.0, 0.0, 0.0], [1.0, 0.1, 0.0], [0.2, 0.9, 0.1]])


def _reference_closest(p, a, b, c):
    """min over (s, t) >= 0, s + t <= 1 of |a + s (b - a) + t (c - a) - p|: dense grid + SLSQP."""
    n = 400
    s, t = np.meshgrid(np.linspace(0, 1, n + 1), np.linspace(0, 1, n + 1), indexing="ij")
    keep = s + t <= 1.0
    s, t = s[keep], t[keep]
    pts = a + s[:, None] * (b - a) + t[:, None] * (c - a)
    i = np.argmin(((pts - p) ** 2).sum(1))

    def f(z):
        r = a + z[0] * (b - a) + z[1] * (c - a) - p
        return r @ r

    res = minimize(f, [s[i], t[i]], method="SLSQP", bounds=[(0, 1), (0, 1)],
                   constraints=[{"type": "ineq", "fun": lambda z: 1.0 - z[0] - z[1]}],
                   options={"ftol": 1e-16, "maxiter": 200})
    z = res.x if res.fun <= ((pts[i] - p) ** 2).sum() else np.array([s[i], t[i]])
    return a + z[0] * (b - a) + z[1] * (c - a), np.array([1.0 - z[0] - z[1], z[0], z[1]])


def _region_points():
    a, b, c = TRI
    n = np.cross(b - a, c - a)
    n /= np.linalg.norm(n)
    out = {"face": (a + b + c) / 3 + 0.3 * n}
    for name, (u, v, w) in {"edge ab": (a, b, c), "edge bc": (b, c, a), "edge ca": (c, a, b)}.items():
        mid = 0.5 * (u + v)
        away = mid - w
        away -= (away @ (v - u)) / ((v - u) @ (v - u)) * (v - u)
        out[name] = mid + 0.5 * away / np.linalg.norm(away) - 0.2 * n
    cen = (a + b + c) / 3
    for name, v in {"vertex a": a, "vertex b": b, "vertex c": c}.items():
        out[name] = v + 0.7 * (v - cen) + 0.1 * n
    return out


@pytest.mark.parametrize("region", ["face", "edge ab", "edge bc", "edge ca", "vertex a", "vertex b", "vertex c"])
def test_closest_point_triangle_in_every_voronoi_region(region):
    p = _region_points()[region]
    q, w = G.closest_point_triangle(jnp.asarray(p), *map(jnp.asarray, TRI))
    q_ref, w_ref = _reference_closest(p, *TRI)
    np.testing.assert_allclose(np.asarray(q), q_ref, atol=1e-7)
    np.testing.assert_allclose(np.asarray(w), w_ref, atol=1e-6)
    np.testing.assert_allclose(np.sum(np.asarray(w)), 1.0, atol=1e-14)
    np.testing.assert_allclose(np.asarray(w) @ TRI, np.asarray(q), atol=1e-14)
    # The region is the expected one: exact one-hot weights at a vertex, an exact zero on an edge.
    w = np.asarray(w)
    if region.startswith("vertex"):
        assert np.max(w) == 1.0
    elif region.startswith("edge"):
        assert np.min(w) == 0.0 and np.max(w) < 1.0
    else:
        assert np.min(w) > 0.0
    d2 = float(G.point_triangle_sqdist(jnp.asarray(p), *map(jnp.asarray, TRI)))
    np.testing.assert_allclose(d2, ((q_ref - p) ** 2).sum(), rtol=1e-10, atol=1e-14)


def test_closest_point_triangle_random_points_and_broadcasting():
    rng = np.random.default_rng(0)
    p = rng.normal(scale=0.8, size=(40, 3)) + TRI.mean(0)
    q, w = G.closest_point_triangle(jnp.asarray(p), *map(jnp.asarray, TRI))
    for i in range(0, 40, 5):
        np.testing.assert_allclose(np.asarray(q[i]), _reference_closest(p[i], *TRI)[0], atol=1e-7)
    assert q.shape == (40, 3) and w.shape == (40, 3)


def test_zero_area_triangles_are_the_union_of_their_edges():
    p = np.array([[0.5, 0.3, 0.4], [3.0, 0.0, 0.0], [1.5, -0.2, 0.0]])
    for tri in (np.array([[0.0, 0, 0], [1.0, 0, 0], [2.0, 0, 0]]),   # collinear
                np.array([[0.0, 0, 0], [0.0, 0, 0], [2.0, 0, 0]]),   # two corners equal
                np.array([[2.0, 0, 0], [0.0, 0, 0], [1.0, 0, 0]])):  # collinear, middle last
        d = np.sqrt(np.asarray(G.point_triangle_sqdist(jnp.asarray(p), *map(jnp.asarray, tri))))
        np.testing.assert_allclose(d, [0.5, 1.0, 0.2], atol=1e-14)
    q, w = G.closest_point_triangle(jnp.zeros(3), *[jnp.ones(3)] * 3)  # a point triangle
    np.testing.assert_allclose(np.asarray(q), np.ones(3))


def test_safe_helpers_values_and_finite_gradients_at_zero():
    v = jnp.array([[3.0, 4.0, 0.0], [0.0, 0.0, 0.0]])
    np.testing.assert_allclose(np.asarray(G.safe_norm(v)), [5.0, 0.0])
    np.testing.assert_allclose(np.asarray(G.safe_normalize(v)), [[0.6, 0.8, 0.0], [0.0, 0.0, 1.0]])
    np.testing.assert_allclose(np.asarray(G.safe_normalize(v, fallback=v[0])), [[0.6, 0.8, 0.0], [3, 4, 0]])
    np.testing.assert_allclose(np.asarray(G.safe_sqrt(jnp.array([4.0, 0.0, -1.0]))), [2.0, 0.0, 0.0])
    np.testing.assert_allclose(np.asarray(G.safe_div(jnp.array([1.0, 1.0]), jnp.array([4.0, 0.0]))), [0.25, 0.0])
    zero3 = jnp.zeros(3)
    grads = [
        jax.grad(lambda x: G.safe_norm(x))(zero3),
        jax.grad(lambda x: jnp.sum(G.safe_normalize(x)))(zero3),
        jax.grad(G.safe_sqrt)(0.0),
        jax.grad(G.safe_sqrt)(-1.0),
        jax.grad(lambda y: G.safe_div(1.0, y))(0.0),
        jax.grad(lambda y: G.safe_div(y, 0.0 * y))(0.0),
    ]
    for g in grads:
        assert np.all(np.isfinite(np.asarray(g))) and np.all(np.asarray(g) == 0.0)
    np.testing.assert_allclose(np.asarray(jax.grad(G.safe_norm)(jnp.array([3.0, 4.0, 0.0]))), [0.6, 0.8, 0.0])
    # Distance to a triangle: finite gradient for a point on it.
    g = jax.grad(lambda x: jnp.sqrt(G.point_triangle_sqdist(x, *map(jnp.asarray, TRI)) + 1.0))(
        jnp.asarray(TRI.mean(0)))
    assert np.all(np.isfinite(np.asarray(g)))


def _random_mesh(rng, n=24):
    """A wavy sheet plus a random soup of triangles: (V, 3), (F, 3)."""
    s = np.linspace(-1, 1, n)
    X, Y = np.meshgrid(s, s, indexing="ij")
    Z = 0.2 * np.sin(3 * X) * np.cos(2 * Y)
    v = np.stack([X, Y, Z], -1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(n - 1), np.arange(n - 1), indexing="ij")
    a = (i * n + j).ravel()
    f = np.concatenate([np.stack([a, a + n, a + n + 1], 1), np.stack([a, a + n + 1, a + 1], 1)])
    soup = rng.uniform(-1, 1, (60, 3, 3)) * [1, 1, 0.5] + [0, 0, 0.6]
    v2 = np.concatenate([v, soup.reshape(-1, 3)])
    f2 = np.concatenate([f, len(v) + np.arange(180).reshape(60, 3)])
    return v2, f2


def _brute_sqdist(points, v, f):
    tri = jnp.asarray(v[f])
    d = G.point_triangle_sqdist(jnp.asarray(points)[:, None, :], tri[None, :, 0], tri[None, :, 1], tri[None, :, 2])
    return np.asarray(d)


@pytest.mark.parametrize("budget", [{}, {"ks": 1, "k": 1, "ks2": 1, "k2": 2, "batch": 32}])
def test_certified_search_matches_brute_force(budget):
    rng = np.random.default_rng(1)
    v, f = _random_mesh(rng)
    x = np.concatenate([rng.uniform(-1.3, 1.3, (300, 3)), [[0.0, 0.0, 5.0], [0.0, 0.0, 0.0]]])
    ref = _brute_sqdist(x, v, f)
    index = G.build_triangle_index(v, f, **budget)
    q, w, ids = (np.asarray(t) for t in G.closest_point_on_mesh(x, index))
    best = ref.min(axis=1)
    np.testing.assert_allclose(((q - x) ** 2).sum(1), best, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(ref[np.arange(len(x)), ids], best, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(np.einsum("nk,nkd->nd", w, v[f][ids]), q, atol=1e-14)
    # The brute-force mode of the same search (an index without clusters, e.g. traced triangles).
    ids_b = np.asarray(jax.jit(G.closest_triangle)(x, G.TriangleIndex(tri=jnp.asarray(v[f]))))
    np.testing.assert_allclose(ref[np.arange(len(x)), ids_b], best, rtol=1e-12, atol=1e-15)


def test_search_gradient_is_the_unit_vector_from_the_closest_point():
    rng = np.random.default_rng(2)
    v, f = _random_mesh(rng, 12)
    index = G.build_triangle_index(v, f)
    x = rng.uniform(-1, 1, (20, 3))

    def dist(y):
        q, _, _ = G.closest_point_on_mesh(y, index)
        return G.safe_norm(y - q)

    g = np.asarray(jax.jacrev(lambda y: jnp.sum(dist(y)))(jnp.asarray(x)))
    q = np.asarray(G.closest_point_on_mesh(x, index)[0])
    u = (x - q) / np.linalg.norm(x - q, axis=1, keepdims=True)
    np.testing.assert_allclose(g, u, atol=1e-9)
