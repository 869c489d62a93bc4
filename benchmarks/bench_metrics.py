"""Wrinkle-metric timings: curvature and tool distance for a fabric mesh against a triangle tool.

Full size: a 245 x 245 quad fabric (60 025 nodes, 1 mm elements) draped over the hemisphere rig
with wrinkles, against a ~20 000-face mesh of the rig. The host-side tables (curvature stencil, tool
index) are built once at the edge, outside the timings. Timings after compilation (best of 3),
plus the first call (compile).
"""
from __future__ import annotations

import time

import numpy as np


def _fabric(n: int):
    s = np.linspace(-0.12, 0.12, n)
    X, Y = np.meshgrid(s, s, indexing="ij")
    r = np.hypot(X, Y)
    Z = np.sqrt(np.maximum(0.05**2 - r**2, 0.0)) + 0.15e-3
    Z = Z + 0.001 * np.sin(2 * np.pi * r / 0.01) * np.exp(-((r - 0.07) / 0.015) ** 2)
    i, j = np.meshgrid(np.arange(n - 1), np.arange(n - 1), indexing="ij")
    a = (i * n + j).ravel()
    faces = np.stack([a, a + n, a + n + 1, a + 1], axis=1)
    return np.stack([X, Y, Z], -1).reshape(-1, 3), faces


def _time(fn, repeat=3):
    t0 = time.perf_counter()
    fn()
    first = time.perf_counter() - t0
    best = min(_timed(fn) for _ in range(repeat))
    return first, best


def _timed(fn):
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def run(quick: bool) -> dict:
    import jax

    jax.config.update("jax_enable_x64", True)
    from jaxform.io.tool_mesh import hemisphere_rig_mesh
    from jaxform.metrics import build_tool_index, curvature_stencil, curvatures_from_stencil, tool_distance

    n = 61 if quick else 245
    nodes, faces = _fabric(n)
    tv, tf = hemisphere_rig_mesh(size=0.006 if quick else 0.002)
    index = build_tool_index(tv, tf)
    stencil = curvature_stencil(faces, len(nodes))  # host-side tables, built once at the edge
    curv_first, curv = _time(lambda: jax.block_until_ready(curvatures_from_stencil(nodes, stencil)))
    dist_first, dist = _time(lambda: jax.block_until_ready(tool_distance(nodes, index)))
    return {
        "n_nodes": int(len(nodes)),
        "n_tool_faces": int(len(tf)),
        "dtype": "float64",
        "curvature_s": curv,
        "curvature_first_call_s": curv_first,
        "distance_s": dist,
        "distance_first_call_s": dist_first,
        "curvature_plus_distance_s": curv + dist,
    }
