"""Normal contact integrated backward (jaxform.backward_normal): stable at any stiffness, the
explicit penalty's static penetration, a contraction with shared nodes, momentum kept."""
import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from jaxform import backward_normal, contact, tools


H = 0.3e-3
RHO_A = 0.21
AREA = 1e-6
M = RHO_A * AREA


def _plane_load(k, c=0.0, **kw):
    params = contact.ContactParams(stiffness=k, friction=0.0, slip_velocity=1e-3, damping=c)
    return contact.ToolLoad(tool=tools.Plane(point=[0.0, 0.0, 0.0]), params=params, offset=H / 2,
                            area=jnp.full(1, AREA), active=jnp.ones(1), implicit_normal=True, **kw)


def _run(load, z0, v0, f_ext, dt, n):
    """A node of mass M on the plane, the integrator's order: trial momentum, the backward hook."""
    def body(s, _):
        x, p = s
        f, _, ex = load.force(x, p / M, 0.0, None)
        pt = p + dt * (f + f_ext)
        fb, _, _ = load.backward(ex["backward_support"], pt, jnp.full(1, M), dt, dt, ex, None)
        p = pt + dt * fb
        x = x + dt * p / M
        return (x, p), x[0, 2]

    return jax.lax.scan(body, (jnp.array([[0.0, 0.0, z0]]), jnp.array([[0.0, 0.0, M * v0]])), None, length=n)[1]


def test_a_node_on_a_tool_is_stable_far_beyond_the_explicit_limit_and_rests_at_the_penalty_penetration():
    """k dt^2 / rho_A = 100 (the explicit penalty is stable below 4): the node settles, damped at
    the rate the backward step predicts (modulus 1 / sqrt(1 + beta) a step, derived by hand from
    the two-step map), onto the explicit penalty's static penetration ``p / k``."""
    dt, beta = 1e-5, 100.0
    k = beta * RHO_A / dt**2
    p = 2.0e4  # Pa pressing the node down
    z = np.asarray(_run(_plane_load(k), H / 2, -0.05, jnp.array([[0.0, 0.0, -p * AREA]]), dt, 200))
    z_eq = H / 2 - p / k
    assert np.all(np.isfinite(z)) and z[-1] == pytest.approx(z_eq, rel=1e-9)
    # the ringing about the rest: the deviations follow e_{n+1} (1 + beta) = 2 e_n - e_{n-1} (the spring
    # at x_{n+1}; roots of modulus 1 / sqrt(1 + beta)), derived by hand, not from the code
    e = z - z_eq
    for i in (1, 2, 3):
        assert e[i + 1] == pytest.approx((2 * e[i] - e[i - 1]) / (1 + beta), rel=1e-4)
    # the explicit penalty at the same step: the node leaves at once (|omega dt| > 2)
    explicit = contact.ToolLoad(tool=tools.Plane(point=[0.0, 0.0, 0.0]), params=_plane_load(k).params, offset=H / 2,
                                area=jnp.full(1, AREA), active=jnp.ones(1), implicit_friction=False)

    def body(s, _):
        x, p_ = s
        f, _, _ = explicit.force(x, p_ / M, 0.0, None)
        p_ = p_ + dt * (f + jnp.array([[0.0, 0.0, -p * AREA]]))
        return (x + dt * p_ / M, p_), x[0, 2]

    ze = np.asarray(jax.lax.scan(body, (jnp.array([[0.0, 0.0, H / 2]]), jnp.array([[0.0, 0.0, -0.05 * M]])), None,
                                 length=200)[1])
    assert not np.all(np.abs(ze - z_eq) < 1e-3)


def test_at_a_small_step_the_backward_contact_is_the_explicit_penalty():
    """beta = 1e-4: a node dropped on the tool bounces as on the explicit penalty's spring (half its
    period in contact, within 1 %), and leaves with the speed the backward step's damping predicts
    (1.6 % slower)."""
    dt, beta = 1e-7, 1e-4
    k = beta * RHO_A / dt**2
    zb = np.asarray(_run(_plane_load(k), H / 2 + 1e-7, -0.1, jnp.zeros((1, 3)), dt, 4000))
    t_contact = np.count_nonzero(zb < H / 2) * dt
    assert t_contact == pytest.approx(math.pi * math.sqrt(RHO_A / k), rel=0.01)  # half a period of the spring
    v_out = (zb[-1] - zb[-2]) / dt  # the backward step's energy loss: (1 + beta)^-1 a step in contact
    assert v_out == pytest.approx(0.1 * (1 + beta) ** (-0.5 * round(t_contact / dt)), rel=2e-3)


def test_rows_sharing_nodes_never_add_kinetic_energy():
    """Jacobi rows with split masses: random node-to-face rows on a few shared nodes, infinitely
    stiff at zero gap (a velocity projection): the kinetic energy never grows (with each row using
    its nodes' whole masses it grows in some draws: the rows together overshoot), and momentum is kept."""
    rng = np.random.default_rng(0)
    n, r = 12, 40
    mass = rng.uniform(0.5, 2.0, n) * 1e-7
    grew = 0
    for trial in range(20):
        slave = rng.integers(0, n, r)
        masters = np.stack([rng.choice(np.delete(np.arange(n), s), 3, replace=False) for s in slave])
        w = rng.dirichlet(np.ones(3), r)
        nodes = np.concatenate([slave[:, None], masters], axis=1)
        weights = np.concatenate([np.ones((r, 1)), -w], axis=1)
        normal = rng.normal(size=(r, 3))
        normal /= np.linalg.norm(normal, axis=1, keepdims=True)
        p = rng.normal(size=(n, 3)) * mass[:, None]
        F, force = backward_normal.row_forces(jnp.asarray(p), jnp.asarray(mass), 1e-6, 1e-6, jnp.asarray(nodes),
                                              jnp.asarray(weights), jnp.asarray(normal), jnp.zeros(r),
                                              jnp.full(r, 1e-6), 1e15, 0.0)
        p2 = p + 1e-6 * np.asarray(force)
        ke = lambda q: 0.5 * np.sum(q * q / mass[:, None])  # noqa: E731
        assert ke(p2) <= ke(p) * (1 + 1e-12), trial
        # the same rows each with its nodes' whole masses (numpy, by hand): they overshoot
        u = np.einsum("rk,rkc,rc->r", weights, p[nodes] / mass[nodes][:, :, None], normal)
        lam = np.where(u < 0, -u / np.sum(weights**2 / mass[nodes], axis=1), 0.0)  # k -> infinity
        p_lone = p.copy()
        np.add.at(p_lone, nodes.reshape(-1), ((lam[:, None] * weights)[:, :, None] * normal[:, None, :]).reshape(-1, 3))
        grew += ke(p_lone) > ke(p)
        assert np.all(np.asarray(F) >= 0)
        np.testing.assert_allclose(np.sum(np.asarray(force), axis=0), 0.0, atol=1e-12 * np.abs(force).max())
    assert grew > 0  # 2 of the 20 draws


def test_a_lone_row_at_infinite_stiffness_stops_the_closing_velocity():
    """One node against one triangle, zero gap, k -> infinity: the end-of-step normal velocity is 0
    (the row's mass ``1 / (1/m_s + sum w_j^2 / m_j)``: nodes used by this row only)."""
    mass = np.array([1.0, 2.0, 3.0, 4.0]) * 1e-7
    w = np.array([0.2, 0.3, 0.5])
    p = np.array([[0.0, 0.0, -1.0], [0.0, 0.0, 0.5], [0.1, 0.0, 0.2], [0.0, 0.3, 0.0]]) * mass[:, None]
    F, force = backward_normal.row_forces(jnp.asarray(p), jnp.asarray(mass), 1e-6, 1e-6, jnp.array([[0, 1, 2, 3]]),
                                          jnp.asarray([np.concatenate([[1.0], -w])]), jnp.array([[0.0, 0.0, 1.0]]),
                                          jnp.zeros(1), jnp.ones(1), 1e20, 0.0)
    v2 = (p + 1e-6 * np.asarray(force)) / mass[:, None]
    assert v2[0, 2] - w @ v2[1:, 2] == pytest.approx(0.0, abs=1e-9)


def test_force_controlled_holder_with_an_implicit_normal_carries_the_clamping_force():
    """The holder moves in the backward hook with the reaction of the step: pressing 1000 N on
    nodes held in place it comes to rest where the contact carries it."""
    n = 100
    area = np.full(n, 5.4e-2 / n)
    xs = jnp.asarray(np.column_stack([np.linspace(0.06, 0.12, n), np.zeros(n), np.full(n, H / 2)]))
    dt = 1e-6
    k = 2.0e12  # k dt^2 / rho_A = 9.5: beyond the explicit penalty's stability limit (4)
    params = contact.ContactParams(stiffness=k, friction=0.23, slip_velocity=1e-3)
    load = contact.ToolLoad(tool=tools.BlankHolder(0.053, bottom_z=H), params=params, offset=H / 2, area=area,
                            active=np.ones(n), clamp_force=1000.0, mass=5.0,
                            damping=2 * math.sqrt(k * 5.4e-2 * 5.0), dt=dt, force_controlled=True, implicit_normal=True)
    mass = jnp.full(n, RHO_A * 5.4e-4)

    @jax.jit
    def run(state):
        def body(s, _):
            f, s1, ex = load.force(xs, jnp.zeros((n, 3)), 0.0, s)
            fb, ex, s2 = load.backward(ex["backward_support"], jnp.zeros((n, 3)), mass, dt, dt, ex, s1)
            return s2, (ex["reaction"][2], jnp.sum(fb[:, 2]))
        return jax.lax.scan(body, state, None, length=20000)

    _, (rz, fz) = run(contact.HolderState())
    np.testing.assert_allclose(rz[-1], 1000.0, rtol=1e-3)
    np.testing.assert_allclose(fz[-1], -1000.0, rtol=1e-3)


def test_where_two_rows_press_a_node_from_both_sides_the_penetration_grows_with_k_dt2():
    """The limit the rig refuses a clamped stack for (jaxform.forming.numerics): a node on a floor
    row, pressed down by a second row from a wall a force ``f`` pushes (a damped mass), both rows
    solved together, settles with each row's penetration ``(1 + 2 beta) f / (A k)`` (``beta = k
    dt^2 / rho_A``; each row holds half the node's mass, and neither sees the other's force in its
    trial), not the penalty's ``f / (A k)``: for ``beta >> 1`` the contact holds no stiffer than
    about ``rho_A / (2 dt^2)``. The forces themselves are right: ``f`` on each row."""
    dt, f, mw = 1e-5, 1e-3, 1000 * M
    normals = jnp.array([[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]])

    def settle(k):
        def body(s, _):
            z, v, wall, vw = s
            F, force = backward_normal.row_forces(jnp.array([[0.0, 0.0, M * v]]), jnp.array([M]), dt, dt,
                                                  jnp.zeros((2, 1), int), jnp.ones((2, 1)), normals,
                                                  jnp.stack([z, wall - z - H]), jnp.full(2, AREA), k, 0.0,
                                                  jnp.array([[0.0, 0.0, 0.0], [0.0, 0.0, 1.0]]) * vw)
            v = v + dt * force[0, 2] / M
            vw = vw + dt * (F[1] - f - 2 * jnp.sqrt(k * AREA * mw) * vw) / mw  # the wall, critically damped
            return (z + dt * v, v, wall + dt * vw, vw), F

        s, F = jax.lax.scan(body, (0.0, 0.0, H, 0.0), None, length=20000)
        return s[0], F[-1]

    for beta in (0.1, 1.0, 10.0):
        k = beta * RHO_A / dt**2
        z, F = jax.jit(settle)(k)
        assert np.asarray(F) == pytest.approx([f, f], rel=1e-4)
        assert -float(z) * AREA * k / f == pytest.approx(1 + 2 * beta, rel=1e-3)


def test_one_node_a_row_without_the_index_tables_gives_the_rows_forces():
    """``row_forces(nodes=None, weights=None)`` (a tool's contact: row r is node r, weight 1) is the
    general rows' arithmetic without gathers and scatter-adds: the same forces (float64, random
    momenta, gaps on both sides of contact, rows off by area, a moving tool)."""
    rng = np.random.default_rng(3)
    n = 400
    p = jnp.asarray(rng.normal(scale=1e-6, size=(n, 3)))
    mass = jnp.asarray(rng.uniform(0.5, 2.0, n) * M)
    normal = rng.normal(size=(n, 3))
    normal = jnp.asarray(normal / np.linalg.norm(normal, axis=1, keepdims=True))
    gap = jnp.asarray(rng.normal(scale=2e-5, size=n))
    area = jnp.asarray(AREA * rng.uniform(0.5, 1.0, n) * (rng.uniform(size=n) > 0.2))
    vel = jnp.broadcast_to(jnp.asarray([0.0, 0.0, -0.0625]), (n, 3))
    args = (1e-5, 1e-5)
    f_rows, F_rows = backward_normal.row_forces(p, mass, *args, jnp.arange(n)[:, None], jnp.ones((n, 1)), normal, gap, area,
                                                3e8, 20.0, vel)
    f_node, F_node = backward_normal.row_forces(p, mass, *args, None, None, normal, gap, area, 3e8, 20.0, vel)
    assert 0.2 * n < int(jnp.sum(f_rows > 0)) < 0.8 * n  # both sides of contact present
    np.testing.assert_allclose(f_node, f_rows, rtol=1e-12, atol=1e-18)
    np.testing.assert_allclose(F_node, F_rows, rtol=1e-12, atol=1e-18)
