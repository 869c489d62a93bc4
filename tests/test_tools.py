"""Rigid tools: analytic signed distances and normals, motion, and the mesh-derived field."""
import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from jaxform import tools
from helpers import central_difference

R, RD, RF = 0.05, 0.053, 0.006

_sdf = jax.jit(tools.sdf)


def test_punch_distance_and_normal_at_known_points():
    punch = tools.Punch(R, apex_z=0.01)
    c = np.array([0.0, 0.0, 0.01 + R])
    pts = np.array([
        [0.0, 0.0, 0.0],            # 10 mm below the apex
        [0.0, 0.0, 0.01],           # on the apex
        c + [0.07, 0.0, 0.03],      # beside the shank: r - R = 20 mm
        c + [0.0, 0.0, 0.02],       # on the axis inside the shank (degenerate direction)
        c + 0.06 * np.array([math.sin(0.5), 0.0, -math.cos(0.5)]),  # 10 mm off the sphere
    ])
    phi, n = _sdf(punch, pts)
    np.testing.assert_allclose(phi, [0.01, 0.0, 0.02, -R, 0.01], atol=1e-12)
    np.testing.assert_allclose(n[0], [0, 0, -1], atol=1e-12)
    np.testing.assert_allclose(n[2], [1, 0, 0], atol=1e-12)
    np.testing.assert_allclose(n[3], [0, 0, 1], atol=1e-12)  # fallback at the axis
    np.testing.assert_allclose(n[4], [math.sin(0.5), 0, -math.cos(0.5)], atol=1e-12)
    # A vertical displacement shifts the field.
    phi2, _ = _sdf(punch, pts[:1], dz=-0.004)
    np.testing.assert_allclose(phi2, [0.006], atol=1e-12)


def test_die_top_face_bore_and_fillet():
    die = tools.Die(RD, RF, thickness=0.02, top_z=0.0)
    pts = np.array([
        [0.1, 0.0, 0.002],          # 2 mm above the flat top face
        [0.0, 0.04, -0.01],         # in the bore, 13 mm from its wall
        [0.1, 0.0, -0.005],         # inside the plate, 5 mm under the top face
    ])
    # Fillet: centre at r = RD + RF, z = -RF; a point along 45 degrees at 1 mm outside the arc.
    a = math.radians(45.0)
    fil = np.array([RD + RF - (RF + 0.001) * math.cos(a), 0.0, -RF + (RF + 0.001) * math.sin(a)])
    phi, n = _sdf(die, np.vstack([pts, fil]))
    np.testing.assert_allclose(phi, [0.002, 0.013, -0.005, 0.001], atol=1e-12)
    np.testing.assert_allclose(n[0], [0, 0, 1], atol=1e-12)
    np.testing.assert_allclose(n[1], [0, -1, 0], atol=1e-12)
    np.testing.assert_allclose(n[3], [-math.cos(a), 0, math.sin(a)], atol=1e-12)


def test_holder_and_plane():
    holder = tools.BlankHolder(RD, edge_radius=0.001, thickness=0.02, bottom_z=0.007)
    phi, n = _sdf(holder, np.array([[0.1, 0.0, 0.003], [0.0, 0.0, 0.01]]))
    np.testing.assert_allclose(phi, [0.004, RD], atol=1e-12)
    np.testing.assert_allclose(n[0], [0, 0, -1], atol=1e-12)
    plane = tools.Plane(point=[0.0, 0.0, 0.0], normal=[0.0, math.sin(0.3), math.cos(0.3)])
    phi, n = _sdf(plane, np.array([[0.0, 0.0, 1.0]]))
    np.testing.assert_allclose(phi, [math.cos(0.3)], atol=1e-12)
    np.testing.assert_allclose(n[0], [0.0, math.sin(0.3), math.cos(0.3)], atol=1e-12)


def test_invalid_tools_are_refused():
    with pytest.raises(ValueError, match="Punch.radius"):
        tools.Punch(-0.05)
    with pytest.raises(ValueError, match="fillet_radius"):
        tools.Die(RD, 0.015, thickness=0.02)
    with pytest.raises(ValueError, match="Plane.normal"):
        tools.Plane(point=[0.0, 0.0, 0.0], normal=[0.0, 0.0, 0.0])


def test_normals_are_unit_and_match_the_gradient_with_finite_derivatives():
    rng = np.random.default_rng(1)
    pts = rng.uniform([-0.08, -0.08, -0.03], [0.08, 0.08, 0.08], (200, 3))
    # the punch, the plates and a mirrored, shifted punch: their normals come in closed form (jaxform.revolved),
    # checked here against reverse mode through their distances
    for tool in (tools.Punch(R), tools.Die(RD, RF), tools.BlankHolder(RD, bottom_z=0.007),
                 tools.Punch(R, apex_z=0.01, apex_up=True, axis_xy=(0.01, -0.02))):
        phi, n = _sdf(tool, pts)
        np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-12)
        g = jax.vmap(jax.grad(tool.phi_local))(jnp.asarray(pts))
        np.testing.assert_allclose(g, n, atol=1e-9)
        # Exact SDF: |grad phi| = 1; finite differences agree.
        # each point moved along one axis at a time: phi is per point, so one call per axis
        fd = np.stack([central_difference(lambda p: _sdf(tool, p)[0], pts, 1e-7,
                                          direction=np.broadcast_to(np.eye(3)[k], pts.shape)) for k in range(3)], 1)
        mask = np.abs(np.asarray(phi)) > 1e-4
        np.testing.assert_allclose(fd[mask], np.asarray(n)[mask], atol=1e-5)
    # Finite gradients at degenerate points (punch axis, die axis) and w.r.t. parameters.
    degenerate = jnp.array([[0.0, 0.0, 0.08], [0.0, 0.0, -0.01]])
    for tool in (tools.Punch(R), tools.Die(RD, RF)):
        g = jax.grad(lambda p: jnp.sum(_sdf(tool, p)[0]))(degenerate)
        assert np.all(np.isfinite(g))
    gr = jax.grad(lambda r: jnp.sum(_sdf(tools.Punch(r), pts)[0]))(R)
    assert np.isfinite(gr)


def test_vertical_motion_ramp_and_stroke():
    m = tools.VerticalMotion(velocity=-0.5, ramp_time=0.01, stroke=0.05)
    assert float(m.displacement(0.0)) == 0.0
    np.testing.assert_allclose(m.displacement(0.005), -0.5 * 0.5 * 0.005**2 / 0.01)
    np.testing.assert_allclose(m.displacement(0.05), -0.5 * (0.05 - 0.005))
    np.testing.assert_allclose(m.speed(0.005), -0.25)
    np.testing.assert_allclose(m.speed(0.05), -0.5)
    t_end = m.time_to_stroke()
    np.testing.assert_allclose(t_end, 0.05 / 0.5 + 0.005)
    np.testing.assert_allclose(m.displacement(t_end + 1.0), -0.05)
    assert float(m.speed(t_end + 1.0)) == 0.0
    # The speed is the derivative of the displacement.
    ts = np.array([0.003, 0.02, 0.07])
    np.testing.assert_allclose(jax.vmap(jax.grad(m.displacement))(ts), jax.vmap(m.speed)(ts), atol=1e-12)
    punch = tools.Punch(R, motion=m)
    np.testing.assert_allclose(tools.velocity(punch, 0.02), [0, 0, -0.5])
    np.testing.assert_allclose(tools.displacement(punch, 0.02), m.displacement(0.02))


def test_closest_point_triangle_regions():
    a, b, c = jnp.array([0.0, 0, 0]), jnp.array([1.0, 0, 0]), jnp.array([0.0, 1, 0])
    cases = {
        (0.2, 0.2, 0.5): ([0.2, 0.2, 0.0], [0.6, 0.2, 0.2]),   # face
        (-1.0, -1.0, 0.0): ([0.0, 0.0, 0.0], [1, 0, 0]),       # vertex a
        (0.5, -1.0, 0.3): ([0.5, 0.0, 0.0], [0.5, 0.5, 0]),     # edge ab
        (1.0, 1.0, 0.0): ([0.5, 0.5, 0.0], [0, 0.5, 0.5]),      # edge bc
        (2.0, -0.1, 0.0): ([1.0, 0.0, 0.0], [0, 1, 0]),         # vertex b
    }
    for p, (q_ref, w_ref) in cases.items():
        q, w = tools.closest_point_triangle(jnp.array(p), a, b, c)
        np.testing.assert_allclose(q, q_ref, atol=1e-12)
        np.testing.assert_allclose(w, w_ref, atol=1e-12)


def test_grid_sdf_trilinear_exact_for_linear_field_and_outside_box():
    x = np.linspace(0, 1, 5)
    X, Y, Z = np.meshgrid(x, x, x, indexing="ij")
    phi = Z - 0.3
    grad = np.zeros(phi.shape + (3,))
    grad[..., 2] = 1.0
    g = tools.GridSDF(phi=phi, grad=grad, origin=np.zeros(3), spacing=np.full(3, 0.25))
    pts = np.array([[0.13, 0.77, 0.41], [0.5, 0.5, 1.5]])
    p, n = _sdf(g, pts)
    np.testing.assert_allclose(p, [0.11, 0.7 + 0.5], atol=1e-12)
    np.testing.assert_allclose(n, [[0, 0, 1], [0, 0, 1]], atol=1e-12)
    dg = jax.grad(lambda q: jnp.sum(_sdf(g, q)[0]))(jnp.asarray(pts))
    assert np.all(np.isfinite(dg))


def test_mesh_derived_hemisphere_matches_analytic_punch():
    """A capsule mesh (hemisphere + shank) sampled on 4 mm cells vs the analytic punch.

    Tolerance near the surface (|phi| < 2 cells): the mesh's chordal error R (1 - cos(pi/n)) plus
    the trilinear interpolation error, bounded by cell^2 / (2 R): 0.06 + 0.16 = 0.22 mm here.
    """
    import trimesh
    from jaxform.io import tool_mesh

    n_seg, cell = 64, 0.004
    mesh = trimesh.creation.capsule(height=0.1, radius=R, count=[n_seg, n_seg])
    mesh.apply_translation([0.0, 0.0, -mesh.bounds[0, 2]])  # apex at z = 0
    v, f = tool_mesh.mesh_arrays(mesh)
    grid = tool_mesh.grid_sdf_from_mesh(v, f, cell=cell, lo=[-0.06, -0.06, -0.008], hi=[0.06, 0.06, 0.06])
    rng = np.random.default_rng(0)
    pts = rng.uniform([-0.06, -0.06, -0.008], [0.06, 0.06, 0.06], (5000, 3))
    pa, na = _sdf(tools.Punch(R), pts)
    pg, ng = _sdf(grid, pts)
    pa, pg, na, ng = map(np.asarray, (pa, pg, na, ng))
    near = np.abs(pa) < 2 * cell
    tol = R * (1 - math.cos(math.pi / n_seg)) + cell**2 / (2 * R)
    err = np.abs(pa - pg)
    assert err[near].max() < tol, (err[near].max(), tol)
    # Far from the surface the only larger error is the interpolation across the medial axis
    # (the punch axis, where the field has a kink): below half a cell; signs are right everywhere.
    assert err.max() < 0.5 * cell
    assert np.min(np.sum(na * ng, axis=1)[near]) > 0.99  # normals within 8 degrees
    # Differentiable w.r.t. the points.
    dg = jax.grad(lambda q: jnp.sum(_sdf(grid, q)[0]))(jnp.asarray(pts[:50]))
    assert np.all(np.isfinite(dg))


def test_tool_mesh_file_roundtrip_and_validation(tmp_path):
    import trimesh
    from jaxform.io import tool_mesh

    box = trimesh.creation.box(extents=[100.0, 100.0, 20.0])  # mm
    path = tmp_path / "plate.stl"
    box.export(path)
    v, f = tool_mesh.load_tool_mesh(path, units="mm")
    np.testing.assert_allclose(np.ptp(v, axis=0), [0.1, 0.1, 0.02])
    g = tool_mesh.load_tool_sdf(path, cell=0.005, units="mm")
    phi, n = _sdf(g, np.array([[0.0, 0.0, 0.013], [0.0, 0.0, 0.0]]))
    np.testing.assert_allclose(phi, [0.003, -0.01], atol=1e-9)
    np.testing.assert_allclose(n[0], [0, 0, 1], atol=1e-9)
    with pytest.raises(ValueError, match="units"):
        tool_mesh.load_tool_mesh(path, units="furlong")
    with pytest.raises(ValueError, match="wrong units"):
        tool_mesh.load_tool_mesh(path, units="m")  # 100 m plate
    with pytest.raises(FileNotFoundError):
        tool_mesh.load_tool_mesh(tmp_path / "missing.stl")
    open_mesh = trimesh.Trimesh(box.vertices, box.faces[:-2])
    open_mesh.export(tmp_path / "open.stl")
    with pytest.raises(ValueError, match="watertight"):
        tool_mesh.load_tool_mesh(tmp_path / "open.stl")
