"""``jaxform check-quasi-static RUN_DIR HALF_SPEED_DIR``: is a run quasi-static, from two finished runs?

Compares a ``jaxform run`` folder with one of the same case run at half its punch speed, as
``jaxform run --verify-quasi-static`` compares the pair it runs, without running either again
(:func:`jaxform.study.measures.quasi_static_check_dirs`): the final shear-angle map at the 95th
percentile of the nodes (limit 1°), the edge mid-side draw-in (2 %) and the number of flange
wrinkles (equal), the shear maps frame by frame along the stroke, and where the runs differ,
whether either lost the case's half-turn symmetry (a slower run is then not known to help). For a
pair run apart: a long run, then its half-speed twin on another day or machine
(``--set process.speed_mm_per_s=V``, V half the first run's ``numerics.punch_speed_m_per_s``).

Exit status 0: quasi-static; 1: not, or not checked (a run incomplete: the reason is printed);
2: bad input (not two run folders of one case at a speed and its half). ``--json FILE`` writes the
check; an existing FILE is refused unless ``--force``.
"""
from __future__ import annotations

import pathlib
import sys


def add_parser(subparsers) -> None:
    p = subparsers.add_parser(
        "check-quasi-static",
        help="the quasi-static check of two finished runs of one case, the second at half the speed",
        description=__doc__,
    )
    p.add_argument("run_dir", type=pathlib.Path, help="a 'jaxform run' folder")
    p.add_argument("half_speed_dir", type=pathlib.Path, help="the same case's run folder at half that run's speed")
    p.add_argument("--json", type=pathlib.Path, default=None, help="write the check to this JSON file")
    p.add_argument("--force", action="store_true", help="overwrite an existing --json file")
    p.set_defaults(handler=run)


def run(args) -> int:
    from jaxform.cli.run import report_check
    from jaxform.io.frames import write_json
    from jaxform.study.measures import quasi_static_check_dirs

    for d in (args.run_dir, args.half_speed_dir):
        if not d.is_dir():
            raise FileNotFoundError(f"no such run folder: {d}")
    if args.json is not None and args.json.exists() and not args.force:
        raise FileExistsError(f"{args.json} exists; refusing to overwrite it (give --force)")
    check = quasi_static_check_dirs(args.run_dir, args.half_speed_dir)
    print(f"{args.run_dir} at {check['speed_mm_per_s']:g} mm/s against {args.half_speed_dir}:")
    report_check(check, sys.stdout)
    if args.json is not None:
        write_json(args.json, check)
        print(f"wrote {args.json}")
    sys.stdout.flush()
    return 0 if check["quasi_static"] else 1
