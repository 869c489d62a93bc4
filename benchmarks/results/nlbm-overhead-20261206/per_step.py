"""bench_forming_2mm's per-step comparison alone: python per_step.py SIZE_MM N ROUNDS OUT.json"""
import importlib.util, json, pathlib, sys
spec = importlib.util.spec_from_file_location("b2", pathlib.Path("benchmarks/bench_forming_2mm.py").resolve())
b2 = importlib.util.module_from_spec(spec); spec.loader.exec_module(b2)
size, n, rounds, out = float(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
json.dump(b2._per_step(size, n=n, rounds=rounds), open(out, "w"), indent=1, default=float)
