"""Hemisphere forming runs: a case (spec, presets) becomes a rig built once, which the driver runs into frames and a summary.

Modules, along the data flow (imports point one way):

    case      the SI description of a case and its validation (no I/O, no physics)
    presets   the paper's cases and ``--set`` overrides
    health    the physical bounds a run never crosses, and their words
    rig       Case -> (Model, State, RunInfo): mesh, fabrics, tools, contact, time step, built once
    fields    nodal fields of a state (pure, jit-able)
    summary   draw-in, wrinkle count, symmetry, the JSON summary, the half-speed check (host, numpy)
    driver    pure chunks and rollout; the host run with frames and progress callbacks
    batch     many members of a case as vmapped programs sharded over devices (sweeps)

``simulate(case)`` = ``run(build(jaxform.cases.resolve(case)))``.
"""
from __future__ import annotations

from jaxform.forming.case import Case, ply_heights
from jaxform.forming.driver import ENERGY_FLOOR, FormingResult, rollout, run, run_steps, simulate, with_momentum_term
from jaxform.forming.fields import node_average, state_fields
from jaxform.forming.rig import (Rig, RunInfo, build, build_fabric, build_mesh, build_tools, grid_quads, ply_fabrics,
                                 punch_motion, stroke_time, with_fabric)
from jaxform.forming.summary import (QUASI_STATIC_LIMITS, draw_in, flange_census, flange_mask, quasi_static_check,
                                     summarize, symmetry_error)

__all__ = ["Case", "ply_heights", "Rig", "RunInfo", "build", "build_fabric", "build_mesh", "build_tools", "grid_quads",
           "ply_fabrics", "punch_motion", "stroke_time", "with_fabric", "node_average", "state_fields", "ENERGY_FLOOR",
           "FormingResult", "rollout", "run", "run_steps", "simulate", "with_momentum_term", "draw_in", "flange_census", "flange_mask",
           "summarize", "symmetry_error", "QUASI_STATIC_LIMITS", "quasi_static_check"]
