"""Fabric contact benchmark (issue 19, done-when item 4): the search and the self-contact's share.

``run(quick)`` returns named figures:

* ``search_case_b_<S>mm``: the stack-contact candidate search of Case B alone (ply 1's nodes
  against ply 2's triangles, flat blank): the old ``O(N_s F)`` :func:`jaxform.contact.nearest_faces`
  and the cell grid of :func:`jaxform.broadphase.candidates` (``PlyLoad.search``), seconds per
  call after compilation; at 1 mm (2 x 63k nodes, 125k triangles) the old search is timed on
  ``old_sample`` slave nodes and scaled by ``N_s / old_sample`` (its cost is exactly linear in the
  slave count), the new on all of them.
* ``share_<preset>_<S>mm``: ms per step of the full forming step with and without self-contact
  (``run_steps``, best of 3) on a folded shape (a frame of ``case-a-ncf-nlbm`` interpolated onto
  the mesh: at the start the blank is flat and self-contact costs nothing): at 4 mm its last
  frame at 4 mm, preset numerics; at 2 mm the frame at 90% of the stroke of the 2 mm run with
  the automatic fibre mass (6), with that fibre mass (the numerics a 2 mm run uses; the 4 mm
  shape interpolated onto 2 mm at the preset's step moved at 200 m/s, nothing like a forming run),
  timed over 400 steps after 400 steps of settling, with the number of refreshes in that window;
  the self-contact load alone (its table carried, refreshed every 200 calls), one refresh of its
  candidate table, and the nodes and edges evaluated each step.

* ``friction_<preset>_<S>mm``: ms per step of the full forming step with the tools' and the
  plies' friction integrated backward (``ToolLoad.friction``, ``PlyLoad.friction``, the default)
  and with the explicit law inside the loads (``implicit_friction=False``, the stick limit of one
  interface), from the flat blank (every node on the die), best of 3 over ``n`` steps after ``n``
  of settling; their ratio is the implicit friction's overhead.

Timings depend on the machine's load: say so when quoting them.
"""
from __future__ import annotations

import pathlib
import time

import jax
import jax.numpy as jnp
import numpy as np


def _best(f, *a, repeat=3):
    jax.block_until_ready(f(*a))
    t = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        jax.block_until_ready(f(*a))
        t.append(time.perf_counter() - t0)
    return min(t)


def search_cost(size_mm: float, old_sample: int | None = 4096) -> dict:
    from jaxform import cases, contact
    from jaxform.forming import rig

    case = cases.with_element_size(cases.load("case-b-woven-nlbm"), size_mm * 1e-3)
    mesh = rig.build_mesh(case)
    x = jnp.asarray(mesh.nodes, jnp.float32)
    (a, b), (t0, t1) = mesh.ply_nodes[0], mesh.ply_tris[1]
    slave = jnp.arange(a, b, dtype=jnp.int32)
    tris = jnp.asarray(np.asarray(mesh.tris)[t0:t1], jnp.int32)
    h = float(case.ply_thickness)
    load = contact.PlyLoad(slave=slave, triangles=tris, gap0=h, area=1.0,
                           params=contact.ContactParams(stiffness=1e10), skin=max(h, 0.25 * size_mm * 1e-3))
    new = _best(jax.jit(load.search), x)
    n_old = len(slave) if old_sample is None else min(old_sample, len(slave))
    old_fn = jax.jit(lambda y: contact.nearest_faces(y, slave[:n_old], tris, 8))
    old = _best(old_fn, x, repeat=1) * len(slave) / n_old
    return {"slave_nodes": int(len(slave)), "triangles": int(len(tris)), "old_s": old, "old_timed_on": int(n_old),
            "new_s": new, "speedup": old / new}


FOLDED = pathlib.Path(__file__).resolve().parent / "data" / "case-a-ncf-nlbm-4mm-last-frame.npz"
FOLDED_2MM = pathlib.Path(__file__).resolve().parent / "data" / "case-a-ncf-nlbm-2mm-frame-90pc.npz"


def folded_state(model, state, info, frame=FOLDED):
    """``state`` moved to a formed, folded shape: the displacements of the last frame of
    ``case-a-ncf-nlbm`` at 4 mm (``frame``: reference ``x0`` (N, 3) and ``u`` (N, 3), m, and the
    time ``t``), interpolated linearly onto this blank; the punch where it was then, at rest, the
    contact tables built there. Self-contact costs what it costs where the fabric folds."""
    import dataclasses

    from jaxform import integrate
    from scipy.interpolate import LinearNDInterpolator, NearestNDInterpolator

    d = np.load(frame)
    x0 = np.asarray(info.x0, np.float64)
    u = LinearNDInterpolator(d["x0"][:, :2], d["u"])(x0[:, :2])
    miss = ~np.all(np.isfinite(u), axis=1)
    u[miss] = NearestNDInterpolator(d["x0"][:, :2], d["u"])(x0[miss, :2])
    x = jnp.asarray(x0 + u, state.x.dtype)
    loads = tuple(ls if i < 3 else ld.initial_state(x) for i, (ld, ls) in enumerate(zip(model.loads, state.loads)))
    new = integrate.init_state(model, x=x, load_states=loads)
    return dataclasses.replace(new, t=jnp.asarray(float(d["t"]), state.t.dtype))


def contact_share(name: str, size_mm: float, n: int = 400, frame=FOLDED, overrides=()) -> dict:
    """ms per step with and without self-contact on the folded shape (:func:`folded_state`), over
    ``n`` steps after ``n`` steps of settling (the interpolated shape is not in equilibrium: its first
    steps move fast and refresh the table nearly every step), with the refreshes in that window."""
    from jaxform import cases, forming

    c = cases.apply_overrides(cases.with_element_size(cases.load(name), size_mm * 1e-3), list(overrides))
    out = {"steps_timed": n, "frame": pathlib.Path(frame).name, "overrides": list(overrides)}
    for label, keys in (("on", []), ("off", ["contact.self_contact=false"])):
        model, state, info = forming.build(cases.apply_overrides(c, keys))
        state = folded_state(model, state, info, frame)
        f = jax.jit(lambda m, s: forming.run_steps(m, s, s.energies, s.x, n=n))
        settled = f(model, state)
        end = f(model, settled)
        out[f"healthy_{label}"] = bool(int(end.bad_step) < 0)  # (a failed stretch is frozen: timed anyway)
        out[f"step_{label}_ms"] = 1e3 * _best(lambda m, s: f(m, s).x, model, settled, repeat=2) / n
        if label == "on":
            sc, ls = model.loads[-1], settled.loads[-1]
            out["refreshes_in_window"] = int(end.loads[-1].refreshes - ls.refreshes)
            out["max_node_speed_m_per_s"] = float(jnp.max(jnp.linalg.norm(settled.v, axis=1)))

            def narrow(m, s, ld=sc, st=ls):  # the load alone, its table carried (refreshed every 200 calls)
                def one(c, _):
                    x, st = c
                    fo, st, _ = ld.force(x, s.v, s.t, st)
                    return (x + 1e-15 * fo, st), None
                return jax.lax.scan(one, (s.x, st), None, length=n)[0][0]

            out["self_contact_alone_ms"] = 1e3 * _best(jax.jit(narrow), model, settled) / n
            out["refresh_ms"] = 1e3 * _best(jax.jit(lambda y, ld=sc: ld.search(y)), settled.x)
            cand = ls.candidates
            out["nodes"] = int(len(info.x0))
            out["active_nodes"] = int(jnp.sum(cand.active_nodes >= 0))
            out["active_edges"] = int(jnp.sum(cand.active_edges >= 0))
            out["edges"] = int(sc.edges.shape[0])
            out["all_evaluated"] = bool(cand.overflow)
    out["share_of_step"] = (out["step_on_ms"] - out["step_off_ms"]) / out["step_on_ms"]
    return out


def friction_cost(name: str, size_mm: float, n: int = 400) -> dict:
    """ms per step with the tools' and plies' friction integrated backward and explicitly (module
    docstring), from the start of the run (the flat blank on the die, under the holder: every node
    in contact), timed over ``n`` steps after ``n`` of settling."""
    import dataclasses

    from jaxform import cases, contact, forming

    model, state, info = forming.build(cases.with_element_size(cases.load(name), size_mm * 1e-3))
    rho = float(model.mass[0] / jnp.ravel(jnp.asarray(model.loads[0].area))[0])  # areal mass (scaled), kg/m²
    limit = float(model.dt) / rho  # the explicit law's stick limit for one interface (two for ply on ply)

    def explicit(ld):
        if not hasattr(ld, "implicit_friction"):
            return ld
        k = 2.0 if isinstance(ld, contact.PlyLoad) else 1.0
        return dataclasses.replace(ld, implicit_friction=False, params=dataclasses.replace(ld.params, stick_limit=k * limit))

    f = jax.jit(lambda m, s: forming.run_steps(m, s, s.energies, s.x, n=n))
    settled = f(model, state)
    out = {"steps_timed": n, "nodes": int(model.mass.shape[0]), "start": "the flat blank (step 0), settled n steps"}
    for label, m in (("implicit", model), ("explicit", dataclasses.replace(model, loads=tuple(map(explicit, model.loads))))):
        end = f(m, settled)
        if int(end.bad_step) >= 0:  # a frozen, failed stretch times nothing a run would do
            raise RuntimeError(f"friction_cost {name} {size_mm} mm: the {label} run failed at step "
                               f"{int(end.bad_step)}; no timing recorded")
        out[f"step_{label}_ms"] = 1e3 * _best(lambda mm, s: f(mm, s).x, m, settled, repeat=3) / n
    out["overhead"] = out["step_implicit_ms"] / out["step_explicit_ms"] - 1.0
    return out


def run(quick: bool = False) -> dict:
    figures = {}
    if quick:
        figures["search_case_b_8mm"] = search_cost(8.0, old_sample=None)
        figures["share_case-a-ncf-nlbm_8mm"] = contact_share("case-a-ncf-nlbm", 8.0, n=20)
        figures["friction_case-a-woven-nlbm_8mm"] = friction_cost("case-a-woven-nlbm", 8.0, n=20)
        return figures
    figures["friction_case-a-woven-nlbm_4mm"] = friction_cost("case-a-woven-nlbm", 4.0)
    figures["search_case_b_1mm"] = search_cost(1.0)
    figures["share_case-a-ncf-nlbm_4mm"] = contact_share("case-a-ncf-nlbm", 4.0)
    figures["share_case-a-ncf-nlbm_2mm"] = contact_share("case-a-ncf-nlbm", 2.0, frame=FOLDED_2MM,
                                                         overrides=['numerics.fibre_mass_scaling="auto"'])
    return figures
