"""Unsigned distance from fabric nodes to a tool surface (paper eq. 1, SPEC section 5).

``d_P = |P - P'|`` with ``P'`` the closest point of the tool surface, which need not be a tool node.

Triangle-mesh tools
    The exact distance is a minimum over all tool triangles of the point-triangle distance. The
    search is :func:`jaxform.geometry.closest_triangle` on a host-built
    :class:`~jaxform.geometry.TriangleIndex` (clusters with bounding spheres and boxes, certified
    exact for every node; an exhaustive search when the tool arrays are traced). Build the index
    once at the edge with :func:`build_tool_index` and pass it as ``tool_vertices`` (it is a
    pytree); :func:`tool_distance` with vertex and face arrays builds it on every call.

    The search only picks *which* triangle is closest (integers); the distance itself is recomputed
    from that triangle with differentiable, safe operations, so ``jax.grad`` with respect to the node
    positions is finite everywhere (zero where a node lies exactly on the tool).

Analytic tools
    The tools of :mod:`jaxform.tools` (:class:`~jaxform.tools.Punch`, ``Die``, ``BlankHolder``,
    ``Plane``, ``GridSDF``), one or a sequence of them (e.g. :func:`jaxform.tools.hemisphere_rig`,
    the paper's hemispherical punch on a flat base plane), or a
    :class:`~jaxform.tools.FormingTools`, in their reference pose: the distance is ``|phi|`` of
    their union (:func:`jaxform.tools.union_sdf`).

Everything is pure JAX once the index exists. Under ``jit``/``vmap`` close over the tool arrays
(or the index) rather than passing them as traced arguments; with traced tool arrays
:func:`tool_distance` still works, by an exhaustive (slow, exact) search.
"""
from __future__ import annotations

import warnings

import jax
import jax.numpy as jnp
import numpy as np

from jaxform import tools as _tools
from jaxform.geometry import TriangleIndex, build_triangle_index, closest_point_on_mesh, safe_norm

__all__ = [
    "ToolIndex",
    "ToolWarning",
    "HemisphereRig",
    "PlaneTool",
    "build_tool_index",
    "tool_distance",
    "distance_to_index",
    "validate_tool",
]

ToolIndex = TriangleIndex
"""The triangle-tool index (the name kept from before :mod:`jaxform.geometry`)."""

_ANALYTIC = (_tools.Punch, _tools.Die, _tools.BlankHolder, _tools.Plane, _tools.GridSDF)


class ToolWarning(UserWarning):
    """A tool that is probably not the one intended (far from the fabric, wrong units...)."""


def validate_tool(tool_vertices, tool_faces) -> tuple[np.ndarray, np.ndarray]:
    """Check a triangle tool given by the user; return float64 vertices and int64 faces.

    Raises ValueError for an empty tool, faces that are not triangles, indices out of range, or
    non-finite coordinates. Degenerate (zero-area) triangles are allowed (they act as segments)."""
    v = np.asarray(tool_vertices, dtype=np.float64)
    f = np.asarray(tool_faces)
    if v.ndim != 2 or v.shape[1] != 3:
        raise ValueError(f"tool_vertices must have shape (V, 3), got {v.shape}")
    if f.ndim != 2 or f.shape[1] != 3:
        raise ValueError(
            f"tool_faces must be triangles with shape (F, 3), got {f.shape}; split quads first "
            "(jaxform.io.read_surface(..., triangulate=True) does)"
        )
    if f.shape[0] == 0 or v.shape[0] == 0:
        raise ValueError("the tool is empty (no triangles): nothing to measure the distance to")
    if not np.issubdtype(f.dtype, np.integer):
        raise ValueError(f"tool_faces must be integers, got dtype {f.dtype}")
    if f.min() < 0 or f.max() >= v.shape[0]:
        raise ValueError(
            f"tool_faces refer to vertices {f.min()}..{f.max()} but there are {v.shape[0]} vertices"
        )
    bad = ~np.isfinite(v).all(axis=1)
    if bad.any():
        raise ValueError(
            f"tool_vertices has {int(bad.sum())} non-finite (NaN/inf) rows, first at {int(np.argmax(bad))}"
        )
    return v, f.astype(np.int64)


def build_tool_index(tool_vertices, tool_faces, **options) -> TriangleIndex:
    """Validate a triangle tool (:func:`validate_tool`) and index it for the search (host side).

    Args:
      tool_vertices: (V, 3) tool vertex positions, m (numpy or concrete JAX array).
      tool_faces: (F, 3) triangle vertex indices, integer.
      options: search parameters of :func:`jaxform.geometry.build_triangle_index` (``cluster_size``,
        ``super_size``, ``ks``, ``k``, ``ks2``, ``k2``, ``batch``).

    Returns:
      A :class:`~jaxform.geometry.TriangleIndex` (float64; cast to the nodes' dtype at query time).
    """
    v, f = validate_tool(tool_vertices, tool_faces)
    return build_triangle_index(v, f, **options)


def distance_to_index(nodes, index: TriangleIndex):
    """Unsigned distance from nodes to an indexed triangle tool (pure JAX, exact).

    Args:
      nodes: (N, 3) node positions, m.
      index: :class:`~jaxform.geometry.TriangleIndex` from :func:`build_tool_index`.

    Returns:
      (N,) distance to the closest point of the tool surface, m. Differentiable w.r.t. ``nodes``.
    """
    nodes = _floating(nodes)
    q, _, _ = closest_point_on_mesh(nodes, index)
    return safe_norm(nodes - q)


def HemisphereRig(radius=0.05, center=(0.0, 0.0, 0.0), base_plane: bool = True) -> tuple:  # noqa: N802
    """The paper's hemisphere rig as tools: :func:`jaxform.tools.hemisphere_rig` (old name)."""
    return _tools.hemisphere_rig(radius, center, base_plane)


def PlaneTool(point=(0.0, 0.0, 0.0), normal=(0.0, 0.0, 1.0)):  # noqa: N802
    """An infinite flat tool: :class:`jaxform.tools.Plane` (old name)."""
    return _tools.Plane(point=point, normal=normal)


def _floating(x):
    x = jnp.asarray(x)
    return x if jnp.issubdtype(x.dtype, jnp.floating) else x.astype(jnp.result_type(float))


def _analytic(tool):
    """The tool(s) as a tuple of :mod:`jaxform.tools` pytrees, or None for anything else."""
    if isinstance(tool, _tools.FormingTools):
        return (tool.punch, tool.die, tool.holder)
    if isinstance(tool, _ANALYTIC):
        return (tool,)
    if isinstance(tool, (tuple, list)) and tool and all(isinstance(t, _ANALYTIC) for t in tool):
        return tuple(tool)
    return None


def _is_concrete(x) -> bool:
    return not isinstance(x, jax.core.Tracer)


def tool_distance(nodes, tool_vertices, tool_faces=None, *, check: bool = True):
    """Exact unsigned distance from each node to the closest point of a tool surface.

    Args:
      nodes: (N, 3) fabric node positions, m; numpy or JAX, float32 or float64.
      tool_vertices: (V, 3) tool triangle-mesh vertices, m; or, with ``tool_faces=None``, a
        :class:`~jaxform.geometry.TriangleIndex` (:func:`build_tool_index`) or analytic tools
        (see the module docstring).
      tool_faces: (F, 3) tool triangles, int32 or int64.
      check: when ``nodes`` are concrete, raise on non-finite nodes and warn (:class:`ToolWarning`)
        when the tool is far from every node.

    Returns:
      (N,) distance, m, in the dtype of ``nodes``. Pure JAX: jit-able and vmap-able over ``nodes``
      (close over the tool arrays, which then must be concrete), differentiable w.r.t. ``nodes``.
    """
    if check and _is_concrete(nodes):
        arr = np.asarray(nodes)
        if arr.ndim != 2 or arr.shape[-1] != 3:
            raise ValueError(f"nodes must have shape (N, 3), got {arr.shape}")
        bad = ~np.isfinite(arr).all(axis=1)
        if bad.any():
            raise ValueError(
                f"nodes has {int(bad.sum())} non-finite (NaN/inf) rows, first at index "
                f"{int(np.argmax(bad))}; fix or remove them before measuring distances"
            )
    if tool_faces is None:
        if isinstance(tool_vertices, TriangleIndex):
            d = distance_to_index(nodes, tool_vertices)
        elif (rig := _analytic(tool_vertices)) is not None:
            d = jnp.abs(_tools.union_sdf(rig, _floating(nodes))[0])
        else:
            raise ValueError("tool_faces is required when tool_vertices is an array of vertices")
    elif _is_concrete(tool_vertices) and _is_concrete(tool_faces):
        d = distance_to_index(nodes, build_tool_index(tool_vertices, tool_faces))
    else:
        # Traced tool: no host-side index possible; the exhaustive mode of the same search.
        x = _floating(nodes)
        d = distance_to_index(x, TriangleIndex(tri=jnp.asarray(tool_vertices, x.dtype)[jnp.asarray(tool_faces)]))
    if check and _is_concrete(nodes) and np.asarray(nodes).shape[0] > 0:
        _warn_if_far(np.asarray(nodes), np.asarray(d))
    return d


def _warn_if_far(nodes: np.ndarray, d: np.ndarray) -> None:
    span = float(np.linalg.norm(nodes.max(axis=0) - nodes.min(axis=0)))
    dmin = float(d.min())
    if span > 0 and dmin > 0.25 * span:
        warnings.warn(
            f"the closest fabric node is {dmin:.4g} m from the tool, more than a quarter of the "
            f"fabric's size ({span:.4g} m): wrong tool, tool offset or units (mm vs m)?",
            ToolWarning,
            stacklevel=3,
        )
