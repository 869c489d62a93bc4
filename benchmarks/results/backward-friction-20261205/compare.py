"""Compare two run summaries: draw-in, punch force, friction power, holder, wall time, KE/IE."""
import json, sys
import numpy as np
def load(d):
    return json.load(open(f"{d}/summary.json"))
rows = []
for d in sys.argv[1:]:
    s = load(d); h = s["history"]
    pf = np.asarray(h["punch_force_N"]); fp = np.asarray(h["friction_power_W"])
    print(d)
    print(f"  complete {s['complete']} wall {s['wall_time_s']:.0f} s  max KE/IE {s['max_ke_ie']:.4f}  steps {s['numerics']['steps_done']}")
    print(f"  draw-in edge mid {1e3*s['draw_in']['edge_mid_m']:.2f} mm  corner {1e3*s['draw_in']['corner_m']:.2f} mm  each {[round(1e3*x,2) for x in s['draw_in']['edge_mid_each_m']]}")
    print(f"  punch force at 25/50/75/100%: {[round(float(x),2) for x in pf[[len(pf)//4, len(pf)//2, 3*len(pf)//4, -1]]]} N")
    print(f"  tool friction power at 25/50/75/100%: {[round(float(x),3) for x in fp[[len(fp)//4, len(fp)//2, 3*len(fp)//4, -1]]]} W")
    print(f"  max shear {s['max_shear_angle_deg']:.2f} deg  max flange dev {1e3*s['max_flange_deviation_m']:.2f} mm  wrinkles {s['flange_wrinkles']}  holder_dz end {np.asarray(h['holder_dz_m'])[-1]*1e3:.4f} mm  max pen {np.max(h['max_penetration_m'])*1e3:.4f} mm")
