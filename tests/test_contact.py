"""Contact kernel: penalty equilibrium, regularised friction, ply-ply contact, holder dynamics."""
import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from jaxform import contact, friction, penalty, tools

H = 0.3e-3  # ply thickness, m
RHO_A = 0.21  # kg/m²


_tool_contact = jax.jit(contact.tool_contact)
_ply_contact = jax.jit(contact.ply_contact)


def _params(**kw):
    base = dict(stiffness=4.0e10, friction=0.23, slip_velocity=1e-3)
    base.update(kw)
    return contact.ContactParams(**base)


def test_penalty_equilibrium_returns_the_applied_pressure():
    """Nodes on a flat plate pushed by a known pressure: at the penalty equilibrium the contact
    pressure is that pressure and the reaction on the plate is the total load."""
    plate = tools.Plane(point=[0.0, 0.0, 0.0])
    params = _params()
    area = np.array([1e-6, 4e-6, 2.5e-6])
    p_applied = 1.234e4
    # Equilibrium: k * delta = p  ->  node z = h/2 - p/k.
    z = H / 2 - p_applied / params.stiffness
    x = np.column_stack([np.zeros(3), np.arange(3) * 1e-3, np.full(3, z)])
    res = _tool_contact(plate, x, np.zeros((3, 3)), H / 2, area, params, dz=0.0, tool_velocity=np.zeros(3))
    np.testing.assert_allclose(res.pressure, p_applied, rtol=1e-10)
    np.testing.assert_allclose(res.force[:, 2], p_applied * area, rtol=1e-10)
    np.testing.assert_allclose(res.reaction, [0, 0, -p_applied * area.sum()], rtol=1e-10)
    np.testing.assert_allclose(res.gap, -p_applied / params.stiffness, rtol=1e-10)
    # Out of contact: nothing.
    res = _tool_contact(plate, x + [0, 0, 1e-3], np.zeros((3, 3)), H / 2, area, params, dz=0.0,
                               tool_velocity=np.zeros(3))
    assert float(jnp.abs(res.force).max()) == 0.0


@pytest.mark.parametrize("width", [0.0, 2e-5])
def test_normal_force_is_minus_gradient_of_penalty_energy(width):
    punch = tools.Punch(0.05)
    params = _params(friction=0.0, smooth_width=width)
    rng = np.random.default_rng(0)
    # Nodes just inside the punch surface (penetrations 0..40 micrometre) and some outside.
    dirs = rng.normal(size=(30, 3))
    dirs[:, 2] = -np.abs(dirs[:, 2])
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    x = np.array([0, 0, 0.05]) + dirs * (0.05 + H / 2 + rng.uniform(-4e-5, 2e-5, (30, 1)))
    area = 1e-6

    def energy(xx):
        return contact.tool_contact(punch, xx, jnp.zeros_like(xx), H / 2, area, params, dz=0.0,
                                    tool_velocity=jnp.zeros(3)).energy

    res = _tool_contact(punch, x, np.zeros_like(x), H / 2, area, params, dz=0.0, tool_velocity=np.zeros(3))
    np.testing.assert_allclose(res.force, -jax.grad(energy)(jnp.asarray(x)), rtol=1e-8, atol=1e-12)


def test_smooth_penetration_is_c1_and_matches_plain_beyond_width():
    w = 1e-5
    g = jnp.linspace(-5e-5, 1e-5, 61)
    d_s, _ = contact.penetration(g, w)
    d_p, _ = contact.penetration(g, 0.0)
    deep = g <= -w
    np.testing.assert_allclose(np.asarray(d_s)[deep], np.asarray(d_p - w / 2)[deep], rtol=1e-12, atol=1e-20)
    slope = jax.vmap(jax.grad(lambda gg: contact.penetration(gg, w)[0]))
    np.testing.assert_allclose(slope(jnp.array([-w - 1e-12, -w + 1e-12])), [-1.0, -1.0], atol=1e-6)
    np.testing.assert_allclose(slope(jnp.array([0.0, 1e-6])), [0.0, 0.0], atol=1e-12)


def test_friction_saturates_at_mu_n_and_is_smooth_at_zero_slip():
    mu, eps, fn = 0.23, 1e-3, 2.0
    f = lambda vt: friction.regularised_friction(vt, fn, mu, eps)
    big = f(jnp.array([1.0, 0.0, 0.0]))
    np.testing.assert_allclose(big, [-mu * fn * 1.0 / math.sqrt(1 + eps**2), 0, 0], rtol=1e-12)
    assert abs(float(big[0]) + mu * fn) < 1e-6 * mu * fn  # Coulomb within 1e-6 at 1000 eps
    speeds = jnp.logspace(-8, 1, 50)
    mags = jax.vmap(lambda s: safe(f(jnp.array([s, 0.0, 0.0]))))(speeds)
    assert np.all(np.asarray(mags) <= mu * fn) and np.all(np.diff(np.asarray(mags)) > 0)
    # Continuous through zero slip, finite derivative there: -mu F_n / eps.
    np.testing.assert_allclose(f(jnp.zeros(3)), 0.0)
    jac = jax.jacfwd(f)(jnp.zeros(3))
    np.testing.assert_allclose(jac, -mu * fn / eps * np.eye(3), rtol=1e-12)
    # Through the whole kernel: finite gradient w.r.t. node velocity and position at zero slip.
    plate = tools.Plane(point=[0.0, 0.0, 0.0])
    params = _params()
    x = jnp.array([[0.0, 0.0, H / 2 - 1e-6]])

    def ft(xx, vv):
        r = contact.tool_contact(plate, xx, vv, H / 2, 1e-6, params, dz=0.0, tool_velocity=jnp.zeros(3))
        return r.force[0, 0]

    gx, gv = jax.grad(ft, argnums=(0, 1))(x, jnp.zeros((1, 3)))
    assert np.all(np.isfinite(gx)) and np.all(np.isfinite(gv))
    np.testing.assert_allclose(gv[0, 0], -params.friction * params.stiffness * 1e-6 * 1e-6 / params.slip_velocity)


def safe(v):
    return jnp.sqrt(jnp.sum(v * v))


def test_friction_opposes_slip_relative_to_moving_tool_and_dissipates():
    plate = tools.Plane(point=[0.0, 0.0, 0.0])
    params = _params(friction=0.3)
    x = np.array([[0.0, 0.0, H / 2 - 1e-6]])
    v = np.array([[0.2, 0.0, 0.0]])
    res = _tool_contact(plate, x, v, H / 2, 1e-6, params, dz=0.0, tool_velocity=np.array([0.5, 0.0, 0.0]))
    fn = float(res.force[0, 2])
    np.testing.assert_allclose(fn, params.stiffness * 1e-6 * 1e-6, rtol=1e-12)
    assert float(res.force[0, 0]) > 0  # node slower than the tool: dragged along +x
    np.testing.assert_allclose(float(res.force[0, 0]), 0.3 * fn, rtol=1e-5)
    assert float(res.friction_power) > 0
    np.testing.assert_allclose(res.reaction, -res.force[0])


def test_node_on_tilted_plate_starts_sliding_at_the_friction_angle():
    """One contact node of a ply under gravity on a plate tilted by theta: below atan(mu) it only
    creeps at the regularisation speed; 1 degree above it accelerates."""
    mu, eps, g = 0.36, 1e-4, 9.81
    area, dt = 1e-6, 1e-5
    m = RHO_A * area
    k = penalty.auto_penalty_stiffness(RHO_A, dt)
    params = contact.ContactParams(stiffness=k, friction=mu, slip_velocity=eps,
                                   damping=2 * 0.5 * math.sqrt(k * RHO_A))

    def final_speed(theta):
        n = jnp.array([0.0, math.sin(theta), math.cos(theta)])
        plate = tools.Plane(point=[0.0, 0.0, 0.0], normal=n)
        x0 = (H / 2 - RHO_A * g / k) * n

        def step(carry, _):
            x, v = carry
            r = contact.tool_contact(plate, x[None], v[None], H / 2, area, params, dz=0.0, tool_velocity=jnp.zeros(3))
            a = r.force[0] / m + jnp.array([0.0, 0.0, -g])
            v = v + dt * a
            return (x + dt * v, v), None

        (x, v), _ = jax.lax.scan(step, (jnp.asarray(x0), jnp.zeros(3)), None, length=4000)
        return float(jnp.linalg.norm(v))

    crit = math.atan(mu)
    below, above = final_speed(crit - math.radians(1.0)), final_speed(crit + math.radians(1.0))
    r = math.tan(crit - math.radians(1.0)) / mu
    assert below < 1.5 * eps * r / math.sqrt(1 - r * r)  # creep only
    # Above: accelerating at about g (sin - mu cos) after 0.04 s.
    a_ref = g * (math.sin(crit + math.radians(1.0)) - mu * math.cos(crit + math.radians(1.0)))
    assert above > 0.5 * a_ref * 0.04 and above > 20 * eps


def test_auto_penalty_stiffness_is_stable_and_stiff():
    dt = 1e-6
    k = penalty.auto_penalty_stiffness(RHO_A, dt)
    np.testing.assert_allclose(k, 0.1 * RHO_A / dt**2)
    np.testing.assert_allclose(math.sqrt(k / RHO_A) * dt, math.sqrt(0.1))
    # Penetration under 18.5 kPa (1000 N on the holder ring) is far below h.
    assert 1.85e4 / k < 1e-2 * H
    # A node bouncing on the contact spring with leapfrog stays bounded at this k, blows up at 50x.
    def peak(stiff, steps=2000):
        z, v = -1e-7, 0.0
        for _ in range(steps):
            v += dt * (-stiff * z) / RHO_A
            z += dt * v
        return abs(z)
    with np.errstate(over="ignore", invalid="ignore"):
        assert peak(k) < 2e-7 and not peak(50 * k) < 1e-3
    p = penalty.contact_params(RHO_A, dt, H, friction=0.23)
    assert float(p.stiffness) == pytest.approx(k) and float(p.damping) > 0
    assert float(penalty.contact_params(RHO_A, dt, H, stiffness=1e12).stiffness) == 1e12
    with pytest.raises(ValueError, match="penetration"):
        penalty.contact_params(RHO_A, 1e-3, H)
    with pytest.raises(ValueError, match="dt"):
        penalty.auto_penalty_stiffness(RHO_A, 0.0)


def test_holder_step_under_constant_force():
    mass, force, dt = 2.0, 1000.0, 1e-4
    s = contact.HolderState()
    n = 100
    for _ in range(n):
        s = contact.holder_step(s, 0.0, mass=mass, force=force, dt=dt)
    a = -force / mass
    np.testing.assert_allclose(s.vz, a * dt * n, rtol=1e-12)
    np.testing.assert_allclose(s.dz, a * dt**2 * n * (n + 1) / 2, rtol=1e-12)
    # Resting on a linear "fabric" spring: settles where the reaction balances the force.
    K = 1e7
    s = contact.HolderState()
    step = jax.jit(lambda st: contact.holder_step(st, -K * st.dz, mass=mass, force=force, dt=dt,
                                                   damping=2 * math.sqrt(K * mass)))
    for _ in range(3000):
        s = step(s)
    np.testing.assert_allclose(s.dz, -force / K, rtol=1e-6)


def _flat_ply(nx, ny, spacing, z, offset=(0.0, 0.0)):
    xs, ys = np.meshgrid(np.arange(nx) * spacing + offset[0], np.arange(ny) * spacing + offset[1], indexing="ij")
    nodes = np.column_stack([xs.ravel(), ys.ravel(), np.full(nx * ny, z)])
    idx = np.arange(nx * ny).reshape(nx, ny)
    quads = np.column_stack([idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()])
    return nodes, quads


def test_ply_ply_contact_pressure_friction_and_momentum():
    h, s = H, 2e-3
    lower, quads = _flat_ply(5, 5, s, 0.0)
    delta = 2e-6
    upper, _ = _flat_ply(3, 3, s, h - delta, offset=(s * 0.7, s * 0.6))  # shifted: not node-matched
    x = np.vstack([lower, upper])
    slave = np.arange(25, 34)
    tri = contact.quads_to_triangles(quads)
    cand = jax.jit(contact.nearest_faces, static_argnames=("k",))(x, slave, tri, k=8)
    v = np.zeros_like(x)
    v[slave, 0] = 0.05  # upper ply sliding along +x
    params = _params(friction=0.36)
    res = _ply_contact(x, v, slave, tri, cand, h, s * s, params)
    fn = params.stiffness * delta * s * s
    np.testing.assert_allclose(res.pressure, params.stiffness * delta, rtol=1e-9)
    np.testing.assert_allclose(res.force[slave, 2], fn, rtol=1e-9)
    np.testing.assert_allclose(res.force[slave, 0], -0.36 * fn * 0.05 / math.hypot(0.05, 1e-3), rtol=1e-9)
    np.testing.assert_allclose(res.force.sum(axis=0), 0.0, atol=1e-12 * fn)  # internal forces
    # Lower ply receives the opposite load.
    np.testing.assert_allclose(res.force[:25, 2].sum(), -9 * fn, rtol=1e-9)
    # A slave node beyond the edge of the master ply does not touch it.
    x_far = x.copy()
    x_far[25, :2] = [-0.02, -0.02]
    res = _ply_contact(x_far, v, slave, tri, cand, h, s * s, params)
    assert float(res.pressure[0]) == 0.0
    # Finite gradients.
    gx = jax.jit(jax.grad(lambda xx: contact.ply_contact(xx, v, slave, tri, cand, h, s * s, params).energy))(jnp.asarray(x))
    assert np.all(np.isfinite(gx))


def test_tool_load_hook_force_controlled_holder_settles_on_the_fabric():
    """The integrator hook: a force-controlled holder pressing 1000 N on nodes held in place
    comes to rest where the contact reaction carries the clamping force."""
    n = 100
    area = np.full(n, 5.4e-2 / n)  # the holder ring of the 250 mm blank
    xs = np.column_stack([np.linspace(0.06, 0.12, n), np.zeros(n), np.full(n, H / 2)])
    dt = 1e-6
    params = penalty.contact_params(RHO_A, dt, H, friction=0.23)
    holder = tools.BlankHolder(0.053, bottom_z=H)
    load = contact.ToolLoad(tool=holder, params=params, offset=H / 2, area=area, active=np.ones(n),
                            clamp_force=1000.0, mass=5.0, damping=2 * math.sqrt(float(params.stiffness) * 5.4e-2 * 5.0),
                            dt=dt, force_controlled=True)

    @jax.jit
    def run(state):
        def body(s, _):
            f, s2, ex = load.force(jnp.asarray(xs), jnp.zeros((n, 3)), 0.0, s)
            return s2, ex["reaction"][2]
        return jax.lax.scan(body, state, None, length=3000)

    state, rz = run(contact.HolderState())
    np.testing.assert_allclose(rz[-1], 1000.0, rtol=1e-3)
    f, _, ex = load.force(jnp.asarray(xs), jnp.zeros((n, 3)), 0.0, state)
    np.testing.assert_allclose(jnp.sum(f[:, 2]), -1000.0, rtol=1e-3)
    np.testing.assert_allclose(ex["max_pressure"], 1000.0 / 5.4e-2, rtol=1e-3)
    # Prescribed tools: the load follows the motion and has no state.
    punch = tools.Punch(0.05, apex_z=H, motion=tools.VerticalMotion(-0.5))
    pl = contact.ToolLoad(tool=punch, params=params, offset=H / 2, area=1e-6, active=np.ones(1))
    f, s, ex = pl.force(jnp.array([[0.0, 0.0, H / 2]]), jnp.zeros((1, 3)), 1e-4, None)
    assert s is None and float(f[0, 2]) < 0 and float(ex["dz"]) == pytest.approx(-5e-5)


def test_ply_load_refreshes_candidates():
    lower, quads = _flat_ply(4, 4, 2e-3, 0.0)
    upper, _ = _flat_ply(2, 2, 2e-3, H - 1e-6, offset=(1e-3, 1e-3))
    x = jnp.asarray(np.vstack([lower, upper]))
    slave = np.arange(16, 20)
    load = contact.PlyLoad(slave=slave, triangles=contact.quads_to_triangles(quads), gap0=H, area=4e-6,
                           params=_params(friction=0.36), k=4, refresh_every=2)
    st = load.initial_state(x)
    f, st, ex = jax.jit(load.force)(x, jnp.zeros_like(x), 0.0, st)
    np.testing.assert_allclose(f[slave, 2], 4e10 * 1e-6 * 4e-6, rtol=1e-9)
    assert int(st[1]) == 1


def test_stick_under_high_pressure_is_stable_with_the_stick_limit():
    """Explicit stick: the regularised friction is a damper ``mu p A / eps_v`` on the node. With
    ``mu p dt / (eps_v rho_A) = 5`` (a clamped holder, 1% regularisation, 8 mm mesh) the plain law
    makes the slip velocity flip sign every step and grow; the stick limit of
    :func:`penalty.contact_params` keeps it decaying without a sign change."""
    dt, p, mu, area = 2.0e-6, 1.5e4, 0.23, 6.4e-5
    eps = mu * p * dt / (5.0 * RHO_A)
    base = penalty.contact_params(RHO_A, dt, H, friction=mu, slip_velocity=eps)
    assert float(base.stick_limit) == pytest.approx(dt / RHO_A)
    plain = contact.ContactParams(stiffness=base.stiffness, friction=mu, slip_velocity=eps)
    depth = p / float(base.stiffness)
    m = RHO_A * area
    node = jax.jit(contact.node_contact)
    out = {}
    for name, params in (("plain", plain), ("limited", base)):
        v = jnp.array([1e-3, 0.0, 0.0])
        vs = []
        for _ in range(30):
            f = node(jnp.asarray(-depth + H / 2), jnp.array([0.0, 0.0, 1.0]), v, H / 2, area, params)[0]
            v = v + dt * jnp.array([f[0], f[1], 0.0]) / m
            vs.append(float(v[0]))
        out[name] = np.array(vs)
    lim = np.abs(out["limited"])
    assert np.all(lim[1:] <= lim[:-1]) and lim[-1] < 1e-12  # decays at once (ratio 1), no chatter
    flips = np.sum(np.sign(out["plain"][1:]) != np.sign(out["plain"][:-1]))
    assert flips >= 20 and abs(out["plain"][-1]) > 1e-5  # the test sees chatter where it exists
    # two-sided (ply on ply) contact: twice the limit (two nodes share the slip)
    assert float(penalty.contact_params(RHO_A, dt, H, two_sided=True).stick_limit) == pytest.approx(2 * dt / RHO_A)


def test_backward_friction_solves_the_regularised_law_at_the_end_of_step_slip():
    """:func:`friction.backward_friction` against an independent root finder (scipy's brentq on
    ``m (u* - u) / h = mu F_n u / sqrt(u**2 + eps**2)``), against Coulomb's return mapping as
    ``eps -> 0``, and its gradient against central differences (float64)."""
    from scipy.optimize import brentq

    m, h, mu, fn, eps = 2e-5, 1e-5, 0.23, 1e-2, 1e-4
    a = h * mu * fn / m  # the slip speed friction can remove in one step: 1.15e-3 m/s
    speeds = a * np.array([0.0, 0.01, 0.5, 0.9, 0.999, 1.0, 1.001, 1.1, 3.0, 100.0])
    n = len(speeds)
    tool_v = np.array([0.02, 0.0, 0.0])  # a moving tool: the slip is relative to it
    direction = np.array([0.6, 0.8, 0.0])
    p = m * (tool_v + speeds[:, None] * direction + np.array([0.0, 0.0, 0.3]))  # a normal part too
    f_normal = np.tile([0.0, 0.0, fn], (n, 1))
    f, pw = jax.jit(friction.backward_friction)(p, np.full(n, m), h, f_normal, mu, eps, tool_v)
    f, pw = np.asarray(f), np.asarray(pw)
    for us, fi, pi in zip(speeds, f, pw):
        u = brentq(lambda u: u + a * u / math.hypot(u, eps) - us, 0.0, us) if us > 0 else 0.0
        mag = mu * fn * u / math.hypot(u, eps)
        np.testing.assert_allclose(fi, -mag * direction, rtol=1e-6, atol=1e-9 * mu * fn)
        assert pi == pytest.approx(mag * u, rel=1e-5, abs=1e-12)
        assert np.linalg.norm(fi) <= mu * fn * (1 + 1e-12)  # never beyond Coulomb
        assert u <= us  # never reverses the slip
    # eps << a: Coulomb's return mapping (stick below a, mu F_n beyond)
    f0, _ = friction.backward_friction(p, np.full(n, m), h, f_normal, mu, 1e-5 * a, tool_v)
    coulomb = -np.minimum(speeds / a, 1.0)[:, None] * mu * fn * direction
    np.testing.assert_allclose(np.asarray(f0), coulomb, atol=1e-3 * mu * fn)
    # d force / d momentum, AD against central differences, in stick and in slip
    fx = lambda q: friction.backward_friction(q, np.full(n, m), h, f_normal, mu, eps, tool_v)[0][:, 0]  # noqa: E731
    g = np.asarray(jax.jacfwd(fx)(jnp.asarray(p)))[np.arange(n), np.arange(n), 0]
    d = 1e-6 * m * eps
    dp = np.zeros_like(p)
    dp[:, 0] = d
    fd = (np.asarray(fx(p + dp)) - np.asarray(fx(p - dp))) / (2 * d)
    np.testing.assert_allclose(g[1:], fd[1:], rtol=1e-5)


def test_backward_friction_in_float32_is_converged_over_both_regimes_within_a_few_newton_steps():
    """float32 :func:`friction.backward_friction` over ``a / eps_v = 1e-3 .. 1e5`` and ``u* / a =
    1e-3 .. 1e3`` (stick, the transition, slip) against the root in float64 (bisection): the force
    within 1e-6 of ``mu F_n`` and of itself; and the start (``_slip_from_below``) is a lower bound
    from which 4 float32 Newton steps already give that (the loop stops on its own, not at its cap:
    the same result with the cap at 4)."""
    a_over_eps, s_over_a = np.meshgrid(np.logspace(-3, 5, 81), np.r_[np.logspace(-3, 3, 61), np.linspace(0.9, 1.1, 41)])
    m, h, mu, fn, eps = 2e-5, 1e-5, 0.23, 1e-2, 1e-4
    a = h * mu * fn / m
    eps = a / a_over_eps.ravel()  # one eps_v a node here: a call per eps, vectorised by vmap
    us = (a * s_over_a).ravel()
    n = us.size
    lo, hi = np.zeros(n), us.copy()
    for _ in range(200):  # the root in float64
        mid = 0.5 * (lo + hi)
        neg = mid + a * mid / np.hypot(mid, eps) - us < 0
        lo, hi = np.where(neg, mid, lo), np.where(neg, hi, mid)
    u = 0.5 * (lo + hi)
    ref = mu * fn * u / np.hypot(u, eps)
    p = np.zeros((n, 3), np.float32)
    p[:, 0] = m * us
    f_normal = np.tile(np.float32([0.0, 0.0, fn]), (n, 1))
    one = jax.jit(jax.vmap(lambda pi, ei: friction.backward_friction(pi[None], jnp.full(1, m, jnp.float32), h,
                                                                     f_normal[:1], mu, ei, jnp.zeros(3, jnp.float32))[0][0, 0]))
    pj, ej = jnp.asarray(p), jnp.asarray(eps, jnp.float32)
    got = -np.asarray(one(pj, ej), np.float64)
    assert got.dtype == np.float64 and np.asarray(one(pj, ej)).dtype == np.float32
    np.testing.assert_allclose(got, ref, rtol=1e-6, atol=1e-6 * mu * fn)
    start = np.asarray(friction._slip_from_below(jnp.asarray(us, jnp.float32), jnp.float32(a), ej), np.float64)
    assert np.all(start <= u * (1 + 1e-6) + 1e-30)
    cap = friction.FRICTION_ITERATIONS
    try:
        friction.FRICTION_ITERATIONS = 4
        capped = -np.asarray(jax.jit(jax.vmap(lambda pi, ei: friction.backward_friction(
            pi[None], jnp.full(1, m, jnp.float32), h, f_normal[:1], mu, ei, jnp.zeros(3, jnp.float32))[0][0, 0]))(pj, ej),
            np.float64)
    finally:
        friction.FRICTION_ITERATIONS = cap
    np.testing.assert_allclose(capped, ref, rtol=1e-6, atol=1e-6 * mu * fn)


def test_backward_pair_friction_conserves_momentum_stops_a_stuck_pair_and_slides_at_coulomb():
    """Ply on ply, integrated backward (:func:`friction.backward_pair_friction`): the pair forces sum
    to zero; a sliding pair feels ``mu F_n`` against its relative slip; a node resting on a node
    (weights (1, 0, 0), equal masses) stops its slip within the step, and one at a triangle's
    centre keeps a third of it (the Jacobi mass counts each master node fully): no reversal."""
    m, h, mu, fn, eps = 2e-5, 1e-5, 0.36, 1e-2, 1e-6
    a = h * mu * fn / m  # slip speed one step of Coulomb friction removes from one node: 1.8e-3 m/s
    x = np.zeros((4, 3))
    slave, masters = np.array([3]), np.array([[0, 1, 2]])
    f_normal = np.array([[0.0, 0.0, fn]])
    mass = np.full(4, m)
    pair = jax.jit(friction.backward_pair_friction)

    def after(v, w):
        p = m * np.asarray(v, float)
        f, pw = pair(p, mass, h, slave, masters, w, f_normal, mu, eps)
        forces = np.asarray(contact.pair_forces(jnp.asarray(x), slave, masters, w, f))
        np.testing.assert_allclose(forces.sum(axis=0), 0.0, atol=1e-15)  # momentum conserved
        v_new = (p + h * forces) / m
        return np.asarray(f)[0], v_new[3] - np.asarray(w)[0] @ v_new[:3]

    centre = np.full((1, 3), 1.0 / 3.0)
    # sliding: 10x the speed one step can remove; Coulomb's force against the relative slip
    v = np.zeros((4, 3))
    v[:3, 0] = 0.01
    v[3, 0] = 0.01 + 10 * a
    f, _ = after(v, centre)
    np.testing.assert_allclose(f, [-mu * fn, 0.0, 0.0], rtol=1e-6)
    # a stuck node on a node: the slip stops in the step (down to the regularised creep)
    v[3, 0] = 0.01 + 0.3 * a
    _, rel = after(v, np.array([[1.0, 0.0, 0.0]]))
    assert abs(rel[0]) < 1e-3 * 0.3 * a
    # at the triangle's centre: a third of the slip is left, with its sign
    _, rel = after(v, centre)
    assert rel[0] == pytest.approx(0.3 * a / 3.0, rel=1e-3)
