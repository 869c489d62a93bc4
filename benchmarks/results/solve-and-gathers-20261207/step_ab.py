"""ms/step of woven Case A NLBM (SIZE mm, env; default 2) from a saved state: SIZE=4 python step_ab.py save K, then SIZE=4 PYTHONPATH=CODE python step_ab.py time N (4 timings of N steps, and a node position)."""
import sys, time, pickle, jax, numpy as np
from jaxform import cases, integrate
from jaxform.forming import rig as rigmod
SIZE = __import__("os").environ.get("SIZE", "2")
m, s, info = rigmod.build(cases.with_element_size(cases.load("case-a-woven-nlbm"), float(SIZE) * 1e-3))
leaves, tree = jax.tree_util.tree_flatten(s)
if sys.argv[1] == "save":
    adv = jax.jit(integrate.advance, static_argnums=2, compiler_options=integrate.COMPILER_OPTIONS)
    s = adv(m, s, int(sys.argv[2])); s.x.block_until_ready()
    pickle.dump([np.asarray(l) for l in jax.tree_util.tree_leaves(s)], open(f"/tmp/state{SIZE}.pkl", "wb"))
    print("saved t", float(s.t)); sys.exit()
s = jax.tree_util.tree_unflatten(tree, [jax.numpy.asarray(l) for l in pickle.load(open(f"/tmp/state{SIZE}.pkl", "rb"))])
N = int(sys.argv[2])
f = jax.jit(lambda mm, ss: integrate.run_steps(mm, ss, N)[0], compiler_options=integrate.COMPILER_OPTIONS)
out = f(m, s); out.x.block_until_ready()
ts = []
for _ in range(4):
    t0 = time.perf_counter(); out = f(m, s); out.x.block_until_ready(); ts.append((time.perf_counter()-t0)/N*1e3)
print(" ".join(f"{t:.3f}" for t in ts), "ms/step; x[0] after", N, ":", np.asarray(out.x)[0].tolist(), flush=True)
