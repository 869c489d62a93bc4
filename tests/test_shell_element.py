"""The shell element: forces are the energy gradient, rigid motions are force free, signs and readings."""
import jax
import jax.numpy as jnp
import numpy as np
import pytest

from jaxform.materials import NCF_FCIM359, WOVEN_38616
from jaxform.mesh import Mesh
from jaxform.shell import (Shell, _shear_energy, energy, energy_parts, fibre_curvatures, forces, shear_angle,
                           fibre_vectors, shear_resultant)

# jitted once per module: op-by-op (eager) evaluation of the element kernel costs tens of seconds
forces, energy = jax.jit(forces), jax.jit(energy)


def _curved_sheared_mesh():
    """A cylindrical-ish, doubly curved patch meshed with a skewed (sheared) grid: stress-free reference."""
    m = Mesh.rectangle(0.06, 0.04, 0.006)
    X = np.asarray(m.nodes)
    u, w = X[:, 0], X[:, 1]
    nodes = np.stack([u + 0.3 * w, w, 2.0 * u**2 - 1.0 * w**2 + 0.5 * u * w], axis=1)
    return Mesh.from_arrays(nodes, m.faces)


def _random_rotation(seed):
    q, _ = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    return q * np.sign(np.linalg.det(q))


@pytest.mark.parametrize("fabric", [WOVEN_38616, NCF_FCIM359])
def test_rigid_motion_of_curved_sheared_reference_is_force_free(fabric):
    mesh = _curved_sheared_mesh()
    shell = Shell.build(mesh, fabric)
    x0 = jnp.asarray(mesh.nodes)
    R = _random_rotation(1)
    x = x0 @ R.T + jnp.array([0.3, -0.2, 0.7])
    f = forces(x, shell)
    # force scale: a 1% deformation of the same mesh
    xd = x0 + 0.01 * jnp.asarray(np.random.default_rng(2).normal(size=x0.shape)) * 0.006
    scale = float(jnp.max(jnp.abs(forces(xd, shell))))
    assert scale > 0
    assert float(jnp.max(jnp.abs(f))) <= 1e-9 * scale
    assert abs(float(energy(x, shell))) <= 1e-9 * abs(float(energy(xd, shell)))


def test_rigid_motion_of_deformed_state_rotates_forces():
    mesh = _curved_sheared_mesh()
    shell = Shell.build(mesh, NCF_FCIM359)
    rng = np.random.default_rng(3)
    x = jnp.asarray(mesh.nodes) + 0.0005 * jnp.asarray(rng.normal(size=mesh.nodes.shape))
    f = forces(x, shell)
    R = jnp.asarray(_random_rotation(4))
    f2 = forces(x @ R.T + jnp.array([1.0, 2.0, 3.0]), shell)
    assert float(jnp.max(jnp.abs(f2 - f @ R.T))) <= 1e-9 * float(jnp.max(jnp.abs(f)))
    assert float(jnp.max(jnp.abs(jnp.sum(f, axis=0)))) <= 1e-9 * float(jnp.max(jnp.abs(f)))  # no net force


@pytest.mark.parametrize("fabric", [WOVEN_38616, NCF_FCIM359])
def test_assembled_forces_equal_minus_energy_gradient(fabric):
    mesh = Mesh.rectangle(0.03, 0.02, 0.005)
    shell = Shell.build(mesh, fabric)
    rng = np.random.default_rng(0)
    x = jnp.asarray(mesh.nodes) + 0.0008 * jnp.asarray(rng.normal(size=mesh.nodes.shape))
    f = forces(x, shell)
    g = jax.grad(energy)(x, shell)
    np.testing.assert_allclose(np.asarray(f), -np.asarray(g), rtol=1e-9, atol=1e-9 * float(jnp.max(jnp.abs(g))))


@pytest.mark.parametrize("fabric", [WOVEN_38616, NCF_FCIM359])
def test_forces_and_energies_from_displacements_equal_those_from_positions(fabric):
    """The integrator's path (displacements; the fibre strain from the edges' changes, no
    cancellation) and the positions' path (checked against autodiff above) are the same forces and
    energy parts in float64, on a stretched, sheared and bent blank, with the weights too."""
    from jaxform.shell import forces_and_energy_soa

    mesh = Mesh.rectangle(0.03, 0.02, 0.005)
    shell = Shell.build(mesh, fabric)
    X = jnp.asarray(mesh.nodes).T
    rng = np.random.default_rng(3)
    u = jnp.asarray(np.stack([3e-3 * X[1] + 1e-3 * X[0], -2e-3 * X[0], 6.0 * (X[0] - 0.015) ** 2])
                    + 3e-4 * rng.normal(size=X.shape))
    for w in (None, (0.3, -0.7, 1.3)):
        f_x, p_x = forces_and_energy_soa(X + u, shell, w)
        f_u, p_u = forces_and_energy_soa(u, shell, w, displacement=True)
        np.testing.assert_allclose(np.asarray(f_u), np.asarray(f_x), rtol=0, atol=1e-9 * float(jnp.max(jnp.abs(f_x))))
        for k in ("tension", "shear", "bending"):
            assert float(p_u[k]) == pytest.approx(float(p_x[k]), rel=1e-9, abs=1e-15), k


def test_float32_fibre_strains_from_displacements_are_exact_to_their_own_roundoff():
    """Fibre tension forces in float32 from displacements (the integrator's path): the strain comes
    from the edges' displacement parts (``2 g0 . dg + dg . dg``, no cancellation), so on a blank
    carried 50 mm with fibre strains of about 1e-4 the float32 forces match float64's on the same
    (float32) displacements to 1e-5 of their largest; from the fibre vectors' lengths (``|g| - 1``,
    the positions' path, and the displacement path before) they miss by more than 1e-4 (the
    strain's 6e-8 rounding)."""
    import jaxform.shell as S

    mesh = Mesh.rectangle(0.04, 0.03, 0.004)
    shell = Shell.build(mesh, WOVEN_38616)
    X = np.asarray(mesh.nodes)
    rng = np.random.default_rng(5)
    strain = 1e-4 * (1.0 + 0.5 * rng.normal(size=(2, 2)))
    u = np.zeros_like(X)
    u[:, :2] = X[:, :2] @ strain.T + np.array([0.05, -0.03])  # uniform stretch, carried 50 mm
    u[:, 2] = 2e-4 * np.sin(60.0 * X[:, 0])  # and a gentle wave out of plane
    w = (1.0, 0.0, 0.0)  # the tension alone

    def tension_forces(us, exact):
        e1, e2, D, base = S._kinematics(us, shell, True)
        if exact:
            return S._local_gradients(e1, e2, D, shell, w, base)[1][:2]
        b = jnp.asarray(base, us.dtype)  # the whole edges, as from positions
        return S._local_gradients(e1 + b[0], e2 + b[1], D, shell, w)[1][:2]

    u32 = jnp.asarray(u.T, jnp.float32)  # float64 gets the same (rounded) displacements: the arithmetic compared
    want = [np.asarray(g, np.float64) for g in tension_forces(u32.astype(jnp.float64), True)]
    scale = max(np.max(np.abs(g)) for g in want)
    for exact, bound in ((True, 1e-5), (False, None)):
        got = tension_forces(u32, exact)
        assert got[0].dtype == jnp.float32
        err = max(np.max(np.abs(np.asarray(g, np.float64) - h)) for g, h in zip(got, want)) / scale
        if exact:
            assert err < bound, err
        else:
            assert err > 1e-4, err  # the test would see the old strain's noise


def _stack_shell():
    """Two plies at 0 and 45 degrees, the top one membrane-only (a ply without bending beside one with)."""
    mesh = Mesh.rectangle(0.03, 0.02, 0.005, plies=2, ply_spacing=0.001)
    return Shell.build(mesh, (WOVEN_38616, NCF_FCIM359.replace(bending=None)))


@pytest.mark.parametrize("make", [
    lambda: Shell.build(_curved_sheared_mesh(), WOVEN_38616),
    lambda: Shell.build(_curved_sheared_mesh(), NCF_FCIM359),  # a law per bending sign; the stitch's knots
    lambda: Shell.build(_curved_sheared_mesh(), WOVEN_38616, shear_reading="conjugate"),
    _stack_shell,
], ids=["woven", "ncf", "conjugate", "stack"])
def test_closed_form_local_gradients_equal_autodiff(make):
    """The kernel's closed-form element gradients (membrane per triangle, bending per node) and
    energies equal ``jax.value_and_grad`` of the energy densities, weighted as the reverse mode
    weights them, at a state sheared by up to ~35 degrees (both signs) and bent both ways."""
    from jaxform import shell as S

    shell = make()
    X = jnp.asarray(shell.mesh.nodes)
    rng = np.random.default_rng(5)
    u = jnp.stack([0.7 * X[:, 1] * jnp.sign(X[:, 0] - 0.015), 0.0 * X[:, 1], 8.0 * (X[:, 0] - 0.015) ** 2], axis=1)
    xs = (X + u + 2e-4 * jnp.asarray(rng.normal(size=X.shape))).T
    e1, e2, D, _ = S._kinematics(xs, shell, False)
    w = (0.3, -0.7, 1.3)
    (_, parts_ad), g_ad = jax.value_and_grad(S._local_energy, argnums=(0, 1, 2), has_aux=True)(e1, e2, D, shell, w)
    parts, g = jax.jit(lambda a, b, c: S._local_gradients(a, b, c, shell, w))(e1, e2, D)
    gamma = shear_angle(fibre_vectors(xs.T, shell.mesh, shell.ref), shell.ref)
    assert float(jnp.min(gamma)) < -0.4 and float(jnp.max(gamma)) > 0.4
    for k in parts:
        np.testing.assert_allclose(float(parts[k]), float(parts_ad[k]), rtol=1e-12)
    for a, b in zip(g, g_ad):
        np.testing.assert_allclose(np.asarray(a), np.asarray(b), rtol=1e-9, atol=1e-11 * float(jnp.max(jnp.abs(b))))


def test_closed_form_gradients_keep_the_kinematics_dtype():
    """A float32 state with float64 law parameters and weights (x64, a float32 rig's reverse mode):
    the gradients come back in float32 and the energies promoted, as autodiff gives them."""
    from jaxform import shell as S

    shell = Shell.build(_curved_sheared_mesh(), NCF_FCIM359)
    xs = (jnp.asarray(shell.mesh.nodes) * 1.01).T.astype(jnp.float32)
    e1, e2, D, _ = S._kinematics(xs, shell, False)
    w = tuple(jnp.asarray(v, jnp.float64) for v in (0.3, -0.7, 1.3))
    (_, parts_ad), g_ad = jax.value_and_grad(S._local_energy, argnums=(0, 1, 2), has_aux=True)(e1, e2, D, shell, w)
    parts, g = S._local_gradients(e1, e2, D, shell, w)
    assert [a.dtype for a in g] == [b.dtype for b in g_ad] == [jnp.float32] * 3
    assert {k: parts[k].dtype for k in parts} == {k: parts_ad[k].dtype for k in parts}
    for a, b in zip(g, g_ad):
        np.testing.assert_allclose(np.asarray(a), np.asarray(b), rtol=2e-3, atol=2e-5 * float(jnp.max(jnp.abs(b))))


def test_horner_shear_energy_matches_the_law():
    g = jnp.linspace(-1.0, 1.0, 41)
    for law in (WOVEN_38616.shear, NCF_FCIM359.shear):
        np.testing.assert_allclose(_shear_energy(law, g, "a14"), law.integral2(g), rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(_shear_energy(law, g, "conjugate"), law.integral(g), rtol=1e-12, atol=1e-12)


def test_shear_angle_sign_and_value_ncf_stitch_stretch_positive():
    mesh = Mesh.rectangle(0.02, 0.02, 0.005)
    shell = Shell.build(mesh, NCF_FCIM359)
    X = jnp.asarray(mesh.nodes)
    # stretch along x (the stitch), contract along y, keeping the ±45° fibres' length: positive shear
    gam = 0.3
    th = 0.5 * (np.pi / 2 - gam)  # half angle between fibres
    F = jnp.diag(jnp.array([np.cos(th) / np.cos(np.pi / 4), np.sin(th) / np.sin(np.pi / 4), 1.0]))
    x = X @ F.T
    gamma = shear_angle(fibre_vectors(x, mesh, shell.ref), shell.ref)
    np.testing.assert_allclose(gamma, gam, rtol=1e-12)
    p = energy_parts(x, shell)
    assert float(p["tension"]) < 1e-20
    area = 0.02 * 0.02
    np.testing.assert_allclose(p["shear"], area * NCF_FCIM359.shear.integral2(gam), rtol=1e-10)


def test_curvature_sign_and_value_on_a_cylinder():
    mesh = Mesh.rectangle(0.05, 0.03, 0.0025)
    shell = Shell.build(mesh, WOVEN_38616)
    X = np.asarray(mesh.nodes)
    R = 0.2
    # drooping (bent down about the y axis, n = +z initially): positive curvature 1/R of the x fibre
    phi = X[:, 0] / R
    x = np.stack([R * np.sin(phi), X[:, 1], R * (np.cos(phi) - 1.0)], axis=1)
    k = np.asarray(fibre_curvatures(jnp.asarray(x), mesh, shell.ref))
    np.testing.assert_allclose(k[:, 0], 1.0 / R, rtol=2e-3)
    np.testing.assert_allclose(k[:, 1], 0.0, atol=1e-9)
    k_up = np.asarray(fibre_curvatures(jnp.asarray(x * np.array([1, 1, -1])), mesh, shell.ref))
    np.testing.assert_allclose(k_up[:, 0], -1.0 / R, rtol=2e-3)


def test_ncf_asymmetric_bending_energy_uses_pos_and_neg_sides():
    mesh = Mesh.rectangle(0.05, 0.03, 0.0025)
    shell = Shell.build(mesh, NCF_FCIM359)
    X = np.asarray(mesh.nodes)
    R = 0.5
    s = (X[:, 0] + X[:, 1]) / np.sqrt(2)  # along the +45° fibre
    for sign, law in ((1, NCF_FCIM359.bending[0].pos), (-1, NCF_FCIM359.bending[0].neg)):
        dz = sign * -(R - np.sqrt(R**2 - s**2))
        x = jnp.asarray(np.stack([X[:, 0], X[:, 1], dz], axis=1))
        k = fibre_curvatures(x, mesh, shell.ref)
        assert np.all(np.sign(np.asarray(k[:, 0])) == sign)


def test_membrane_only_has_no_bending_energy():
    from jaxform.materials import membrane_only

    fab = membrane_only(WOVEN_38616)
    mesh = Mesh.rectangle(0.03, 0.03, 0.005)
    shell = Shell.build(mesh, fab)
    X = np.asarray(mesh.nodes)
    x = jnp.asarray(X + np.stack([0 * X[:, 0], 0 * X[:, 0], 0.001 * np.sin(100 * X[:, 0])], 1))
    assert float(energy_parts(x, shell)["bending"]) == 0.0


def test_shear_resultant_readings():
    law = WOVEN_38616.shear
    g = jnp.linspace(-0.9, 0.9, 19)
    dW = jax.vmap(jax.grad(lambda a: _shear_energy(law, a, "a14")))(g)
    np.testing.assert_allclose(shear_resultant(law, g, "a14"), dW, rtol=1e-10, atol=1e-12)
    dWc = jax.vmap(jax.grad(lambda a: _shear_energy(law, a, "conjugate")))(g)
    np.testing.assert_allclose(shear_resultant(law, g, "conjugate"), dWc, rtol=1e-10, atol=1e-12)


# the woven case slow-marked: the NCF one runs the same kernel and custom reverse mode with more in
# it (a law per bending sign, fibres at +-45 degrees), and each compiles for ~45 s CPU
@pytest.mark.parametrize("fabric", [pytest.param(WOVEN_38616, marks=pytest.mark.slow), NCF_FCIM359])
def test_symmetric_hessian_reverse_mode_equals_plain_autodiff(fabric):
    """The integrator's forces take their reverse mode from the Hessian's symmetry (a forward
    derivative): cotangents w.r.t. positions and every fabric parameter equal plain autodiff."""
    from jaxform.shell import forces_and_energy_soa, forces_and_energy_sym

    mesh = _curved_sheared_mesh()
    shell = Shell.build(mesh, fabric)
    rng = np.random.default_rng(3)
    xs = jnp.asarray(mesh.nodes).T + 2e-4 * rng.normal(size=(3, mesh.n_nodes))
    r = jnp.asarray(rng.normal(size=xs.shape))
    c = {"tension": 0.3, "shear": -0.7, "bending": 1.3}

    def loss(f, x, fab):
        out, parts = f(x, shell.replace(fabrics=(fab,)))
        return jnp.sum(out * r) + sum(c[k] * parts[k] for k in c)

    args = (xs, shell.fabrics[0])
    # jitted: op-by-op (eager) reverse mode through the element kernel costs minutes of dispatch
    plain = jax.jit(jax.grad(lambda x, fb: loss(forces_and_energy_soa, x, fb), argnums=(0, 1)))(*args)
    x_ref = jnp.asarray(mesh.nodes).T  # the integrator's kernel takes displacements from the mesh
    sym = jax.jit(jax.grad(lambda x, fb: loss(lambda y, sh: forces_and_energy_sym(y - x_ref, sh), x, fb),
                           argnums=(0, 1)))(*args)
    for a, b in zip(jax.tree_util.tree_leaves(plain), jax.tree_util.tree_leaves(sym)):
        a, b = np.asarray(a), np.asarray(b)
        np.testing.assert_allclose(b, a, rtol=1e-10, atol=1e-12 * max(np.max(np.abs(a)), 1e-300))
