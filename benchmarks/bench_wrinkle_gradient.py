"""Benchmark: is the gradient through a whole forming run informative? (issue 16, done-when 1)

``run(quick)``: woven Case A at 8 mm in float64 (``numerics.dtype = float64``,
``fibre_mass_scaling = auto``), the round trip's data (:mod:`bench_wrinkle_fit`: hidden law, two
sections, 0.05 mm noise) and the fit's section loss
(:func:`jaxform.calibrate.wrinkle_fit.section_loss`) at the starting law ``q0`` (the woven preset,
log space ``(log B_init, log B_inf/B_init, log kappa0)``). Reported: the AD gradient at ``q0``
(checkpointed reverse mode through the run) and its wall time; for each parameter the loss along
the line ``q0 + t e_i`` for ``t`` in ``STEPS`` (the landscape's roughness) and the central
differences ``(L(t) - L(-t)) / 2t`` it gives at every ``t``, with the relative error of AD
against each; the fit's check uses ``t = FD_STEP = 0.05``. ``quick``: 16 mm, ``t = 0.05`` only.
"""
from __future__ import annotations

import dataclasses
import importlib.util
import pathlib
import time

import numpy as np

_spec = importlib.util.spec_from_file_location("bench_wrinkle_fit", pathlib.Path(__file__).with_name("bench_wrinkle_fit.py"))
_bw = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(_bw)

STEPS = (0.01, 0.02, 0.05, 0.1, 0.2)


def run(quick: bool = False) -> dict:
    import jax

    jax.config.update("jax_enable_x64", True)  # the case runs in float64
    from jaxform import cases
    from jaxform.calibrate import wrinkle_fit

    h = 16e-3 if quick else 8e-3
    steps = (0.05,) if quick else STEPS
    case = cases.resolve("case-a-woven-nlbm", element_size=h, overrides=_bw.OVERRIDES + ("numerics.dtype=float64",))
    truth_case = dataclasses.replace(case, fabric=dataclasses.replace(case.fabric, voce=_bw.TRUTH))
    sections, _ = _bw.make_sections(truth_case, _bw.FIT_LINES, np.random.default_rng(16))
    q0 = _q0(case)
    t0 = time.perf_counter()
    (l0,), g = wrinkle_fit.section_loss(case, sections, [q0], gradient_at=[0])
    t_ad = time.perf_counter() - t0
    g_ad = g[0]
    scan, t1 = {}, time.perf_counter()
    for i, name in enumerate(wrinkle_fit.NAMES[:3]):
        ts = sorted({s * t for t in steps for s in (-1.0, 1.0)})
        losses, _ = wrinkle_fit.section_loss(case, sections, [q0 + t * np.eye(3)[i] for t in ts])
        L = dict(zip(ts, losses.tolist()))
        fd = {t: (L[t] - L[-t]) / (2 * t) for t in steps}
        scan[name] = {"t": [-t for t in steps[::-1]] + [0.0] + list(steps),
                      "loss": [L[-t] for t in steps[::-1]] + [float(l0)] + [L[t] for t in steps],
                      "ad": float(g_ad[i]), "fd": fd,
                      "rel_err_ad_vs_fd": {t: abs(g_ad[i] - v) / max(abs(v), 1e-300) for t, v in fd.items()}}
    return {"element_size_mm": 1e3 * h, "dtype": "float64", "q0": q0.tolist(), "loss_q0": float(l0),
            "ad_gradient": g_ad.tolist(), "ad_wall_s_incl_compile_and_forward": t_ad,
            "scan_wall_s": time.perf_counter() - t1, "scan": scan}


def _q0(case):
    """The starting law's ``q`` as the fit takes it (the rig's bending law)."""
    from jaxform import forming
    from jaxform.calibrate import transforms

    model, _, _ = forming.build(case)
    return transforms.q_from_law(transforms.voce_start(model.shell.fabrics[0].bending[0]), "voce")
