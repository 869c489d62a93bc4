"""The exact fibre strain's cost on the whole 2 mm step, in one process: woven Case A NLBM as shipped, from the
state step_ab.py saved (/tmp/state2.pkl), two programs of 400 steps: as shipped, and with the shell's kinematics
patched back to whole edges (the strain |g| - 1, the code before), alternating, six rounds (ms/step)."""
import pickle, time, jax, numpy as np
import jaxform.shell as S
from jaxform import cases, integrate
from jaxform.forming import rig as rigmod
m, s, info = rigmod.build(cases.with_element_size(cases.load("case-a-woven-nlbm"), 2e-3))
s = jax.tree_util.tree_unflatten(jax.tree_util.tree_flatten(s)[1], [jax.numpy.asarray(l) for l in pickle.load(open("/tmp/state2.pkl", "rb"))])
N = 400
exact_kin = S._kinematics


def whole_edges(xs, shell, displacement):
    e1, e2, D, base = exact_kin(xs, shell, displacement)
    if base is None:
        return e1, e2, D, None
    b = jax.numpy.asarray(base, xs.dtype)
    return e1 + b[0], e2 + b[1], D, None


progs = {}
for name, kin in (("exact strain", exact_kin), ("|g| - 1", whole_edges)):
    S._kinematics = kin
    f = jax.jit(lambda mm, ss: integrate.run_steps(mm, ss, N)[0], compiler_options=integrate.COMPILER_OPTIONS)
    out = f(m, s); out.x.block_until_ready()  # compiled with this kinematics
    progs[name] = f
    print(name, "x[0]", np.asarray(out.x)[0].tolist(), flush=True)
S._kinematics = exact_kin
for r in range(6):
    for name, f in progs.items():
        t0 = time.perf_counter(); f(m, s).x.block_until_ready()
        print(f"{name:12s} {(time.perf_counter() - t0) / N * 1e3:.3f} ms/step", flush=True)
