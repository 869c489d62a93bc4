"""Principal curvatures by iterative quadric fitting, against analytic surfaces and libigl."""
import warnings

import igl
import jax
import jax.numpy as jnp
import numpy as np
import pytest

from _surfaces import cube_sphere, grid_faces, surface
from jaxform.metrics import MeshWarning, curvature_stencil, kappa_max, principal_curvatures
from helpers import central_difference


def _tri(f):
    return f if f.shape[1] == 3 else np.concatenate([f[:, [0, 1, 2]], f[:, [0, 2, 3]]])


def _median_rel_err(km, exact, mask):
    return float(np.median(np.abs(km[mask] - exact[mask]) / exact[mask]))


def _igl_kappa_max(x, f):
    _, _, p1, p2, _ = igl.principal_curvature(np.asarray(x, np.float64), _tri(f).astype(np.int64))
    return np.maximum(np.abs(p1), np.abs(p2))


CASES = [(name, h, kind) for name in ("sphere", "cylinder", "saddle", "wrinkle", "torus")
         for h in (0.001, 0.002) for kind in ("quad", "tri")]


@pytest.mark.parametrize("name,h,kind", CASES)
def test_kappa_max_on_analytic_surfaces(name, h, kind):
    x, f, k1e, k2e, depth = surface(name, h, kind)
    k1, k2 = principal_curvatures(x, f)
    km = np.asarray(kappa_max(k1, k2))
    exact = np.maximum(np.abs(k1e), np.abs(k2e))
    assert km.shape == (len(x),) and np.all(np.isfinite(km)), "every node, boundary included"
    assert np.all(np.isfinite(np.asarray(k1))) and np.all(np.asarray(k1) >= np.asarray(k2))
    # Nodes at least two rings from the boundary; on the wrinkle, leave out the nodes at the
    # inflection lines where the exact kappa_max is (near) zero and a relative error is undefined.
    mask = (depth >= 2) & (exact > 0.05 * exact.max())
    err = _median_rel_err(km, exact, mask)
    limit = 0.03 if (name == "wrinkle" and h == 0.002) else 0.01
    assert err <= limit, f"median relative error {err:.4%} > {limit:.0%}"
    # Not worse than libigl's principal_curvature (default neighbourhood) on the same mesh.
    err_igl = _median_rel_err(_igl_kappa_max(x, f), exact, mask)
    assert err <= err_igl, f"ours {err:.4%} vs libigl {err_igl:.4%}"
    # Signs follow SPEC section 2 (positive bending away from the normal): k1, k2 themselves match.
    m = depth >= 2
    scale = exact.max()
    assert np.median(np.abs(np.asarray(k1)[m] - k1e[m])) < 0.03 * scale
    assert np.median(np.abs(np.asarray(k2)[m] - k2e[m])) < 0.03 * scale


def test_quad_one_ring_is_every_node_of_the_faces_around():
    f = grid_faces(6, 6, "quad")
    st = curvature_stencil(f, 36)
    counts = np.asarray(st.ring_mask).sum(1).reshape(6, 6)
    assert np.all(counts[1:-1, 1:-1] == 8)
    assert np.all(counts[0, 1:-1] == 5)  # edge nodes keep their one-ring (five nodes)
    # corners have three one-ring nodes: the two-ring is used instead
    assert counts[0, 0] == len({1, 2, 6, 7, 8, 12, 13, 14})
    ring = np.asarray(st.ring)[14][np.asarray(st.ring_mask)[14]]
    assert sorted(ring.tolist()) == [7, 8, 9, 13, 15, 19, 20, 21]


@pytest.mark.parametrize("kind,rings", [("quad", 1), ("tri", 2)])
def test_noisy_sphere(kind, rings):
    """Sphere R = 50 mm, 5 mm elements, 0.02 mm Gaussian noise on every node coordinate.

    On triangles the paper's one-ring (six nodes) gives about 7.3%; the two-ring option is the
    setting to use for noisy data there."""
    x, f = cube_sphere(0.05, 0.005, kind)
    xn = x + np.random.default_rng(0).normal(0.0, 2e-5, x.shape)
    km = np.asarray(kappa_max(*principal_curvatures(xn, f, rings=rings)))
    err = float(np.median(np.abs(km * 0.05 - 1.0)))
    assert err <= 0.07, err
    assert err <= float(np.median(np.abs(_igl_kappa_max(xn, f) * 0.05 - 1.0)))


def test_closed_sphere_with_irregular_valence():
    x, f = cube_sphere(0.05, 0.002, "quad")
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a clean, consistently wound mesh: no MeshWarning
        k1, k2 = principal_curvatures(x, f)
    np.testing.assert_allclose(np.asarray(k1), 20.0, rtol=5e-3)  # outward normals: +1/R
    np.testing.assert_allclose(np.asarray(k2), 20.0, rtol=5e-3)


def test_gradient_of_mean_kappa_max_matches_finite_differences():
    """A perturbed torus patch: |k1| and |k2| stay apart, so kappa_max is smooth in the nodes."""
    x, f, *_ = surface("torus", 0.002, "quad")
    xs = x + np.random.default_rng(0).normal(0, 5e-5, x.shape)

    def loss(y):
        return jnp.mean(kappa_max(*principal_curvatures(y, f, max_iter=20, tol=0.0)))

    g = np.asarray(jax.grad(loss)(xs))
    assert np.all(np.isfinite(g))
    rng = np.random.default_rng(1)
    for _ in range(6):
        i, k = rng.integers(len(xs)), rng.integers(3)
        fd = central_difference(loss, xs, 1e-7, index=(i, k))
        assert abs(fd - g[i, k]) <= 1e-4 * abs(g).max(), (i, k, fd, g[i, k])


def test_jit_vmap_dtypes_and_concrete_faces():
    x, f, _, _, depth = surface("torus", 0.002, "quad")
    frames = np.stack([x, x * 1.1, x * 0.9])
    fn = jax.jit(jax.vmap(lambda y: kappa_max(*principal_curvatures(y, f))))
    km = np.asarray(fn(frames))
    ref = np.asarray(kappa_max(*principal_curvatures(x, f)))
    # the same arithmetic compiled two ways: rounding apart (measured up to 2.1e-9 with XLA's loop emitters)
    np.testing.assert_allclose(km[0], ref, rtol=1e-8)
    np.testing.assert_allclose(km[1], ref / 1.1, rtol=1e-6)  # curvature scales as 1/length
    k1_32, _ = principal_curvatures(x.astype(np.float32), f.astype(np.int32))
    assert k1_32.dtype == jnp.float32 and k1_32.shape == (len(x),)
    km32 = np.asarray(kappa_max(*principal_curvatures(x.astype(np.float32), f)))
    assert np.all(np.isfinite(km32))
    np.testing.assert_allclose(km32[depth >= 1], ref[depth >= 1], rtol=1e-3)
    with pytest.raises(TypeError, match="concrete"):
        jax.jit(principal_curvatures)(x, jnp.asarray(f))


def test_bad_meshes():
    x, f, *_ = surface("sphere", 0.004, "quad")
    bad = x.copy()
    bad[3, 1] = np.nan
    with pytest.raises(ValueError, match="non-finite"):
        principal_curvatures(bad, f)
    with pytest.raises(ValueError, match="refer to nodes"):
        principal_curvatures(x, f + 1)
    with pytest.raises(ValueError, match="shape"):
        principal_curvatures(x, f[:, :2])
    # A degenerate face (repeated corner) and a duplicated node: warned, values stay finite.
    f2 = np.concatenate([f, [[0, 0, 1, 1]]])
    with pytest.warns(MeshWarning, match="repeated corners"):
        k1, k2 = principal_curvatures(x, f2)
    assert np.all(np.isfinite(np.asarray(k1)))
    x3 = np.concatenate([x, x[:1]])  # a node coinciding with node 0, in no face
    k1, _ = principal_curvatures(x3, f)
    assert np.all(np.isfinite(np.asarray(k1)))
    # Non-manifold: a third face on an existing edge.
    f4 = np.concatenate([_tri(f), [[f[0, 0], f[0, 2], len(x)]]])  # on the split diagonal
    with pytest.warns(MeshWarning, match="non-manifold"):
        principal_curvatures(np.concatenate([x, [[0.0, 0.0, 0.1]]]), f4)
    # Flipped faces: warned.
    f5 = f.copy()
    f5[::7] = f5[::7, ::-1]
    with pytest.warns(MeshWarning, match="consistently oriented"):
        principal_curvatures(x, f5)
