"""``jaxform sweep CASE --vary KEY=V1,V2,... --out DIR``: many runs of one case as batched programs.

The members are every combination of the ``--vary`` values (``--set`` applies to all). Members
that share a mesh run as one vmapped program sharded over the devices
(:func:`jaxform.forming.batch.simulate_batch`). Writes into DIR:

* ``<member>/``: exactly what ``jaxform run`` writes (frames, ``summary.json``, PNGs), the
  summary with a ``batch`` entry saying which program ran the member;
* ``sweep.csv``: one row per member: the varied keys, ``complete``, ``reason``,
  ``max_shear_angle_deg``, ``draw_in_edge_mid_mm``, ``draw_in_corner_mm``, ``flange_wrinkles``,
  ``max_ke_ie``, ``wall_time_s`` (its program's, shared by the program's members), the group,
  part and size of its program, and the process that ran it;
* ``sweep_<key>.png``: each scalar against each varied key.

A failed member is reported in its row and does not stop the others (exit status 1 when any
failed). On a CPU-only machine each core becomes a device (``--cpu-devices``, default the cores
this process may use), so the members are spread over the cores.

Across processes or machines (JAX's multi-controller runtime, ``jax.distributed``): give
``--coordinator HOST:PORT --num-processes N --process-id I`` (or the environment variables
``JAX_COORDINATOR_ADDRESS``, ``JAX_NUM_PROCESSES``, ``JAX_PROCESS_ID``) to every process, all with
the same arguments and the same DIR (a shared file system across machines). Process ``I`` runs
members ``I, I + N, ...`` on its own devices; process 0 gathers the rows (``process_allgather``)
and writes ``sweep.csv`` and the plots.
"""
from __future__ import annotations

import itertools
import json
import os
import pathlib
import re
import sys

from jaxform.batching import cores
from jaxform.cli.progress import Progress
from jaxform.cli.run import OUTPUTS, point_data, save_plots
from jaxform.forming.summary import warning_kinds

SCALARS = ("max_shear_angle_deg", "draw_in_edge_mid_mm", "draw_in_corner_mm", "flange_wrinkles", "max_ke_ie")
"""The per-member scalars of ``sweep.csv`` and of the plots."""
COLUMNS = ("member", "dir", "complete", "reason", "warnings", *SCALARS, "wall_time_s", "group", "part", "batch_members",
           "devices", "process")
"""``sweep.csv``'s columns after the varied keys (``member``/``dir`` first)."""


def add_parser(subparsers) -> None:
    p = subparsers.add_parser("sweep", help="run many variants of one case as batched programs",
                              description=__doc__)
    p.add_argument("case", help="preset name (see 'jaxform cases') or a case .toml file")
    p.add_argument("--vary", action="append", default=[], metavar="KEY=V1,V2,...", required=True,
                   help="a case key and its values, e.g. --vary fabric.friction_tool=0.15,0.2,0.3 (repeatable: "
                        "every combination runs)")
    p.add_argument("--out", type=pathlib.Path, required=True, help="output directory")
    p.add_argument("--element-size-mm", type=float, default=None, help="override blank.element_size_mm")
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                   help="override a case key for every member (repeatable)")
    p.add_argument("--max-members", type=int, default=None, help="at most this many members per program")
    p.add_argument("--cpu-devices", type=int, default=None,
                   help="on a CPU-only machine, the devices JAX makes of the cores (default: the cores this process "
                        "may use)")
    p.add_argument("--coordinator", default=os.environ.get("JAX_COORDINATOR_ADDRESS"),
                   help="HOST:PORT of process 0 for a run over several processes (env JAX_COORDINATOR_ADDRESS)")
    p.add_argument("--num-processes", type=int, default=_env_int("JAX_NUM_PROCESSES"),
                   help="number of processes (env JAX_NUM_PROCESSES)")
    p.add_argument("--process-id", type=int, default=_env_int("JAX_PROCESS_ID"),
                   help="this process's number, 0 .. N-1 (env JAX_PROCESS_ID)")
    p.add_argument("--force", action="store_true", help="write into a non-empty directory")
    p.add_argument("--quiet", action="store_true", help="no progress output")
    p.set_defaults(handler=run)


def _env_int(name):
    v = os.environ.get(name)
    return None if v in (None, "") else int(v)


def split_values(text: str) -> list[str]:
    """``"0.1,0.2,[1,2]"`` -> ``["0.1", "0.2", "[1,2]"]``: commas inside brackets or quotes stay."""
    out, depth, quote, cur = [], 0, None, ""
    for ch in text:
        if quote:
            quote = None if ch == quote else quote
        elif ch in "\"'":
            quote = ch
        elif ch in "[(":
            depth += 1
        elif ch in "])":
            depth -= 1
        elif ch == "," and depth == 0:
            out.append(cur.strip())
            cur = ""
            continue
        cur += ch
    out.append(cur.strip())
    return out


def parse_vary(items) -> list[tuple[str, list[str]]]:
    """``["k=v1,v2", ...]`` -> ``[(k, [v1, v2]), ...]`` with clear errors for bad input."""
    out = []
    for item in items:
        key, sep, values = item.partition("=")
        key = key.strip()
        if not sep or not key or not values.strip():
            raise ValueError(f"--vary {item!r}: expected KEY=V1,V2,... (e.g. fabric.friction_tool=0.15,0.3)")
        vals = split_values(values)
        if any(v == "" for v in vals):
            raise ValueError(f"--vary {item!r}: an empty value (two commas, or one at an end)")
        if key in (k for k, _ in out):
            raise ValueError(f"--vary {key} is given twice; give all its values in one --vary")
        out.append((key, vals))
    return out


def member_names(vary, combos) -> list[str]:
    """Folder names ``000-key=value-...`` (the last part of each key; unsafe characters as ``_``)."""
    names = []
    for i, combo in enumerate(combos):
        parts = [f"{k.rsplit('.', 1)[-1]}={v}" for (k, _), v in zip(vary, combo)]
        names.append(re.sub(r"[^A-Za-z0-9._=+-]", "_", f"{i:03d}-" + "-".join(parts))[:120])
    return names


def _row(i, name, vary, combo, result, process: int) -> dict:
    s = result.summary
    di = s.get("draw_in") or {}
    b = s.get("batch", {})
    row = {"member": i, "dir": name, **{k: v for (k, _), v in zip(vary, combo)}, "complete": bool(result.complete),
           "reason": result.reason or "", "max_shear_angle_deg": s.get("max_shear_angle_deg"),
           "warnings": ";".join(warning_kinds(s.get("findings"))),
           "draw_in_edge_mid_mm": None if not di else 1e3 * di["edge_mid_m"],
           "draw_in_corner_mm": None if not di else 1e3 * di["corner_m"],
           "flange_wrinkles": s.get("flange_wrinkles"), "max_ke_ie": s.get("max_ke_ie"),
           "wall_time_s": result.wall_time_s, "group": b.get("group"), "part": b.get("part"),
           "batch_members": b.get("members"), "devices": b.get("devices"), "process": process}
    return row


def _gather_rows(rows: dict, n: int) -> list[dict]:
    """Every process's rows on every process (JAX's ``process_allgather`` of the rows as bytes)."""
    import jax
    import numpy as np
    from jax.experimental import multihost_utils

    if jax.process_count() == 1:
        return [rows[i] for i in range(n)]
    text = {i: json.dumps(r).encode() for i, r in rows.items()}
    width = int(np.max(multihost_utils.process_allgather(np.array([max(map(len, text.values()), default=1)]))))
    mine = np.zeros((n, width), np.uint8)
    for i, t in text.items():
        mine[i, :len(t)] = np.frombuffer(t, np.uint8)
    every = np.asarray(multihost_utils.process_allgather(mine)).reshape(-1, n, width).max(axis=0)
    return [json.loads(bytes(every[i][every[i] > 0]).decode()) for i in range(n)]


def write_table(out: pathlib.Path, vary, rows) -> pathlib.Path:
    """``sweep.csv``: the varied keys, then :data:`COLUMNS`."""
    import csv

    keys = [k for k, _ in vary]
    cols = ["member", "dir", *keys, *COLUMNS[2:]]
    path = out / "sweep.csv"
    with path.open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=cols)
        w.writeheader()
        for r in rows:
            w.writerow({c: "" if r.get(c) is None else r[c] for c in cols})
    return path


def _init_distributed(args) -> tuple[int, int]:
    """``(process id, process count)``, starting JAX's multi-controller runtime when asked."""
    given = [args.coordinator, args.num_processes, args.process_id]
    if all(v is None for v in given):
        return 0, 1
    if any(v is None for v in given):
        raise ValueError("a run over several processes needs --coordinator HOST:PORT, --num-processes N and "
                         "--process-id I (or JAX_COORDINATOR_ADDRESS, JAX_NUM_PROCESSES, JAX_PROCESS_ID)")
    if not (args.num_processes >= 1 and 0 <= args.process_id < args.num_processes):
        raise ValueError(f"--process-id {args.process_id} with --num-processes {args.num_processes}: need 0 <= id < N")
    import jax

    jax.distributed.initialize(coordinator_address=args.coordinator, num_processes=args.num_processes,
                               process_id=args.process_id)
    return args.process_id, args.num_processes


def _cpu_devices(n):
    """One JAX CPU device per core (before JAX starts; once it has, its devices stay as they are)."""
    import jax

    if n is None:
        n = cores()
    if int(n) < 1:
        raise ValueError(f"--cpu-devices {n}: need at least 1")
    try:
        jax.config.update("jax_num_cpu_devices", int(n))
    except RuntimeError:  # JAX already started in this process (a caller of main()): keep its devices
        pass


def run_members(base, overrides, dirs, *, quiet: bool = False, on_result=None, label: str = "sweep") -> list:
    """Run the members of ``base`` (one list of ``--set`` overrides each) as batched programs, each
    into its prepared folder of ``dirs`` exactly as ``jaxform run`` writes it (frames as they come,
    ``summary.json`` written first as running, plots). Shared by ``jaxform sweep`` and
    ``jaxform study``.

    ``on_result(j, result, ran)`` is called once per member ``j`` when its summary is written
    (``ran``: False for a member that never ran: no rig, or an interrupted batch). Returns the
    :class:`~jaxform.forming.driver.FormingResult` of every member, in order.
    """
    from jaxform import cases
    from jaxform.forming.batch import simulate_batch
    from jaxform.io.frames import FrameWriter, write_json

    for ov, d in zip(overrides, dirs):
        write_json(d / "summary.json", {"complete": False, "reason": "running (or killed before it could say why)",
                                        "case": base.name, "inputs": cases.to_dict(cases.apply_overrides(base, ov))})
    writers, done = {}, set()

    def on_frame(j, info, k, t, x, fields):
        if j not in writers:
            writers[j] = FrameWriter(dirs[j], info.faces, stem="frames")
        writers[j].write(t, x, point_data(fields, info.ply_id))

    def finish(j, res, ran):
        if ran and len(res.t):
            save_plots(res, dirs[j])
        write_json(dirs[j] / "summary.json", res.summary)
        done.add(j)
        if on_result is not None:
            on_result(j, res, ran)

    def on_part(part, results):
        for j, res in zip(part.members, results):
            finish(j, res, True)

    progress = Progress(quiet=quiet, label=label)
    current = [None]

    def on_progress(part, step, n_steps, t, punch, elapsed):
        if current[0] is not part:
            if current[0] is not None:
                progress.done()
            current[0] = part
            progress.start(n_steps, f"program {part.group}.{part.part}: {len(part.members)} members on "
                                    f"{part.devices} device(s)")
        if step > 0:
            progress(step, n_steps, t, punch, elapsed)

    try:
        results = simulate_batch(base, list(overrides), on_frame=on_frame, on_part=on_part, on_progress=on_progress)
    finally:
        if current[0] is not None:
            progress.done()
    for j, res in enumerate(results):  # members that never ran (no rig, or an interrupted batch): say why
        if j not in done:
            finish(j, res, False)
    return results


def run(args) -> int:
    from jaxform import cases
    from jaxform.cli import use_case_dtype
    from jaxform.io.output import prepare_output_dir

    vary = parse_vary(args.vary)
    if args.max_members is not None and args.max_members < 1:
        raise ValueError(f"--max-members {args.max_members}: need at least 1")
    _cpu_devices(args.cpu_devices)  # both before anything starts JAX's backend (reading a case can)
    pid, n_proc = _init_distributed(args)
    base = cases.resolve(args.case, element_size=None if args.element_size_mm is None else args.element_size_mm * 1e-3,
                         overrides=args.overrides)
    combos = list(itertools.product(*[v for _, v in vary]))
    overrides = [[f"{k}={v}" for (k, _), v in zip(vary, combo)] for combo in combos]
    for ov in overrides:  # every member's input checked before anything is written
        use_case_dtype(cases.apply_overrides(base, ov))
    names = member_names(vary, combos)
    out = args.out
    if pid == 0:
        prepare_output_dir(out, force=args.force, owner="sweep", replaces=("sweep.csv", "sweep_*.png"))
    if n_proc > 1:  # the others write into DIR once process 0 has checked and claimed it
        from jax.experimental import multihost_utils

        multihost_utils.sync_global_devices("jaxform sweep: output directory ready")
    mine = list(range(pid, len(combos), n_proc))

    dirs = {i: prepare_output_dir(out / names[i], force=args.force, owner="run", replaces=OUTPUTS) for i in mine}
    rows = {}

    def on_result(j, res, ran):
        i = mine[j]
        rows[i] = _row(i, names[i], vary, combos[i], res, pid)
        if not args.quiet:
            state = "complete" if res.complete else (f"INCOMPLETE ({res.reason})" if ran else f"NOT RUN ({res.reason})")
            print(f"  {names[i]}: {state}", file=sys.stdout, flush=True)

    if not args.quiet:
        print(f"sweep of {base.name}: {len(combos)} members, {len(mine)} in process {pid} of {n_proc}", flush=True)
    if mine:
        run_members(base, [overrides[i] for i in mine], [dirs[i] for i in mine], quiet=args.quiet,
                    on_result=on_result)
    every = _gather_rows(rows, len(combos)) if n_proc > 1 else [rows[i] for i in range(len(combos))]
    if pid == 0:
        from jaxform.plots.sweep import sweep_plots

        written = [write_table(out, vary, every), *sweep_plots(out, vary, every, SCALARS)]
        if not args.quiet:
            failed = sum(not r["complete"] for r in every)
            print(f"{len(every)} members, {failed} failed. Wrote to {out.resolve()}:")
            for p in written:
                print(f"  {p}")
    if all(r["complete"] for r in every):
        return 0
    from jaxform.cli import TERMINATED
    from jaxform.forming.batch import INTERRUPTED

    reasons = [r.get("reason") or "" for r in every]
    if any(TERMINATED in r for r in reasons):
        return 143
    return 130 if any(r.startswith(INTERRUPTED) for r in reasons) else 1
