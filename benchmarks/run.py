"""Run every benchmark and write its figures to a file.

    python benchmarks/run.py [--quick] [--only NAME ...] [--out FILE]

Each ``benchmarks/bench_<name>.py`` exposes ``run(quick: bool) -> dict`` returning named figures
(JSON-serialisable). This driver runs them in one process, one after the other, and writes
``benchmarks/results/<UTC date>-<host>.json`` (or ``--out``) with the machine description, so
figures from different machines are never confused. Timings are never asserted in tests.
"""
from __future__ import annotations

import argparse
import datetime as _dt
import importlib.util
import json
import os
import pathlib
import platform
import socket
import sys
import time
import traceback

HERE = pathlib.Path(__file__).resolve().parent


def _machine() -> dict:
    import jax

    return {
        "host": socket.gethostname(),
        "platform": platform.platform(),
        "python": platform.python_version(),
        "cpu_count": os.cpu_count(),
        "jax": jax.__version__,
        "jax_backend": jax.default_backend(),
        "devices": [str(d) for d in jax.devices()],
    }


def _bench_modules() -> list[pathlib.Path]:
    return sorted(HERE.glob("bench_*.py"))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="small sizes only (a smoke run)")
    parser.add_argument("--only", nargs="*", default=None, help="names to run, e.g. shell metrics")
    parser.add_argument("--out", type=pathlib.Path, default=None, help="result file (JSON)")
    args = parser.parse_args(argv)

    stamp = _dt.datetime.now(_dt.timezone.utc).strftime("%Y%m%dT%H%M%SZ")
    out = args.out or HERE / "results" / f"{stamp}-{socket.gethostname()}.json"
    out.parent.mkdir(parents=True, exist_ok=True)
    if out.exists():
        raise SystemExit(f"refusing to overwrite existing result file {out}; pass another --out")

    results: dict = {"machine": _machine(), "quick": args.quick, "started_utc": stamp, "benchmarks": {}}
    for path in _bench_modules():
        name = path.stem.removeprefix("bench_")
        if args.only and name not in args.only:
            continue
        spec = importlib.util.spec_from_file_location(f"benchmarks.{path.stem}", path)
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        print(f"[bench] {name} ...", flush=True)
        t0 = time.perf_counter()
        try:
            figures = module.run(quick=args.quick)
            status = "ok"
        except Exception:  # keep the other benchmarks' figures; record what failed
            figures = {"error": traceback.format_exc()}
            status = "failed"
        results["benchmarks"][name] = {"status": status, "seconds": time.perf_counter() - t0, **figures}
        # Write after every benchmark so an interrupted run keeps what it measured.
        out.write_text(json.dumps(results, indent=2, default=float))
        print(json.dumps({name: results["benchmarks"][name]}, indent=2, default=float), flush=True)
    print(f"[bench] figures written to {out}")
    return 0 if all(b["status"] == "ok" for b in results["benchmarks"].values()) else 1


if __name__ == "__main__":
    sys.exit(main())
