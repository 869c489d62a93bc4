"""Old vs new study: per run (complete, wall, KE/IE, shear, draw-in, wrinkles, cuts) and per claim."""
import json, sys, pathlib
old = json.load(open(sys.argv[1] + "/runs.json"))
new_root = pathlib.Path(sys.argv[2])
new = {}
for d in sorted((new_root / "runs").iterdir()):
    f = d / "summary.json"
    if f.exists():
        s = json.loads(f.read_text()); n = s.get("numerics")
        if n is None:
            continue
        new[d.name] = dict(complete=s["complete"], wall_time_s=s["wall_time_s"], max_ke_ie=s["max_ke_ie"],
                           max_shear_angle_deg=s["max_shear_angle_deg"], flange_wrinkles=s["flange_wrinkles"],
                           draw_in=s["draw_in"], step_cuts=n.get("step_cuts"), contact_stiffness_factor=n.get("contact_stiffness_factor"),
                           max_penetration_ply=n.get("max_penetration_ply"), pf=s["history"]["punch_force_N"][-1],
                           max_flange_deviation_m=s["max_flange_deviation_m"])
print("| run | complete old/new | wall s old/new | max KE/IE old/new | max shear deg old/new | edge draw-in mm old/new | corner mm old/new | flange wrinkles old/new | punch force end N new | stiffened |")
print("|---|---|---|---|---|---|---|---|---|---|")
for k in sorted(set(old) | set(new)):
    o, n = old.get(k, {}), new.get(k, {})
    f = lambda d, key, s=1, fmt="{:.2f}": (fmt.format(d[key] * s) if d.get(key) is not None else "-")
    di = lambda d, key: (f"{1e3 * d['draw_in'][key]:.2f}" if d.get("draw_in") else "-")
    print(f"| {k} | {o.get('complete')}/{n.get('complete')} | {f(o,'wall_time_s',fmt='{:.0f}')}/{f(n,'wall_time_s',fmt='{:.0f}')} | "
          f"{f(o,'max_ke_ie',fmt='{:.4f}')}/{f(n,'max_ke_ie',fmt='{:.4f}')} | {f(o,'max_shear_angle_deg')}/{f(n,'max_shear_angle_deg')} | "
          f"{di(o,'edge_mid_m')}/{di(n,'edge_mid_m')} | {di(o,'corner_m')}/{di(n,'corner_m')} | {o.get('flange_wrinkles')}/{n.get('flange_wrinkles')} | "
          f"{f(n,'pf',fmt='{:.1f}')} | {n.get('contact_stiffness_factor')} |")
if len(sys.argv) > 3:
    co = json.load(open(sys.argv[1] + "/claims.json"))["claims"] if "claims" in json.load(open(sys.argv[1] + "/claims.json")) else None
