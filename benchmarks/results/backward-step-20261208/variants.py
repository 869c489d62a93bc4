import jax, jax.numpy as jnp
from jaxform import broadphase
PATCHES = {}
def checkonly(state, x, search, half, every=0):
    due = broadphase.moved_beyond(x, state.x_ref, half)
    return state._replace(step=state.step + 1, refreshes=state.refreshes + due.astype(jnp.int32))
PATCHES["checkonly"] = [(broadphase, "refreshed", checkonly)]
def trivial(state, x, search, half, every=0):
    due = broadphase.moved_beyond(x, state.x_ref, half)
    new = jax.lax.cond(due, lambda: state._replace(x_ref=x, refreshes=state.refreshes + 1), lambda: state)
    return new._replace(step=state.step + 1)
PATCHES["trivial"] = [(broadphase, "refreshed", trivial)]
def xrefonly(state, x, search, half, every=0):
    # the cond carries x_ref and the counter only; the candidates pass around it
    due = broadphase.moved_beyond(x, state.x_ref, half)
    xr, n = jax.lax.cond(due, lambda: (x, state.refreshes + 1), lambda: (state.x_ref, state.refreshes))
    return state._replace(x_ref=xr, refreshes=n, step=state.step + 1)
PATCHES["xrefonly"] = [(broadphase, "refreshed", xrefonly)]
import jaxform.contact as C
import jaxform.friction as F
def nofric(p, mass, h, fn, mu, eps, vel):
    return jnp.zeros_like(p), jnp.zeros(p.shape[0], p.dtype)
PATCHES["nofric"] = [(C, "backward_friction", nofric)]
def unrolled(n):
    def bf(p, mass, h, f_normal, mu, eps_v, velocity):
        ps, fs = jnp.asarray(p).T, jnp.asarray(f_normal, p.dtype).T
        fn = F.safe_norm(fs, axis=0)
        nn = F.safe_normalize(fs, axis=0)
        m = jnp.asarray(mass, p.dtype)
        q = ps - m * jnp.asarray(velocity, p.dtype)[:, None]
        qt = q - jnp.sum(q * nn, axis=0) * nn
        u_star = F.safe_norm(qt, axis=0) / m
        a = h * mu * fn / m
        eps = jnp.asarray(eps_v, p.dtype)
        u = F._slip_from_below(u_star, a, eps)
        for _ in range(n):
            r = jnp.sqrt(u * u + eps * eps)
            g = u + a * u / r - u_star
            u = jnp.clip(u - g / (1.0 + a * eps * eps / (r * r * r)), 0.0, u_star)
        mag = mu * fn * u / jnp.sqrt(u * u + eps * eps)
        force = -mag * F.safe_normalize(qt, fallback=jnp.zeros(3, p.dtype), axis=0)
        return force.T, mag * u
    return bf
PATCHES["unroll4"] = [(C, "backward_friction", unrolled(4))]
PATCHES["unroll12"] = [(C, "backward_friction", unrolled(12))]
