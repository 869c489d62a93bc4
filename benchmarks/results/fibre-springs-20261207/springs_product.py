"""ms a product with K_t at 2 mm: the triangles form (jaxform.fibre_mass at e0681a9) against springs gathered per node and springs as shifted arrays (the form shipped), and their differences. Run: python springs_product.py"""
import time, numpy as np, jax, jax.numpy as jnp
from jaxform import cases, fibre_mass as F
from jaxform.forming import rig as rigmod
case = cases.with_element_size(cases.load("case-a-woven-nlbm"), 2e-3)
r = rigmod.build(case); shell = r.model.shell; fm = F.fibre_mass(shell, 12.0, springs=False)  # the triangles' form
tris = np.asarray(shell.mesh.tris); coef = np.asarray(shell.ref.tri_coef, np.float64)
w = np.asarray(fm.weight, np.float64)
N = shell.mesh.nodes.shape[0]
springs = {}
ok = True
for f in range(2):
    c = np.stack([-(coef[:, f, 0] + coef[:, f, 1]), coef[:, f, 0], coef[:, f, 1]], 1)
    big = np.abs(c) > 1e-9 * np.abs(c).max(1, keepdims=True)
    print("family", f, "nonzero counts", np.bincount(big.sum(1)))
    for t in range(len(tris)):
        k = np.flatnonzero(big[t])
        if len(k) != 2: ok = False; continue
        i, j = tris[t, k[0]], tris[t, k[1]]
        key = (min(i, j), max(i, j))
        springs[key] = springs.get(key, 0.0) + w[f, t] * c[t, k[0]] ** 2
print("ok", ok, "springs", len(springs), "tris", len(tris), "nodes", N)
keys = sorted(springs); ends = np.array(keys).T.astype(np.int32); ws = np.array([springs[k] for k in keys])
S = ends.shape[1]
# node table: index into concat([+f (S), -f (S), 0])
ids = np.concatenate([ends[1], ends[0]])  # +f goes to end j (index s), -f to end i (index S+s)
order = np.argsort(ids, kind="stable"); counts = np.bincount(ids, minlength=N); start = np.concatenate([[0], np.cumsum(counts)[:-1]])
table = np.full((counts.max(), N), 2 * S, np.int32)
for k in range(table.shape[0]):
    has = counts > k; table[k, has] = order[start[has] + k]
print("table", table.shape)
ends_j, ws_j, table_j = jnp.asarray(ends), jnp.asarray(ws, jnp.float32), jnp.asarray(table)
def units_s(xs):
    d = xs[:, ends_j[1]] - xs[:, ends_j[0]]
    return d / jnp.sqrt(jnp.sum(d * d, 0))
def k_s(ps, d):
    dv = ps[:, ends_j[1]] - ps[:, ends_j[0]]
    q = (ws_j * (d[0] * dv[0] + d[1] * dv[1] + d[2] * dv[2])) * d
    v = jnp.concatenate([q, -q, jnp.zeros((3, 1), q.dtype)], 1)
    return sum(v[:, table_j[k]] for k in range(table_j.shape[0]))
xs = jnp.asarray(shell.mesh.nodes, jnp.float32).T
rng = np.random.default_rng(0)
xs = xs + 1e-4 * jnp.asarray(rng.normal(size=xs.shape), jnp.float32)
p = jnp.asarray(rng.normal(size=xs.shape), jnp.float32)
ut = F.fibre_units(xs, fm, shell); us = units_s(xs)
a = F.stiffness_times(p, ut, fm, shell); b = k_s(p, us)
print("rel diff", float(jnp.max(jnp.abs(a - b)) / jnp.max(jnp.abs(a))))
def loop(fn, u, n=13):
    return jax.jit(lambda p: jax.lax.fori_loop(0, n, lambda k, q: q + 1e-3 * fn(q, u), p))
for name, fn, u in [("tri", lambda q, u: F.stiffness_times(q, u, fm, shell), ut), ("spring", k_s, us)] * 2:
    g = loop(fn, u); g(p).block_until_ready()
    t0 = time.perf_counter()
    for _ in range(50): g(p).block_until_ready()
    print(name, "ms per product", 1e3 * (time.perf_counter() - t0) / 50 / 13)
# stencil form
strides = sorted(set((ends[1] - ends[0]).tolist()))
print("strides", strides)
W = {}
for dl in strides:
    m = (ends[1] - ends[0]) == dl
    arr = np.zeros(N - dl); arr[ends[0][m]] = ws[m]; W[dl] = jnp.asarray(arr, jnp.float32)
def units_st(xs):
    out = []
    for dl in strides:
        d = xs[:, dl:] - xs[:, :-dl]
        out.append(d / jnp.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]))
    return out
def k_st(ps, us):
    res = 0.0
    for dl, d in zip(strides, us):
        dv = ps[:, dl:] - ps[:, :-dl]
        q = (W[dl] * (d[0] * dv[0] + d[1] * dv[1] + d[2] * dv[2])) * d
        z = jnp.zeros((3, dl), q.dtype)
        res = res + jnp.concatenate([z, q], 1) - jnp.concatenate([q, z], 1)
    return res
ust = units_st(xs)
c = k_st(p, ust)
print("rel diff stencil", float(jnp.max(jnp.abs(a - c)) / jnp.max(jnp.abs(a))))
for name, fn, u in [("stencil", k_st, ust), ("tri", lambda q, u: F.stiffness_times(q, u, fm, shell), ut)] * 2:
    g = loop(fn, u); g(p).block_until_ready()
    t0 = time.perf_counter()
    for _ in range(50): g(p).block_until_ready()
    print(name, "ms per product", 1e3 * (time.perf_counter() - t0) / 50 / 13)
