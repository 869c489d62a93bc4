"""Rigid forming tools as pure JAX signed distance functions, and their prescribed motion.

Rig orientation (the paper's Nottingham hemisphere rig, section 2.3 and Figure 14): ``z`` up,
gravity along ``-z``. The fabric stack lies flat on the **die** (the "bottom blank holder", a plate
whose top face is at ``z = 0`` with a round opening and a filleted entry edge). The **blank holder**
(the top plate, also with a round opening) sits above the stack, either at a fixed height (gap
mode) or resting on it under a clamping force (force mode: its height is a state variable, see
:func:`jaxform.contact.holder_step`). The **punch** (a hemisphere of radius ``R``, apex down, on a
cylindrical shank of the same radius going up) starts above the stack with its apex on the upper
surface of the fabric ("stroke measured from the initial point of contact with the upper surface")
and moves **down**, drawing the fabric through the die opening.

Every tool is a pytree: geometric parameters and the motion's parameters are leaves (so
``jax.grad`` reaches e.g. the punch radius), kinds are classes. A tool's geometry is given in its
*reference pose*; the only motion is a vertical translation ``dz`` (m) of the whole tool.

``sdf(tool, points, dz)`` returns ``(phi, normal)`` for points ``(N, 3)`` (m):

* ``phi`` (N,), m: signed distance to the tool surface, **positive outside the tool material**,
  negative inside;
* ``normal`` (N, 3): outward unit normal (the gradient of ``phi``), finite everywhere: at
  degenerate points (on a symmetry axis deep inside the tool) it falls back to ``+z``.

The analytic shapes are *exact* signed distance fields (so the penalty force ``k * max(-phi, 0) *
normal`` is the gradient of a potential): the die and the holder are half-infinite strips in the
``(r, z)`` half-plane dilated by their edge radius (which rounds both inner edges of the plate: the
die's entry fillet, and its exit edge with the same radius, which the fabric never reaches).

Triangle-mesh tools are sampled once, host side, into a :class:`GridSDF` (see
:mod:`jaxform.io.tool_mesh`), evaluated here by trilinear interpolation.

Safe norms and the point–triangle routine live in :mod:`jaxform.geometry` (``safe_norm``,
``safe_normalize`` and ``closest_point_triangle`` are re-exported here for old imports).
"""
from __future__ import annotations

import math
from typing import Any

import jax
import jax.numpy as jnp
import numpy as np

from jaxform import validate
from jaxform._pytree import as_leaf, is_concrete, pytree_dataclass, static_field
from jaxform.geometry import EZ as _EZ
from jaxform.geometry import closest_point_triangle, safe_norm, safe_normalize  # noqa: F401  (re-exported)
from jaxform.revolved import hemisphere_on_shank, radial, revolved_normal, rounded_halfstrip


# ---------------------------------------------------------------------------------------------
# Motion
# ---------------------------------------------------------------------------------------------


@pytree_dataclass
class VerticalMotion:
    """Prescribed vertical translation of a tool.

    The speed ramps up linearly over ``ramp_time`` (so the displacement is C1 and the fabric is not
    hit by a velocity jump), then stays at ``velocity`` until the displacement reaches ``stroke``,
    where the tool stops.

    Attributes:
        velocity: signed vertical speed after the ramp, m/s (negative: moving down).
        ramp_time: duration of the linear speed ramp, s (0: none).
        stroke: largest displacement magnitude, m (``inf``: no limit).
    """

    velocity: Any = 0.0
    ramp_time: Any = 0.0
    stroke: Any = math.inf

    def __post_init__(self):
        if is_concrete(self.velocity, self.ramp_time, self.stroke):
            validate.finite("VerticalMotion", "velocity", self.velocity, "m/s")
            validate.nonnegative("VerticalMotion", "ramp_time", self.ramp_time, "s")
            if not (float(self.stroke) > 0):
                raise ValueError(f"VerticalMotion.stroke = {self.stroke!r}: must be > 0 (m), or inf")
            for n in ("velocity", "ramp_time", "stroke"):
                object.__setattr__(self, n, as_leaf(getattr(self, n)))

    def _travel(self, t):
        """Distance travelled at full speed equivalent, ``s(t)`` in s, and ``ds/dt`` (-)."""
        t = jnp.maximum(jnp.asarray(t), 0.0)
        T = jnp.asarray(self.ramp_time)
        Ts = jnp.where(T > 0, T, 1.0)
        in_ramp = t < T
        s = jnp.where(in_ramp, 0.5 * t * t / Ts, t - 0.5 * T)
        ds = jnp.where(in_ramp, t / Ts, 1.0)
        return s, ds

    def displacement(self, t):
        """Vertical displacement ``dz(t)`` from the reference pose, m (scalar)."""
        s, _ = self._travel(t)
        u = jnp.abs(self.velocity) * s
        return jnp.sign(self.velocity) * jnp.minimum(u, self.stroke)

    def speed(self, t):
        """Vertical velocity ``d dz / dt`` at time ``t``, m/s (scalar); zero once the stroke is done."""
        s, ds = self._travel(t)
        moving = jnp.abs(self.velocity) * s < self.stroke
        return jnp.where(moving, self.velocity * ds, 0.0)

    def time_to_stroke(self) -> float:
        """Host-side: the time at which the stroke is completed, s (concrete parameters only)."""
        v, T, L = abs(float(self.velocity)), float(self.ramp_time), float(self.stroke)
        if v == 0 or not math.isfinite(L):
            return math.inf
        if L <= 0.5 * v * T:
            return math.sqrt(2 * L * T / v)
        return L / v + 0.5 * T


STILL = VerticalMotion(0.0, 0.0, math.inf)
"""A tool that does not move."""


# ---------------------------------------------------------------------------------------------
# Analytic shapes (reference pose); each has ``phi_local(p)`` for one point (3,) -> scalar, m.
# ---------------------------------------------------------------------------------------------


@pytree_dataclass
class Punch:
    """Hemispherical punch, apex down, on a cylindrical shank of the same radius going up (to +inf).

    With ``apex_up`` the shape is mirrored about ``z = apex_z``: apex up, shank going down (a male
    mould seen from the formed part, as in the wrinkle metric's hemisphere rig,
    :func:`hemisphere_rig`).

    Attributes:
        radius: hemisphere and shank radius ``R``, m (SPEC default 50 mm).
        apex_z: height of the apex in the reference pose, m.
        motion: :class:`VerticalMotion` (punch travel; negative velocity pushes the fabric down).
        apex_up: mirror the punch (static; default False: apex down, the forming rig).
        axis_xy: (2,) position of the punch axis in the xy plane, m (default ``None``: the z axis).
    """

    radius: Any
    apex_z: Any = 0.0
    motion: Any = STILL
    apex_up: bool = static_field(default=False)
    axis_xy: Any = None

    def __post_init__(self):
        if is_concrete(self.radius, self.apex_z):
            validate.positive("Punch", "radius", self.radius, "m")
            validate.finite("Punch", "apex_z", self.apex_z, "m")
            object.__setattr__(self, "radius", as_leaf(self.radius))
            object.__setattr__(self, "apex_z", as_leaf(self.apex_z))
        if self.axis_xy is not None and is_concrete(self.axis_xy):
            if np.shape(self.axis_xy) != (2,):
                raise ValueError(f"Punch.axis_xy: shape {np.shape(self.axis_xy)}: need (2,) (m)")
            validate.finite("Punch", "axis_xy", self.axis_xy, "m")
            object.__setattr__(self, "axis_xy", as_leaf(self.axis_xy))

    def _distance(self, p):
        """``(phi, grad phi)`` of one point (3,) in the reference pose (:func:`~jaxform.revolved.hemisphere_on_shank`)."""
        if self.axis_xy is not None:
            axis = jnp.asarray(self.axis_xy, p.dtype)
            p = jnp.stack([p[0] - axis[0], p[1] - axis[1], p[2]])
        if self.apex_up:
            p = jnp.stack([p[0], p[1], 2.0 * self.apex_z - p[2]])
        phi, g = hemisphere_on_shank(p, self.apex_z, self.radius)
        return phi, (g * jnp.asarray([1.0, 1.0, -1.0], g.dtype) if self.apex_up else g)

    def phi_local(self, p):
        """Signed distance, m, of one point (3,) in the reference pose."""
        return self._distance(p)[0]

    def phi_normal_local(self, p):
        """``(phi, outward unit normal)`` of one point (3,), the gradient in closed form."""
        phi, g = self._distance(p)
        return phi, safe_normalize(g)


@pytree_dataclass
class Die:
    """Die (bottom blank holder): a plate below the fabric with a round opening and entry fillet.

    The plate occupies ``top_z - thickness <= z <= top_z`` for ``r >= opening_radius`` and extends
    to infinity radially; the edge between its top face and the bore is rounded with
    ``fillet_radius`` (so is the lower edge of the bore).

    Attributes:
        opening_radius: bore radius ``R_d``, m (SPEC default 53 mm).
        fillet_radius: entry fillet radius ``r_f``, m (default 6 mm); ``< thickness / 2``.
        thickness: plate thickness, m.
        top_z: height of the top face in the reference pose, m.
        motion: :class:`VerticalMotion` (normally :data:`STILL`).
    """

    opening_radius: Any
    fillet_radius: Any
    thickness: Any = 0.02
    top_z: Any = 0.0
    motion: Any = STILL

    def __post_init__(self):
        if is_concrete(self.opening_radius, self.fillet_radius, self.thickness, self.top_z):
            _check_plate("Die", self.opening_radius, self.fillet_radius, self.thickness, "fillet_radius")
            validate.finite("Die", "top_z", self.top_z, "m")
            for n in ("opening_radius", "fillet_radius", "thickness", "top_z"):
                object.__setattr__(self, n, as_leaf(getattr(self, n)))

    def _distance(self, p):
        return rounded_halfstrip(radial(p), p[2], self.opening_radius, self.top_z - self.thickness, self.top_z,
                                 self.fillet_radius)

    def phi_local(self, p):
        """Signed distance, m, of one point (3,) in the reference pose."""
        return self._distance(p)[0]

    def phi_normal_local(self, p):
        """``(phi, outward unit normal)`` of one point (3,), the gradient in closed form."""
        return revolved_normal(p, *self._distance(p))


@pytree_dataclass
class BlankHolder:
    """Blank holder (top plate): above the fabric, with a round opening and rounded edges.

    The plate occupies ``bottom_z <= z <= bottom_z + thickness`` for ``r >= opening_radius``.

    Attributes:
        opening_radius: opening radius, m (SPEC default 53 mm).
        edge_radius: radius of the rounded opening edges, m; ``< thickness / 2``.
        thickness: plate thickness, m.
        bottom_z: height of its lower face in the reference pose, m.
        motion: :class:`VerticalMotion` (gap mode: :data:`STILL`; in force mode the displacement
            is a state variable instead, :class:`jaxform.contact.HolderState`).
    """

    opening_radius: Any
    edge_radius: Any = 0.001
    thickness: Any = 0.02
    bottom_z: Any = 0.0
    motion: Any = STILL

    def __post_init__(self):
        if is_concrete(self.opening_radius, self.edge_radius, self.thickness, self.bottom_z):
            _check_plate("BlankHolder", self.opening_radius, self.edge_radius, self.thickness, "edge_radius")
            validate.finite("BlankHolder", "bottom_z", self.bottom_z, "m")
            for n in ("opening_radius", "edge_radius", "thickness", "bottom_z"):
                object.__setattr__(self, n, as_leaf(getattr(self, n)))

    def _distance(self, p):
        return rounded_halfstrip(radial(p), p[2], self.opening_radius, self.bottom_z, self.bottom_z + self.thickness,
                                 self.edge_radius)

    def phi_local(self, p):
        """Signed distance, m, of one point (3,) in the reference pose."""
        return self._distance(p)[0]

    def phi_normal_local(self, p):
        """``(phi, outward unit normal)`` of one point (3,), the gradient in closed form."""
        return revolved_normal(p, *self._distance(p))


def _check_plate(owner, opening, radius, thickness, radius_name):
    validate.positive(owner, "opening_radius", opening, "m")
    validate.positive(owner, radius_name, radius, "m")
    validate.positive(owner, "thickness", thickness, "m")
    if not float(radius) < 0.5 * float(thickness):
        raise ValueError(
            f"{owner}.{radius_name} = {float(radius)!r} m: must be < thickness / 2 = {0.5 * float(thickness)!r} m"
        )


@pytree_dataclass
class Plane:
    """A rigid half-space: material on the side opposite to ``normal`` of the plane through ``point``.

    Used for patch tests (a flat or tilted plate). ``normal`` need not be unit length.

    Attributes:
        point: (3,) a point of the plane, m.
        normal: (3,) outward normal (pointing away from the material), -.
        motion: :class:`VerticalMotion`.
    """

    point: Any
    normal: Any = _EZ
    motion: Any = STILL

    def __post_init__(self):
        if is_concrete(self.point, self.normal):
            validate.finite("Plane", "point", self.point, "m")
            validate.finite("Plane", "normal", self.normal)
            if np.shape(self.point) != (3,) or np.shape(self.normal) != (3,):
                raise ValueError("Plane.point and Plane.normal must have shape (3,)")
            if not np.linalg.norm(np.asarray(self.normal, dtype=float)) > 0:
                raise ValueError(f"Plane.normal = {self.normal!r}: must be non-zero")
            n = np.asarray(self.normal, dtype=float)
            object.__setattr__(self, "normal", n / np.linalg.norm(n))
            object.__setattr__(self, "point", np.asarray(self.point, dtype=float))

    def phi_local(self, p):
        """Signed distance, m, of one point (3,) in the reference pose."""
        n = jnp.asarray(self.normal)
        return jnp.dot(p - jnp.asarray(self.point), n / safe_norm(n))


# ---------------------------------------------------------------------------------------------
# Grid-sampled distance field (mesh-derived tools)
# ---------------------------------------------------------------------------------------------


@pytree_dataclass
class GridSDF:
    """A signed distance field sampled on a regular grid, evaluated by trilinear interpolation.

    Built from a triangle mesh by :func:`jaxform.io.tool_mesh.grid_sdf_from_mesh` (host side).
    Inside the grid ``phi`` is the trilinear interpolant of the samples (differentiable, exact at
    the nodes) and ``normal`` the normalised trilinear interpolant of the sampled gradient (a
    continuous field, unlike the piecewise gradient of the ``phi`` interpolant). Outside the grid a
    point is clamped to the box and the distance to the box is added (an upper bound of the true
    distance: choose a padding larger than any contact distance).

    Attributes:
        phi: (nx, ny, nz) signed distance samples, m (positive outside the material).
        grad: (nx, ny, nz, 3) unit gradient samples (outward normal), -.
        origin: (3,) position of sample ``[0, 0, 0]``, m.
        spacing: (3,) grid step along x, y, z, m.
        motion: :class:`VerticalMotion`.
    """

    phi: Any
    grad: Any
    origin: Any
    spacing: Any
    motion: Any = STILL

    def __post_init__(self):
        if is_concrete(self.phi, self.grad, self.origin, self.spacing):
            phi = np.asarray(self.phi)
            if phi.ndim != 3 or min(phi.shape) < 2:
                raise ValueError(f"GridSDF.phi: shape {phi.shape}: need (nx, ny, nz) with every size >= 2")
            if np.shape(self.grad) != phi.shape + (3,):
                raise ValueError(f"GridSDF.grad: shape {np.shape(self.grad)}: need {phi.shape + (3,)}")
            validate.finite("GridSDF", "phi", phi, "m")
            validate.finite("GridSDF", "origin", self.origin, "m")
            validate.positive("GridSDF", "spacing", self.spacing, "m")
            if np.shape(self.origin) != (3,) or np.shape(self.spacing) != (3,):
                raise ValueError("GridSDF.origin and GridSDF.spacing must have shape (3,)")

    def _corners(self, p):
        phi = jnp.asarray(self.phi)
        shape = jnp.asarray(phi.shape, dtype=p.dtype)
        lo = jnp.asarray(self.origin, dtype=p.dtype)
        h = jnp.asarray(self.spacing, dtype=p.dtype)
        hi = lo + (shape - 1) * h
        pc = jnp.clip(p, lo, hi)
        u = (pc - lo) / h
        i0 = jnp.clip(jnp.floor(u), 0, shape - 2).astype(jnp.int32)
        f = u - i0
        outside = safe_norm(p - pc)
        return i0, f, outside

    @staticmethod
    def _trilinear(field, i0, f):
        out = 0.0
        for a in (0, 1):
            wx = f[0] if a else 1.0 - f[0]
            for b in (0, 1):
                wy = f[1] if b else 1.0 - f[1]
                for c in (0, 1):
                    wz = f[2] if c else 1.0 - f[2]
                    out = out + wx * wy * wz * field[i0[0] + a, i0[1] + b, i0[2] + c]
        return out

    def phi_local(self, p):
        """Signed distance, m, of one point (3,) in the reference pose."""
        i0, f, outside = self._corners(p)
        return self._trilinear(jnp.asarray(self.phi), i0, f) + outside

    def phi_normal_local(self, p):
        """``(phi, normal)`` of one point (3,): interpolated distance and sampled-gradient normal."""
        i0, f, outside = self._corners(p)
        phi = self._trilinear(jnp.asarray(self.phi), i0, f) + outside
        g = self._trilinear(jnp.asarray(self.grad), i0, f)
        return phi, safe_normalize(g)


# ---------------------------------------------------------------------------------------------
# Evaluation
# ---------------------------------------------------------------------------------------------


def _phi_normal_one(tool, p):
    if hasattr(tool, "phi_normal_local"):  # closed-form (the punch and plates) or sampled (GridSDF) normals
        return tool.phi_normal_local(p)
    phi, g = jax.value_and_grad(tool.phi_local)(p)
    return phi, safe_normalize(g)


def sdf(tool, points, dz=0.0):
    """Signed distance and outward normal of ``points`` to ``tool`` displaced vertically by ``dz``.

    Args:
        tool: a tool pytree (:class:`Punch`, :class:`Die`, :class:`BlankHolder`, :class:`Plane`,
            :class:`GridSDF`).
        points: (N, 3) positions, m.
        dz: vertical displacement of the tool from its reference pose, m (scalar); use
            :func:`displacement` for prescribed motion or the holder state in force mode.

    Returns:
        ``(phi, normal)``: (N,) signed distance, m, positive outside the material; (N, 3) outward
        unit normal (finite everywhere; ``+z`` at degenerate points).
    """
    phi, normal = sdf_soa(tool, jnp.asarray(points).T, dz)
    return phi, normal.T


def sdf_soa(tool, points, dz=0.0):
    """:func:`sdf` of points in structure of arrays: ``points`` (3, N) m -> ``(phi (N,) m, normal
    (3, N))``. The contact kernels' layout: each point's coordinates are rows, so the per-point
    shape functions run on contiguous (N,) vectors (a trailing axis of 3 does not vectorise on CPU)."""
    points = jnp.asarray(points)
    shift = jnp.zeros(3, points.dtype).at[2].set(jnp.asarray(dz, points.dtype))
    return jax.vmap(lambda p: _phi_normal_one(tool, p - shift), in_axes=1, out_axes=(0, 1))(points)


def union_sdf(tools, points, dz=0.0):
    """Signed distance and outward normal of ``points`` to the union of several tools.

    ``phi = min_i phi_i`` (the normal of the nearest tool): exact outside every tool and inside
    a single one; where tools overlap it is a bound (the distance to the nearer tool's surface).
    The unsigned distance to the rig's surface is ``|phi|``.

    Args:
        tools: a sequence of tool pytrees (see :func:`sdf`), or one tool.
        points: (N, 3) positions, m.
        dz: vertical displacement of all the tools, m (scalar).

    Returns:
        ``(phi, normal)``: (N,) m; (N, 3) unit.
    """
    if not isinstance(tools, (tuple, list)):
        return sdf(tools, points, dz)
    phis, normals = zip(*(sdf(t, points, dz) for t in tools))
    phi = jnp.stack(phis)  # (T, N)
    j = jnp.argmin(phi, axis=0)
    normal = jnp.take_along_axis(jnp.stack(normals), j[None, :, None], axis=0)[0]
    return jnp.min(phi, axis=0), normal


def hemisphere_rig(radius=0.05, center=(0.0, 0.0, 0.0), base_plane: bool = True) -> tuple:
    """The wrinkle metric's hemisphere rig: a hemisphere, apex up, standing on a flat base plane.

    The surface is the upper half-sphere ``|x - c| = R, z >= c_z`` and (with ``base_plane``) the
    plane ``z = c_z`` outside the circle of radius ``R``: the paper's punch seen from the formed
    part. Without the base plane the hemisphere continues downwards as the punch's shank.

    Args:
        radius: hemisphere radius ``R``, m (default 50 mm).
        center: (3,) centre of the sphere, on the base plane, m.
        base_plane: include the flat base plane.

    Returns:
        A tuple of tools for :func:`union_sdf`: ``(Punch(apex up), Plane)`` or ``(Punch,)``.
    """
    c = center if isinstance(center, (tuple, list)) else jnp.asarray(center)
    punch = Punch(radius, apex_z=c[2] + radius, apex_up=True, axis_xy=(c[0], c[1]))
    if not base_plane:
        return (punch,)
    return (punch, Plane(point=c, normal=_EZ))


def displacement(tool, t):
    """Prescribed vertical displacement of ``tool`` at time ``t``, m (scalar)."""
    return tool.motion.displacement(t)


def velocity(tool, t):
    """Prescribed velocity of ``tool`` at time ``t``, (3,) m/s (vertical translation only)."""
    vz = tool.motion.speed(t)
    return jnp.stack([0.0 * vz, 0.0 * vz, vz])


@pytree_dataclass
class FormingTools:
    """The hemisphere rig's three tools (built by :func:`jaxform.cases.build_tools`).

    Attributes:
        punch: :class:`Punch` (or a :class:`GridSDF` from a mesh), moving down.
        die: :class:`Die`, fixed, below the stack.
        holder: :class:`BlankHolder` above the stack (fixed in gap mode; in force mode its
            vertical displacement is the state :class:`jaxform.contact.HolderState`).
    """

    punch: Any
    die: Any
    holder: Any


__all__ = [
    "VerticalMotion",
    "STILL",
    "Punch",
    "Die",
    "BlankHolder",
    "Plane",
    "GridSDF",
    "FormingTools",
    "sdf",
    "sdf_soa",
    "union_sdf",
    "hemisphere_rig",
    "displacement",
    "velocity",
    "safe_norm",
    "safe_normalize",
    "closest_point_triangle",
]
