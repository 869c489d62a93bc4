"""Woven Case A on 2 mm elements (issue 4, done-when item 7): the full stroke.

``run(quick)`` returns:

* ``full_stroke_fibre_mass``: a real full-stroke run of woven Case A, NLBM, 2 mm elements, with
  fibre-selective mass (``FIBRE_MASS_2MM``): wall time (build, compilation, writing nothing) and
  the physics figures of :func:`bench_forming._figures`.
* ``per_step``: per-step time after compilation of NLBM, LBM (B_41.5) and membrane-only, at the
  preset numerics and with the fibre mass (``*_fibre_mass``), with the full-stroke time each
  implies (steps x per-step + build and compile; the unscaled full runs take about half an hour
  each on two cores); NLBM's overhead over LBM in both settings.

``quick``: the per-step figures of the fibre-mass run only (100 steps).
"""
from __future__ import annotations

import importlib.util
import pathlib

_spec = importlib.util.spec_from_file_location("bench_forming", pathlib.Path(__file__).with_name("bench_forming.py"))
_bf = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(_bf)


def run(quick: bool = False) -> dict:
    from jaxform import forming

    name = "case-a-woven-nlbm"
    fm = _bf._per_step(name, 2.0, *_bf.FIBRE_MASS_2MM)
    fm["overrides"] = list(_bf.FIBRE_MASS_2MM)
    if quick:
        return {"per_step": {"nlbm_fibre_mass": fm}}
    out = {}
    r = forming.simulate(_bf._case(name, 2.0, *_bf.FIBRE_MASS_2MM))
    out["full_stroke_fibre_mass"] = {**_bf._figures(r), "overrides": list(_bf.FIBRE_MASS_2MM)}
    _bf._log("full_stroke_fibre_mass", out["full_stroke_fibre_mass"])
    steps = {b: _bf._per_step(f"case-a-woven-{b}", 2.0) for b in ("nlbm", "lbm-41", "membrane")}
    steps["nlbm_fibre_mass"] = fm
    for b in ("lbm-41", "membrane"):
        steps[f"{b}_fibre_mass"] = _bf._per_step(f"case-a-woven-{b}", 2.0, *_bf.FIBRE_MASS_2MM)
    for k in ("", "_fibre_mass"):
        steps[f"nlbm_overhead_over_lbm{k}"] = steps[f"nlbm{k}"]["per_step_s"] / steps[f"lbm-41{k}"]["per_step_s"] - 1.0
    out["per_step"] = steps
    _bf._log("per_step", steps)
    return out


if __name__ == "__main__":
    import json

    print(json.dumps(run(quick=False), indent=2, default=float))
