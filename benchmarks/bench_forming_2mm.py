"""Woven Case A on 2 mm elements as shipped (issue 13, done-when 2): the full stroke and the cost
of a step by bending law.

``run(quick)`` returns:

* ``full_stroke``: ``forming.simulate`` of ``case-a-woven-nlbm`` at 2 mm as shipped (automatic
  numerics, the automatic punch speed): wall time (build, compilation, writing nothing) and the
  physics figures of :func:`bench_forming._figures`. About 30-45 min on two cores.
* ``per_step_2mm`` / ``per_step_4mm``: ms per step of NLBM, LBM (B_init, B_41.5) and
  membrane-only as shipped, the rigs taking turns (:func:`bench_forming._per_step`), with the
  full-stroke time each implies, and NLBM's overhead over each LBM (the issue's target: <= 10 %).

``quick``: the per-step figures at 4 mm only, short windows.
"""
from __future__ import annotations

import importlib.util
import pathlib

_spec = importlib.util.spec_from_file_location("bench_forming", pathlib.Path(__file__).with_name("bench_forming.py"))
_bf = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(_bf)

LAWS = ("nlbm", "lbm-init", "lbm-41", "membrane")


def _per_step(size_mm: float, n: int, rounds: int) -> dict:
    steps = _bf._per_step([f"case-a-woven-{b}" for b in LAWS], size_mm, n=n, rounds=rounds)
    nlbm = steps["case-a-woven-nlbm"]["per_step_s"]
    for b in ("lbm-init", "lbm-41"):
        steps[f"nlbm_overhead_over_{b}"] = nlbm / steps[f"case-a-woven-{b}"]["per_step_s"] - 1.0
    return _bf._log(f"per_step_{size_mm:g}mm", steps)


def run(quick: bool = False) -> dict:
    from jaxform import forming

    if quick:
        return {"per_step_4mm": _per_step(4.0, n=50, rounds=2)}
    out = {"per_step_4mm": _per_step(4.0, n=500, rounds=6), "per_step_2mm": _per_step(2.0, n=100, rounds=6)}
    r = forming.simulate(_bf._case("case-a-woven-nlbm", 2.0))
    out["full_stroke"] = _bf._log("full_stroke", _bf._figures(r))
    return out


if __name__ == "__main__":
    import json

    print(json.dumps(run(quick=False), indent=2, default=float))
