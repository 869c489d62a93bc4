import json, sys, time, platform
sys.path.insert(0, "benchmarks")
import bench_contact
out = {"started_utc": time.strftime("%Y%m%dT%H%M%SZ", time.gmtime()), "machine": platform.processor() or platform.machine(),
       "note": "2-core machine, nothing else running"}
for name, size in (("case-a-woven-nlbm", 8.0), ("case-a-woven-nlbm", 4.0), ("case-b-woven-nlbm", 8.0)):
    out[f"friction_{name}_{size:g}mm"] = bench_contact.friction_cost(name, size)
    print(name, size, out[f"friction_{name}_{size:g}mm"], flush=True)
json.dump(out, open(sys.argv[1], "w"), indent=1)
