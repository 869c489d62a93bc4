"""The wrinkle metric of the source paper (section 3.2, appendix B) as pure JAX functions.

- :func:`tool_distance`: exact unsigned distance from fabric nodes to a tool surface (a triangle
  mesh, its index from :func:`build_tool_index`, or tools of :mod:`jaxform.tools` such as
  :func:`jaxform.tools.hemisphere_rig`; ``HemisphereRig`` and ``PlaneTool`` are the old names of
  those tool constructors).
- :func:`principal_curvatures`: nodal principal curvatures by iterative quadric fitting (B.1-B.9);
  :func:`kappa_max` (eq. 2).
- :mod:`jaxform.metrics.wrinkles`: ``d_crit``, zones (wrinkle / bridging / conforming), wrinkle
  radius, sections and their normalised RMSE, wrinkle counts, ``M_f^RMS`` and densities.
- :func:`wrinkle_census` (:mod:`jaxform.metrics.census`): the wrinkles of a flange as an engineer
  counts them (ridges of the deviation traced across it), each with position, size and amplitude.
"""
from jaxform.metrics.curvature import (
    CurvatureStencil,
    MeshWarning,
    curvature_stencil,
    curvatures_from_stencil,
    kappa_max,
    principal_curvatures,
)
from jaxform.metrics.census import Wrinkle, wrinkle_census
from jaxform.metrics.distance import (
    HemisphereRig,
    PlaneTool,
    ToolIndex,
    ToolWarning,
    build_tool_index,
    tool_distance,
)

from jaxform.metrics.wrinkles import (
    BRIDGING,
    CONFORMING,
    WRINKLE,
    classify_zones,
    count_section_wrinkles,
    count_wrinkle_regions,
    d_crit,
    node_areas,
    probability_density,
    ring_max,
    rms_fibre_moment,
    section_nrmse,
    section_profile,
    wrinkle_radius,
    zone_areas,
)

__all__ = [
    "BRIDGING",
    "CONFORMING",
    "WRINKLE",
    "classify_zones",
    "count_section_wrinkles",
    "count_wrinkle_regions",
    "d_crit",
    "node_areas",
    "probability_density",
    "ring_max",
    "rms_fibre_moment",
    "section_nrmse",
    "section_profile",
    "wrinkle_radius",
    "zone_areas",
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
    "Wrinkle",
    "wrinkle_census",
]
