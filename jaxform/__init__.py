"""jaxform: differentiable explicit forming simulation of engineering fabrics in JAX.

Public names only; see the README for a tour. SI units everywhere (``jaxform.units``).

Modules along the data flow (imports point one way along it)::

    units, materials          laws and presets (SI)
    mesh, shell               the fabric shell: one kernel for every use
    geometry                  safe maths, point-triangle closest points, the nearest-triangle search
    tools, contact, friction  rigid tools, penalty contact, regularised Coulomb friction
    model, integrate          fixed model / changing state, explicit central differences
    metrics                   wrinkle metric: tool distance, principal curvatures, zones
    forming, cases            hemisphere forming runs (case, presets, rig, fields, summary, driver); the user edge
    statics                   one static solver (damped Newton) with its implicit-function gradient
    cantilever, frame_tests   lab tests built on the same shell (cantilever, picture frame, bias extension)
    calibrate                 fitting laws to measurements through the model

``jaxform.simulate(case)`` runs a forming case (a ``Case``, a preset name or a ``.toml`` path);
``jaxform.simulate_batch(case, overrides_per_member)`` runs many variants of it as batched programs.
Sub-modules are imported on first use, so ``import jaxform`` stays light.
"""
from __future__ import annotations

import importlib

from jaxform import materials, units
from jaxform.materials import NCF_FCIM359, WOVEN_38616, Fabric

__version__ = "0.1.0"

_MODULES = (
    "mesh",
    "shell",
    "tools",
    "contact",
    "friction",
    "model",
    "integrate",
    "geometry",
    "cases",
    "forming",
    "statics",
    "cantilever",
    "frame_tests",
    "metrics",
    "calibrate",
)


def __getattr__(name: str):
    if name in _MODULES:
        return importlib.import_module(f"jaxform.{name}")
    if name in ("simulate", "simulate_batch"):
        return getattr(importlib.import_module("jaxform.cases"), name)
    raise AttributeError(f"module 'jaxform' has no attribute {name!r}")


def __dir__():
    return sorted(list(globals()) + list(_MODULES) + ["simulate", "simulate_batch"])


__all__ = ["materials", "units", "Fabric", "WOVEN_38616", "NCF_FCIM359", "simulate", "simulate_batch", "__version__", *_MODULES]
