"""The explicit integrator: energy conservation, stable time step, failure reporting, frames."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from jaxform.integrate import SimulationError, advance, init_state, make_model, rollout, simulate
from jaxform.materials import WOVEN_38616
from jaxform.mesh import Mesh
from jaxform.shell import Shell, forces
from jaxform.spectrum import stable_time_step


def _plate():
    mesh = Mesh.rectangle(0.04, 0.03, 0.005)
    return mesh, Shell.build(mesh, WOVEN_38616)


def _kick(mesh):
    X = np.asarray(mesh.nodes)
    vz = 0.05 * np.sin(np.pi * X[:, 0] / 0.04) * np.cos(np.pi * X[:, 1] / 0.03)
    vx = 0.02 * np.sin(2 * np.pi * X[:, 1] / 0.03)
    return np.stack([vx, 0 * vx, vz], axis=1)


def test_undamped_free_vibration_conserves_energy_over_10000_steps():
    mesh, shell = _plate()
    model = make_model(shell, safety=0.8)
    state = init_state(model, v=_kick(mesh))
    s, fr = simulate(model, state, n_frames=100, every=100)
    e = fr.energies
    total = np.asarray(e.kinetic + e.internal)
    e_start = float(state.energies.kinetic + state.energies.internal)
    assert int(s.step) == 10_000
    assert np.all(np.asarray(fr.ok))
    # the energy really moves between kinetic and elastic (not a trivial run)
    assert float(np.max(np.asarray(e.internal))) > 0.2 * e_start
    assert np.max(np.abs(total - e_start)) <= 0.005 * e_start


def test_float32_time_is_the_step_count_times_the_step():
    """A float32 run's clock does not drift: ``t = steps x dt`` (a running sum ``t + dt`` was off by
    1.1e-4 of the time after 20,000 steps: a punch short of its stroke in a long run; its error
    grows with the step count, and after these 4,000 it is still two orders above the tolerance)."""
    mesh, shell = _plate()
    # a step whose float32 running sum drifts (each step's rounding is biased; for some steps it
    # is not), below the stable limit
    model = make_model(shell, dt=1.1e-6, dtype=jnp.float32)
    assert float(model.dt) < stable_time_step(shell, safety=0.8)
    s, fr = simulate(model, init_state(model, v=_kick(mesh)), n_frames=1, every=4_000)
    assert int(s.step) == 4_000 and s.t.dtype == jnp.float32
    assert float(s.t) == pytest.approx(4_000 * float(model.dt), rel=2e-7)
    # the running sum this guards against, for scale
    dt32, t = np.float32(model.dt), np.float32(0.0)
    for _ in range(4_000):
        t = np.float32(t + dt32)
    assert abs(float(t) / (4_000 * float(model.dt)) - 1.0) > 50 * 2e-7


def test_stable_time_step_is_below_the_largest_eigenfrequency_limit():
    mesh, shell = _plate()
    model = make_model(shell)
    x0 = jnp.asarray(mesh.nodes)
    m = np.repeat(np.asarray(model.mass), 3).reshape(-1, 3)

    @jax.jit
    def kv(u):  # stiffness times u at the flat state
        return -jax.jvp(lambda x: forces(x, shell), (x0,), (u,))[1]

    u = jnp.asarray(np.random.default_rng(0).normal(size=x0.shape))
    lam = 0.0
    for _ in range(300):
        w = kv(u) / m
        lam = float(jnp.linalg.norm(w) / jnp.linalg.norm(u))
        u = w / jnp.linalg.norm(w)
    dt_exact = 2.0 / np.sqrt(lam)
    dt_est = stable_time_step(shell, safety=1.0)
    assert dt_est <= dt_exact
    assert dt_est >= 0.3 * dt_exact  # not uselessly conservative


def test_too_large_time_step_warns_then_fails_with_step_time_and_frames():
    mesh, shell = _plate()
    limit = stable_time_step(shell, safety=1.0)
    with pytest.warns(RuntimeWarning, match="above the estimated stable limit"):
        model = make_model(shell, dt=3.0 * limit)
    state = init_state(model, v=_kick(mesh))
    with pytest.raises(SimulationError) as info:
        simulate(model, state, n_frames=50, every=20)
    err = info.value
    assert "step" in str(err) and "time step" in str(err)
    assert err.step > 0 and err.time == pytest.approx(err.step * 3.0 * limit)
    n_good = err.frames.x.shape[0]
    assert n_good < 50
    assert np.all(np.isfinite(np.asarray(err.frames.x)))
    assert n_good == int(err.step // 20)
    # the host driver's stretch (a while loop) stops at the failing step and returns the last good state
    end = jax.jit(advance, static_argnames=("blowup_tol",))(model, state, 1000, blowup_tol=0.5)
    assert int(end.bad_step) == err.step and int(end.step) == err.step + 1
    np.testing.assert_array_equal(np.asarray(end.x), np.asarray(state.x))
    assert int(jax.jit(advance)(make_model(shell), state, 37).step) == 37  # a healthy stretch: all n steps


def test_gravity_damping_and_fixed_nodes_settle_to_rest_with_balanced_energy():
    mesh = Mesh.rectangle(0.04, 0.01, 0.005)
    shell = Shell.build(mesh, WOVEN_38616)
    X = np.asarray(mesh.nodes)
    fixed = np.repeat((X[:, 0] < 1e-9)[:, None], 3, axis=1)
    model = make_model(shell, gravity=(0, 0, -9.81), damping=200.0, fixed=fixed, mass_scale=100.0)
    s, fr = simulate(model, n_frames=20, every=1000)
    e = fr.energies
    assert np.all(np.asarray(s.x)[fixed[:, 0]] == X[fixed[:, 0]])
    assert float(np.min(np.asarray(s.x)[:, 2])) < -1e-4  # sags
    resid = np.asarray(e.kinetic + e.internal - e.gravity_work - e.boundary_work + e.damping_work)
    assert np.max(np.abs(resid)) <= 0.01 * float(np.max(np.asarray(e.gravity_work)))
    assert float(e.kinetic[-1]) <= 1e-2 * float(e.gravity_work[-1])


def test_checkpointed_and_plain_rollouts_agree_and_differentiate():
    """20 steps as 4 checkpointed frames of 5 (two segments of 3, the first skipping a step) and as
    5 plain frames of 4: the same loss, frames and gradient. As 5 checkpointed frames of 4 (two
    segments of 2, none skipped) the same loss and frames (forward only: its reverse program, a
    scan's remat with no step skipped, cost about 20 s of the default run)."""
    mesh, shell = _plate()
    model = make_model(shell)

    def loss(scale, n_frames, every, ckpt):
        st = init_state(model, v=scale * _kick(mesh))
        s, fr = rollout(model, st, n_frames, every, checkpoint=ckpt)
        return jnp.sum(s.x[:, 2] ** 2), fr.extras

    # jitted: eagerly, every operation outside the scans (the initial state's forces) and each
    # scan's transpose compile on their own
    vg = jax.jit(jax.value_and_grad(loss, has_aux=True), static_argnums=(1, 2, 3))
    (l0, ex0), g0 = vg(1.0, 5, 4, False)
    assert g0 != 0.0
    (l1, ex1), g1 = vg(1.0, 4, 5, True)
    np.testing.assert_allclose(l1, l0, rtol=1e-12)
    np.testing.assert_allclose(g1, g0, rtol=1e-10)
    # frames of 5 steps: the last is step 20 too
    jax.tree_util.tree_map(lambda a, b: np.testing.assert_allclose(a[-1], b[-1], rtol=1e-12), ex1, ex0)
    l2, ex2 = jax.jit(loss, static_argnums=(1, 2, 3))(1.0, 5, 4, True)
    np.testing.assert_allclose(l2, l0, rtol=1e-12)
    jax.tree_util.tree_map(lambda a, b: np.testing.assert_allclose(a, b, rtol=1e-12), ex2, ex0)


def test_displacements_are_summed_with_compensation_so_float32_does_not_drift():
    """48,000 float32 increments of about 1e-6 m onto displacements of a few cm (a forming run's
    steps at 8 mm): the plain sum drifts by up to half an ulp a step (here 7.5e-6 to 1.2e-4 m, the
    order of the 0.036 mm draw-in bias measured against float64), the compensated sum the
    integrator uses stays within an ulp of the exact sum."""
    from jaxform.integrate import compensated_add

    @jax.jit
    def run(u0, inc):
        def body(carry, _):
            (u, lost), plain = carry
            return (compensated_add(u, inc, lost), plain + inc), None
        ((u, _), plain), _ = jax.lax.scan(body, ((u0, jnp.zeros_like(u0)), u0), None, length=48000)
        return u, plain

    u0 = jnp.asarray([0.02, -0.03, 0.045], jnp.float32)
    inc = jnp.asarray([1.05e-6, -7.3e-7, 1.3e-6], jnp.float32)
    u, plain = run(u0, inc)
    exact = np.asarray(u0, np.float64) + 48000 * np.asarray(inc, np.float64)
    ulp = np.spacing(np.abs(exact).astype(np.float32)).astype(np.float64)
    assert np.all(np.abs(np.asarray(u, np.float64) - exact) <= ulp)
    assert np.max(np.abs(np.asarray(plain, np.float64) - exact)) > 1000 * np.max(ulp)
