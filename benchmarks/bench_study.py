"""Paper-study benchmark (issue 15, done-when item 1): ``jaxform study paper`` end to end.

``run(quick)`` runs the command in a fresh process into a new folder and returns its wall time
(runs, measuring, report), every run's own wall time, steps, KE/IE and completion, the time to
measure and write the report again from the finished runs (``--analyse-only``), and the claims'
verdicts. The report, ``claims.json`` and the figures are copied to
``benchmarks/results/study-<size>mm-<UTC stamp>/`` (the run folders are not kept).

Element size ``JAXFORM_BENCH_STUDY_MM`` (default 4 mm: about 40 minutes on two cores);
``quick``: woven Case A NLBM only, at 8 mm.
"""
from __future__ import annotations

import datetime as _dt
import json
import os
import pathlib
import shutil
import subprocess
import sys
import tempfile
import time

HERE = pathlib.Path(__file__).resolve().parent


def _jaxform(*args) -> tuple[int, float]:
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", "jaxform", *args], capture_output=True, text=True)
    if proc.returncode not in (0, 1):
        raise RuntimeError(f"jaxform {' '.join(args)} exited {proc.returncode}: {proc.stderr[-2000:]}")
    return proc.returncode, time.perf_counter() - t0


def run(quick: bool = False) -> dict:
    size = 8.0 if quick else float(os.environ.get("JAXFORM_BENCH_STUDY_MM", "4"))
    part = ["--only", "case-a-woven", "--bending", "nlbm"] if quick else []
    stamp = _dt.datetime.now(_dt.timezone.utc).strftime("%Y%m%dT%H%M%SZ")
    with tempfile.TemporaryDirectory() as tmp:
        out = pathlib.Path(tmp) / "study"
        args = ["study", "paper", "--element-size-mm", f"{size:g}", "--out", str(out), "--quiet", *part]
        status, wall = _jaxform(*args)
        _, analyse = _jaxform(*args, "--analyse-only")
        measures = json.loads((out / "measures.json").read_text())
        claims = json.loads((out / "claims.json").read_text())["claims"]
        keep = HERE / "results" / f"study-{size:g}mm-{stamp}"
        keep.mkdir(parents=True)
        for f in ["report.md", "claims.json", *[p.name for p in out.glob("fig_*.png")]]:
            shutil.copy(out / f, keep / f)
    runs = {n: {"complete": m.get("complete"), "reason": m.get("reason"), "wall_time_s": m.get("wall_time_s"),
                "n_steps": (m.get("numerics") or {}).get("n_steps"), "max_ke_ie": m.get("max_ke_ie")}
            for n, m in measures.items()}
    return {"element_size_mm": size, "parts": part or "all", "exit_status": status, "wall_s": wall,
            "analyse_only_s": analyse, "runs": runs,
            "verdicts": {c["id"]: c["verdict"] for c in claims}, "report": str(keep.relative_to(HERE.parent))}


if __name__ == "__main__":
    print(json.dumps(run(quick="--quick" in sys.argv), indent=2))
