"""The wrinkle metric of the source paper (section 3.2, appendix B) as pure JAX functions.

- :func:`tool_distance`: exact unsigned distance from fabric nodes to a tool surface (a triangle
  mesh or an analytic tool such as :class:`HemisphereRig`).
"""
from jaxform.metrics.distance import (
    HemisphereRig,
    PlaneTool,
    ToolIndex,
    ToolWarning,
    build_tool_index,
    tool_distance,
)

__all__ = [
    "HemisphereRig",
    "PlaneTool",
    "ToolIndex",
    "ToolWarning",
    "build_tool_index",
    "tool_distance",
]
