"""Sweep benchmark (issue 17, done-when items 1 and 2): batched runs against separate runs.

``run(quick)`` returns named figures, every configuration in a fresh process (JAX's device count
is fixed when it starts), one after the other on this machine:

* ``throughput``: member-steps per second of woven Case A NLBM at 8 mm over a short stroke, for
  batches of 1, 2, 4, 8 members (friction values) on one CPU device and on one device per core,
  and the single-run driver (``forming.run``) as the reference measured in the same run. Steady
  state: from the first stretch after compilation to the last.
* ``sweep_vs_separate``: a 4-member sweep (``jaxform sweep``, holder gap) at 8 mm, full stroke,
  against the same four as separate ``jaxform run`` invocations: wall times (compilation
  included, as a user meets them) and their ratio; each member's max shear angle and draw-in
  against its separate run (float32 noise: within 0.3° and 1%).

``quick``: the throughput of batches of 1 and 2 only.
"""
from __future__ import annotations

import json
import os
import pathlib
import subprocess
import sys
import tempfile
import time

CASE = "case-a-woven-nlbm"
SIZE_MM = 8.0
SHORT = ["process.stroke_mm=12", "process.frames=3"]
FRICTION = [0.15, 0.2, 0.25, 0.3, 0.35, 0.4, 0.45, 0.5]
GAPS_MM = ["0.35", "0.45", "0.55", "0.65"]  # above the ply (0.3 mm)


def _worker(members: int, devices: int, single: bool) -> dict:
    import jax

    jax.config.update("jax_num_cpu_devices", devices)
    from jaxform import cases, forming
    from jaxform.forming.batch import simulate_batch

    case = cases.resolve(CASE, element_size=SIZE_MM * 1e-3, overrides=SHORT)
    marks = []

    def progress(*a):
        marks.append((a[-5], time.perf_counter()))  # (step, time) per stretch

    t0 = time.perf_counter()
    if single:
        res = [forming.run(forming.build(case), on_progress=lambda *a: progress(*a))]
    else:
        res = simulate_batch(case, [[f"fabric.friction_tool={FRICTION[i % len(FRICTION)]}"] for i in range(members)],
                             on_progress=lambda part, *a: progress(*a))
    wall = time.perf_counter() - t0
    marks = [m for m in marks if m[0] > 0]
    steps, secs = marks[-1][0] - marks[0][0], marks[-1][1] - marks[0][1]
    return {"members": members, "devices": devices, "wall_s": wall, "steps": res[0].info.n_steps,
            "member_steps_per_s": members * steps / secs, "ms_per_step": 1e3 * secs / steps,
            "complete": all(r.complete for r in res)}


def _spawn(*args) -> dict:
    out = subprocess.run([sys.executable, __file__, *map(str, args)], capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def _throughput(quick: bool) -> dict:
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    figs = {"single_run_driver": _spawn("worker", 1, 1, "single")}
    ref = figs["single_run_driver"]["member_steps_per_s"]
    for d in sorted({1, cores}):
        for b in (1, 2) if quick else (1, 2, 4, 8):
            f = _spawn("worker", b, d, "batch")
            f["vs_single_run_driver"] = f["member_steps_per_s"] / ref
            figs[f"batch{b}_devices{d}"] = f
    return figs


def _sweep_vs_separate() -> dict:
    tmp = pathlib.Path(tempfile.mkdtemp(prefix="jaxform-bench-sweep-"))
    base = [sys.executable, "-m", "jaxform"]
    common = ["--element-size-mm", str(SIZE_MM)]
    t0 = time.perf_counter()
    subprocess.run([*base, "sweep", CASE, "--vary", "holder.gap_mm=" + ",".join(GAPS_MM), "--out", str(tmp / "sweep"),
                    "--quiet", *common], check=True, capture_output=True)
    t_sweep = time.perf_counter() - t0
    t0 = time.perf_counter()
    for g in GAPS_MM:
        subprocess.run([*base, "run", CASE, "--set", f"holder.gap_mm={g}", "--out", str(tmp / f"run{g}"), "--quiet",
                        *common], check=True, capture_output=True)
    t_sep = time.perf_counter() - t0
    members = []
    for i, g in enumerate(GAPS_MM):
        (d,) = list((tmp / "sweep").glob(f"{i:03d}-*"))
        a = json.loads((d / "summary.json").read_text())
        b = json.loads((tmp / f"run{g}" / "summary.json").read_text())
        members.append({"gap_mm": g, "complete": [a["complete"], b["complete"]],
                        "max_shear_deg": [a["max_shear_angle_deg"], b["max_shear_angle_deg"]],
                        "shear_diff_deg": abs(a["max_shear_angle_deg"] - b["max_shear_angle_deg"]),
                        "draw_in_mid_rel_diff": abs(a["draw_in"]["edge_mid_m"] / b["draw_in"]["edge_mid_m"] - 1)})
    return {"sweep_wall_s": t_sweep, "separate_wall_s": t_sep, "ratio": t_sep / t_sweep, "members": members,
            "out": str(tmp)}


def run(quick: bool = False) -> dict:
    figs = {"throughput": _throughput(quick)}
    if not quick:
        try:  # keep the throughput figures whatever happens here
            figs["sweep_vs_separate"] = _sweep_vs_separate()
        except subprocess.CalledProcessError as err:
            figs["sweep_vs_separate"] = {"error": f"{err}; stderr: {(err.stderr or b'')[-2000:]!r}"}
    return figs


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "worker":
        print(json.dumps(_worker(int(sys.argv[2]), int(sys.argv[3]), sys.argv[4] == "single")))
    else:
        print(json.dumps(run(quick="--quick" in sys.argv), indent=2))
