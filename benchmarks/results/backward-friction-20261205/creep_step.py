"""Draw-in of the test rig (Case B 25 mm, 3 mm of stroke, 62.5 mm/s, 4x contact) at the full and half step."""
import sys
sys.path.insert(0, "tests")
from test_forming import _coarse
from jaxform import forming
keys = {"process.stroke_mm": 3, "process.frames": 3, "contact.expected_pressure_Pa": 1e3, "process.speed_mm_per_s": 62.5}
rig = forming.build(_coarse("case-b-woven-nlbm", **keys, **{"contact.safety": 0.02}))
k0 = float(rig.model.loads[0].params.stiffness)
case = _coarse("case-b-woven-nlbm", **keys, **{"contact.penalty_stiffness_Pa_per_m": 4 * k0})
out = {}
for label, dt in (("full", rig.info.dt), ("half", rig.info.dt / 2), ("quarter", rig.info.dt / 4)):
    r = forming.run(forming.build(case, dt=dt), catch=True)
    out[label] = r.summary["draw_in"]["edge_mid_m"]
    print(label, dt, r.complete, f"draw-in {out[label]*1e6:.2f} um", f"holder {r.history['holder_force_N'][-1]:.1f} N", flush=True)
print(f"full/half {out['full']/out['half']-1:+.3%}  half/quarter {out['half']/out['quarter']-1:+.3%}")
