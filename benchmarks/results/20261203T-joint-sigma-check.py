"""The joint fit's Laplace sds, checked: start at the law the joint benchmark fitted
(20261203T040249Z-vm.json), one evaluation, then the final Jacobian and the sigma check."""
import dataclasses, importlib.util, json, pathlib, sys, time
import numpy as np
HERE = pathlib.Path("/work/main/benchmarks")
sys.path.insert(0, str(HERE))
spec = importlib.util.spec_from_file_location("bwj", HERE / "bench_wrinkle_joint.py"); bwj = importlib.util.module_from_spec(spec); spec.loader.exec_module(bwj)
_bw = bwj._bw
import jax
jax.config.update("jax_enable_x64", True)
from jaxform import cases
from jaxform.calibrate import Profile, wrinkle_fit
old = json.load(open(HERE / "results/20261203T040249Z-vm.json"))["benchmarks"]["wrinkle_joint"]
print({k: old[k] for k in ("element_size_mm",)}, flush=True)
f = old["fit"]
fitted = (f["b_inf_Nm"], f["m0_N"], f["kappa0_per_m"])
over = tuple(_bw.OVERRIDES) + ("process.speed_mm_per_s=500",)
case = cases.resolve("case-a-woven-nlbm", element_size=8e-3, overrides=over)
truth_case = dataclasses.replace(case, fabric=dataclasses.replace(case.fabric, voce=_bw.TRUTH))
rng = np.random.default_rng(16)
sections, _ = _bw.make_sections(truth_case, _bw.FIT_LINES, rng)
x, z, _ = bwj._profile(rng)
start = dataclasses.replace(case, fabric=dataclasses.replace(case.fabric, voce=fitted))
t0 = time.perf_counter()
fit = wrinkle_fit.fit_wrinkles(start, sections, profiles=[Profile(x, z, bwj.OVERHANG)], areal_mass=bwj.MASS,
                               profile_noise=_bw.NOISE, n_starts=1, max_iter=1, gradient_check=False,
                               callback=lambda p: print(p.stage, p.forming_runs, round(p.loss, 1), flush=True))
d = fit.as_dict()
out = {"wall_s": time.perf_counter() - t0, "truth": _bw.TRUTH, "old_fit": {k: f[k] for k in f if k.startswith(("b_", "m0", "kappa0", "sigma"))},
       "new": {k: d[k] for k in d if k.startswith(("b_", "m0", "kappa0", "sigma", "determined", "converged", "reason", "loss", "forming"))}}
print(json.dumps(out, indent=1))
json.dump(out, open(pathlib.Path(__file__).with_suffix(".json"), "w"), indent=1)
