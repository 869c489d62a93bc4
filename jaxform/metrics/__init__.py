"""The wrinkle metric of the source paper (section 3.2, appendix B) as pure JAX functions.

- :func:`tool_distance`: exact unsigned distance from fabric nodes to a tool surface (a triangle
  mesh or an analytic tool such as :class:`HemisphereRig`).
- :func:`principal_curvatures`: nodal principal curvatures by iterative quadric fitting (B.1-B.9);
  :func:`kappa_max` (eq. 2).
"""
from jaxform.metrics.curvature import (
    CurvatureStencil,
    MeshWarning,
    curvature_stencil,
    curvatures_from_stencil,
    kappa_max,
    principal_curvatures,
)
from jaxform.metrics.distance import (
    HemisphereRig,
    PlaneTool,
    ToolIndex,
    ToolWarning,
    build_tool_index,
    tool_distance,
)

__all__ = [
    "CurvatureStencil",
    "MeshWarning",
    "curvature_stencil",
    "curvatures_from_stencil",
    "kappa_max",
    "principal_curvatures",
    "HemisphereRig",
    "PlaneTool",
    "ToolIndex",
    "ToolWarning",
    "build_tool_index",
    "tool_distance",
]
