"""``jaxform study paper --out DIR``: the source paper's wrinkle study, run and compared claim by claim.

Runs Case A for both fabrics with NLBM, LBM (B_init, B_41.5, B_inf) and membrane only, and Case B
with NLBM for both fabrics (:mod:`jaxform.study.plan`), each into ``DIR/runs/<preset>/`` exactly as
``jaxform run`` writes it, the runs of one fabric's Case A as batched programs. The study is
resumable: a run whose folder says it ended with the same inputs is not redone; an interrupted
one, or one with other inputs, is run again into its folder. Then it measures every run from its files (:mod:`jaxform.study.measures`) and writes:

* ``DIR/report.md``: the runs (time, KE/IE, numerics), every claim with the paper's statement,
  jaxform's figures and the verdict, and the figures below;
* ``DIR/claims.json``: one entry per claim (:mod:`jaxform.study.claims`);
* ``DIR/measures.json``: every figure measured on every run;
* ``DIR/fig_*.png``: deviation maps with the sections A-A' and B-B' drawn on them (Fig. 7, 10),
  the sections of all variants (Fig. 8, 11), M_f^RMS maps and densities LBM vs NLBM (Fig. 9, 13),
  NCF shear and deviation at 30/40/50 mm of stroke (Fig. 12), Case B deviation, kappa_max and
  fibre strain (Fig. 14, 15);
* ``DIR/sections/<run>_<A|B>.csv``: each section as ``s_mm,amplitude_mm`` (the format
  ``calibration/fit_wrinkles.py`` reads).

Exit status 0 when every run completed, 1 when one did not (its claims say 'not measurable').
"""
from __future__ import annotations

import pathlib
import sys
import time

from jaxform.cli.run import OUTPUTS

STUDIES = ("paper",)


def add_parser(subparsers) -> None:
    p = subparsers.add_parser("study", help="the source paper's wrinkle study, claim by claim", description=__doc__)
    p.add_argument("study", choices=STUDIES, help="which study (the source paper's)")
    p.add_argument("--out", type=pathlib.Path, required=True, help="output directory (resumed when it holds a study)")
    p.add_argument("--element-size-mm", type=float, default=None,
                   help="blank element size for every run (default: each preset's own: 2 mm Case A, 1 mm Case B)")
    p.add_argument("--only", default=None, help="one part of the study: case-a-woven, case-a-ncf or case-b")
    p.add_argument("--bending", default=None, metavar="M1,M2,...",
                   help="run only these bending models (nlbm, lbm-init, lbm-41, lbm-inf, membrane; Case B runs nlbm "
                        "only); default all")
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                   help="override a case key in every run (repeatable), e.g. process.speed_mm_per_s=62.5")
    p.add_argument("--analyse-only", action="store_true",
                   help="run nothing: measure the runs already in DIR and write the report")
    p.add_argument("--cpu-devices", type=int, default=None,
                   help="on a CPU-only machine, the devices JAX makes of the cores (default: the cores this process "
                        "may use)")
    p.add_argument("--force", action="store_true", help="write into a non-empty directory not made by this command")
    p.add_argument("--quiet", action="store_true", help="no progress output")
    p.set_defaults(handler=run)


def _run_missing(runs, root: pathlib.Path, *, force: bool, quiet: bool) -> None:
    """Run every run of ``runs`` that has no reusable folder, batched by base preset."""
    from jaxform import cases
    from jaxform.cli.sweep import run_members
    from jaxform.forming.batch import INTERRUPTED
    from jaxform.io.output import prepare_output_dir
    from jaxform.study.plan import finished

    todo = {}
    for r in runs:
        why = finished(r, root / r.name)
        if why is not None:
            if not quiet:
                print(f"  {r.name}: kept ({why})", flush=True)
            continue
        todo.setdefault(r.base, []).append(r)
    for base, members in todo.items():
        dirs = [prepare_output_dir(root / r.name, force=force, owner="run", replaces=OUTPUTS) for r in members]

        def on_result(j, res, ran, members=members):
            if not quiet:
                state = "complete" if res.complete else f"{'INCOMPLETE' if ran else 'NOT RUN'} ({res.reason})"
                print(f"  {members[j].name}: {state}", flush=True)

        if not quiet:
            print(f"{base}: {len(members)} run(s): {', '.join(r.name for r in members)}", flush=True)
        results = run_members(cases.load(base), [list(r.overrides) for r in members], dirs, quiet=quiet,
                              on_result=on_result, label="study")
        stopped = [res.reason for res in results if (res.reason or "").startswith(INTERRUPTED)]
        if stopped:  # Ctrl-C or SIGTERM: the finished runs stay and a rerun resumes from them
            from jaxform.cli import TERMINATED

            raise KeyboardInterrupt(TERMINATED if any(TERMINATED in r for r in stopped) else
                                    f"interrupted during {base}; rerun the same command to resume")


def run(args) -> int:
    from jaxform.cli.sweep import _cpu_devices
    from jaxform.io.output import prepare_output_dir
    from jaxform.study.plan import RUNS_DIR, SETTINGS, plan
    from jaxform.study.report import REPORT_OUTPUTS, write_study

    if args.cpu_devices is not None or not args.analyse_only:
        _cpu_devices(args.cpu_devices)
    bending = None if args.bending is None else [b.strip() for b in args.bending.split(",")]
    runs = plan(only=args.only, bending=bending, element_size_mm=args.element_size_mm, settings=args.overrides)
    if not runs:
        raise ValueError(f"--only {args.only} with --bending {args.bending}: no run left (Case B runs nlbm only)")
    out = prepare_output_dir(args.out, force=args.force, owner="study", replaces=REPORT_OUTPUTS)
    root = out / RUNS_DIR
    t0 = time.perf_counter()
    if not args.analyse_only:
        root.mkdir(exist_ok=True)
        _run_missing(runs, root, force=args.force, quiet=args.quiet)
    run_s = time.perf_counter() - t0
    if not args.quiet:
        print("measuring the runs and writing the report...", flush=True)
    written, claims, complete = write_study(out, runs, run_wall_s=None if args.analyse_only else run_s,
                                           settings=(*SETTINGS, *args.overrides))
    if not args.quiet:
        counts = {}
        for c in claims:
            counts[c["verdict"]] = counts.get(c["verdict"], 0) + 1
        print(f"{len(claims)} claims: " + ", ".join(f"{n} {v}" for v, n in counts.items()))
        print(f"wrote to {out.resolve()}:")
        for p in written:
            print(f"  {p}")
    if not complete:
        print("jaxform study: some runs did not complete (see report.md)", file=sys.stderr)
    return 0 if complete else 1
