"""Self-contact and the cell-grid contact search (issue 19): the grid finds the triangle brute
force finds; a fold lying on itself closer than h is pushed apart, two-sided, momentum-free;
edge against edge catches the crossing of two kinks whose nodes are all far from the other
layer (forces the gradient of the energy, momentum kept); ordinary bending and a flat sheet are
not contact; the rig wires it by default."""
import dataclasses

import numpy as np
import jax
import jax.numpy as jnp
import pytest

from jaxform import broadphase, cases, contact, penalty
from jaxform.geometry import closest_points_segments, point_triangle_sqdist
from jaxform.metrics.intersections import triangulate
from jaxform.self_contact import SelfContactLoad, edge_contact, mesh_edges, near_edges, self_contact_load
from test_intersections import folded_strip

H = 4e-4
_ply_contact = jax.jit(contact.ply_contact)  # op by op, each operation would compile on its own
# the load as an argument: loads of one shape and room share one compiled program
_force = jax.jit(lambda load, x, v, t, st: load.force(x, v, t, st))


def _wavy_ply(n, size, z0, amp, phase):
    s = np.linspace(0.0, size, n)
    X, Y = np.meshgrid(s, s, indexing="ij")
    Z = z0 + amp * np.sin(2 * np.pi * X / size + phase) * np.cos(2 * np.pi * Y / size)
    idx = np.arange(n * n).reshape(n, n)
    q = np.column_stack([idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()])
    return np.column_stack([X.ravel(), Y.ravel(), Z.ravel()]), triangulate(q)[0]


def test_grid_search_finds_the_brute_force_nearest_triangle():
    lower, tri = _wavy_ply(17, 0.03, 0.0, 1.5e-3, 0.0)
    upper, _ = _wavy_ply(13, 0.028, H, 1.5e-3, 0.3)
    upper[:, :2] += 0.001
    x = jnp.asarray(np.vstack([lower, upper]))
    slave = np.arange(len(lower), len(lower) + len(upper))
    load = contact.PlyLoad(slave=slave, triangles=jnp.asarray(tri, jnp.int32), gap0=H, area=1e-6,
                           params=contact.ContactParams(stiffness=1e10, friction=0.36), skin=2 * H)
    cand = jax.jit(load.search)(x)
    p = np.asarray(x)[slave]
    t = np.asarray(x)[tri]
    d2_all = np.asarray(point_triangle_sqdist(p[:, None], t[None, :, 0], t[None, :, 1], t[None, :, 2]))
    cand = np.asarray(cand)
    d2_cand = np.take_along_axis(d2_all, cand, axis=1)
    reach = 3 * H  # gap0 + skin: every triangle within it is looked at
    near = d2_all.min(axis=1) < reach**2
    assert near.sum() > 0.5 * len(slave)
    # the same closest distance (ties between the two halves of a quad pick either half)
    np.testing.assert_allclose(d2_cand.min(axis=1)[near], d2_all.min(axis=1)[near], rtol=1e-5)
    # the O(N F) search it replaces agrees
    old = np.asarray(contact.nearest_faces(x, slave, tri, 8))
    np.testing.assert_allclose(np.take_along_axis(d2_all, old, 1).min(1)[near], d2_all.min(axis=1)[near], rtol=1e-5)


def test_grid_reads_a_crowded_cell_in_full():
    """50 triangles in one cell, read 4 per page: the 8 nearest are those of a brute-force sort."""
    pts = jnp.zeros((1, 3))
    tri_x = jnp.asarray(np.random.default_rng(1).normal(0, 1e-4, (50, 3, 3)))
    ids, found = jax.jit(lambda p, t: broadphase.candidates(p, t, 8, 1e-3, cap=4))(pts, tri_x)
    d2 = np.sum(np.asarray(tri_x).mean(axis=1) ** 2, axis=1)
    assert bool(found.all())
    np.testing.assert_array_equal(np.asarray(ids)[0], np.argsort(d2)[:8])


def test_refresh_criterion_bounds_every_pair_and_ignores_a_shared_motion():
    """:func:`broadphase.moved_beyond` with ``s``: while it says no, no two points (hence no node
    and point of a triangle, a convex combination) have closed or parted by more than ``2 s``;
    a translation of everything (a sagging blank) is no motion, the same motion with one point
    staying behind is."""
    rng = np.random.default_rng(3)
    x0 = rng.uniform(0.0, 0.1, (300, 3))
    pair = lambda x: np.linalg.norm(x[:, None] - x[None], axis=-1)  # noqa: E731
    moved = jax.jit(broadphase.moved_beyond)
    s = 1e-3
    checked = 0
    for _ in range(200):
        d = rng.normal(0.0, 1.0, (1, 3)) * 5e-3 + rng.normal(0.0, rng.uniform(1e-4, 1e-3), (300, 3))
        x = x0 + d
        if not bool(moved(x, x0, s)):
            checked += 1
            assert np.max(np.abs(pair(x) - pair(x0))) <= 2 * s * (1 + 1e-9)
    assert checked > 20
    shift = np.array([0.02, -0.01, -0.05])  # 54 mm, 50 times s
    assert not bool(moved(x0 + shift, x0, s))
    behind = np.tile(shift, (300, 1))
    behind[7] = 0.0
    assert bool(moved(x0 + behind, x0, s))


def _fold(gap, ns=41, ny=7):
    """A strip folded over itself (layers ``gap`` apart) and its flat reference."""
    nodes, t, layer = folded_strip(gap, length=0.02, width=0.006, ns=ns, ny=ny, quads=False)
    seg = np.linalg.norm(np.diff(nodes[::ny][:, [0, 2]], axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    x0 = np.column_stack([np.repeat(s, ny), nodes[:, 1], np.zeros(len(nodes))])
    return nodes, x0, t


def _load(x0, t, **kw):
    params = contact.ContactParams(stiffness=1e10, friction=0.36)
    return self_contact_load(x0, t, np.full(len(x0), 1e-6), np.zeros(len(x0), int), H, params, **kw)


def test_fold_closer_than_h_is_pushed_apart_two_sided_without_net_force():
    nodes, x0, t = _fold(0.9 * H)
    load = _load(x0, t, active_fraction=1.0)  # room for every node and edge
    assert isinstance(load, SelfContactLoad)
    x = jnp.asarray(nodes, jnp.float32)
    st = load.initial_state(x)
    v = np.zeros_like(nodes)
    v[nodes[:, 2] > 0.5 * H, 1] = 0.01  # upper layer sliding across
    f, st2, ex = _force(load, x, jnp.asarray(v, jnp.float32), 0.0, st)
    f = np.asarray(f)
    upper, lower = nodes[:, 2] > 0.5 * H, (nodes[:, 2] < 0.5 * H) & (nodes[:, 0] < 0.019)
    flat_part = (nodes[:, 0] > 0.001) & (nodes[:, 0] < 0.017)
    assert np.all(f[upper & flat_part, 2] > 0) and np.all(f[lower & flat_part, 2] < 0)  # apart
    np.testing.assert_allclose(f.sum(axis=0), 0.0, atol=1e-4 * np.abs(f).max())  # float32 sums
    # node to face: both passes (each with half the area) add up to one contact, k (0.1 h) A
    # (the force evaluates the normal contact: its friction is the integrator's, test below)
    fn = np.asarray(_ply_contact(x, jnp.asarray(v, jnp.float32), load.slave, load.triangles, st.candidates[0],
                                        load.gap0, load.area, contact.force_params(load)).force)
    np.testing.assert_allclose(np.median(fn[upper & flat_part, 2]), 1e10 * 0.1 * H * 1e-6, rtol=1e-3)
    # edge to edge: flat layers 0.9 h apart are 0.9 h apart edge to edge as well (another k (0.1 h)
    # on the edges' area: a stiffer contact, no other change), frictionless, pushing apart
    fe = f - fn
    # the step evaluates only the nodes and edges near a candidate at the refresh (or all, when
    # more than its room): the same forces as evaluating every one
    # (compiled, as the step is: of two edges equally near, rounding may pick either)
    fe_all = jax.jit(lambda y, w: edge_contact(y, w, load.edges, st.candidates.edges, load.gap0, load.edge_area,
                                               load.params).force)(x, jnp.asarray(v, jnp.float32))
    fn_all = jax.jit(lambda y, w: contact.ply_contact(y, w, load.slave, load.triangles, st.candidates.nodes, load.gap0,
                                                      load.area, contact.force_params(load)).force)(x, jnp.asarray(v, jnp.float32))
    np.testing.assert_allclose(f, np.asarray(fn_all + fe_all), atol=1e-6 * np.abs(f).max())
    small = _load(x0, t, active_fraction=0.0)  # room for 64: overflows, all evaluated
    st_s = small.initial_state(x)
    assert bool(st_s.candidates.overflow) and not bool(st.candidates.overflow)
    f_s, _, ex_s = _force(small, x, jnp.asarray(v, jnp.float32), 0.0, st_s)
    np.testing.assert_allclose(np.asarray(f_s), f, atol=1e-6 * np.abs(f).max())
    assert int(ex_s["active_overflow"]) == 1 and int(ex["active_overflow"]) == 0
    assert np.all(fe[upper & flat_part, 2] > 0) and np.abs(fe[upper & flat_part, 1]).max() < 1e-3 * fe[upper, 2].max()
    assert -0.2 * H < float(ex["min_edge_gap"]) < -0.0999 * H  # 0.1 h on the flat, a little more at the turn
    assert int(st2.step) == 1
    # two-sided: every triangle turned over, the layers are seen from their backs, same forces
    load_r = _load(x0, t[:, ::-1].copy(), active_fraction=1.0)  # the program of `load`
    st_r = load_r.initial_state(x)
    assert np.all(np.asarray(st_r.candidates[0])[upper & flat_part, 0] < 0)  # the nearest: the other layer
    f_r = np.asarray(_force(load_r, x, jnp.asarray(v, jnp.float32), 0.0, st_r)[0])
    fn_r = np.asarray(_ply_contact(x, jnp.asarray(v, jnp.float32), load_r.slave, load_r.triangles,
                                          st_r.candidates[0], load_r.gap0, load_r.area, contact.force_params(load_r)).force)
    np.testing.assert_allclose(fn_r, fn, atol=1e-5 * np.abs(fn).max())
    # edge pairs: flat layers are equally near many edges of the other, which one is taken depends
    # on the order of the candidates; the push on the layer is the same
    np.testing.assert_allclose(f_r[upper].sum(axis=0), f[upper].sum(axis=0), rtol=1e-4, atol=1e-4 * np.abs(f).max())
    # layers h apart (and more): no force; gradient of the penalty energy finite
    nodes2, x02, t2 = _fold(1.1 * H)
    load2 = _load(x02, t2, active_fraction=1.0)
    x2 = jnp.asarray(nodes2, jnp.float32)
    f2, _, _ = _force(load2, x2, jnp.zeros_like(x2), 0.0, load2.initial_state(x2))
    assert float(jnp.abs(f2).max()) == 0.0
    cand = st.candidates[0]
    g = jax.jit(jax.grad(lambda xx: contact.ply_contact(xx, jnp.zeros_like(xx), load.slave, load.triangles, cand,
                                                        load.gap0, load.area, load.params).energy))(x)
    assert np.all(np.isfinite(np.asarray(g))) and float(jnp.abs(g).max()) > 0


def test_a_fold_s_friction_is_integrated_backward_coulomb_when_sliding_and_stopping_a_stuck_slip():
    """The upper layer of a fold slides across the lower one at 1 cm/s, pressed 0.1 h into it.
    Over a step too short to stop the slip, the friction on the upper layer is Coulomb's
    ``mu F_n`` against the slip and the lower layer feels the opposite; over a long step it
    stops the slip in that step without reversing it (the two passes each solve half a pair:
    with whole pairs they would reverse it)."""
    nodes, x0, t = _fold(0.9 * H)
    load = _load(x0, t, active_fraction=1.0)
    x = jnp.asarray(nodes, jnp.float32)
    upper = nodes[:, 2] > 0.5 * H
    flat = (nodes[:, 0] > 0.002) & (nodes[:, 0] < 0.016)
    lower = ~upper & flat
    v = jnp.asarray(np.where(upper[:, None], [0.0, 0.01, 0.0], 0.0), jnp.float32)
    st = load.initial_state(x)
    support = _force(load, x, v, 0.0, st)[2]["backward_support"]
    # the node-to-face contact's normal force (the edges' is frictionless)
    f_n = _ply_contact(x, v, load.slave, load.triangles, st.candidates.nodes, load.gap0, load.area,
                       contact.force_params(load)).force
    mass = jnp.full(len(nodes), 3e-7, jnp.float32)  # 0.3 kg/m² on 1e-6 m²
    hook = jax.jit(lambda p, h: load.backward(support, p, mass, h, h, {}, None)[:2])
    p = mass[:, None] * v
    mu = float(load.params.friction)
    normal = float(np.sum(np.asarray(f_n)[upper & flat, 2]))
    f, ex_f = hook(p, jnp.float32(1e-10))  # sliding: mu F_n / m * h = 5e-5 m/s removed
    f = np.asarray(f)
    sliding = upper & flat
    assert -np.sum(f[sliding, 1]) == pytest.approx(mu * normal, rel=0.02)
    assert np.sum(f[lower, 1]) == pytest.approx(mu * normal, rel=0.02)
    np.testing.assert_allclose(f.sum(axis=0), 0.0, atol=1e-5 * np.abs(f).max())  # momentum kept
    # the power: Coulomb's at the slip over every pair (the fold's turn included)
    assert float(ex_f["friction_power"]) == pytest.approx(mu * float(jnp.sum(f_n[upper, 2])) * 0.01, rel=0.05)
    f, _ = hook(p, jnp.float32(1e-5))  # stick: the step could remove 5 m/s of slip
    v_end = (p + 1e-5 * f) / mass[:, None]
    slip = float(jnp.mean(v_end[upper & flat, 1])) - float(jnp.mean(v_end[lower, 1]))
    assert 0.0 <= slip < 0.05 * 0.01
    half = float(jnp.mean(v_end[upper & flat, 1]))
    assert half == pytest.approx(0.005, rel=0.1)  # both layers end at the mean velocity


def test_every_room_of_the_active_lists_gives_the_forces_of_evaluating_all():
    """The step evaluates the smallest room that holds the active nodes and edges (one slot, the
    lists, or all on overflow): the same forces in each."""
    nodes, x0, t = _fold(0.9 * H)
    x = jnp.asarray(nodes, jnp.float32)
    v = jnp.zeros_like(x).at[:, 1].set(jnp.where(x[:, 2] > 0.5 * H, 0.01, 0.0))
    out = {}
    for frac in (8.0, 1.0, 0.0):  # a room 8x the lists / the lists / overflow
        load = _load(x0, t, active_fraction=frac)
        st = load.initial_state(x)
        c = st.candidates
        n_act, e_act = int(jnp.sum(c.active_nodes >= 0)), int(jnp.sum(c.active_edges >= 0))
        out[frac] = (np.asarray(_force(load, x, v, 0.0, st)[0]), n_act, e_act, load, bool(c.overflow))
    f_all = out[0.0][0]
    assert out[0.0][4] and not out[1.0][4] and not out[8.0][4]
    assert out[8.0][1] > 0 and np.abs(f_all).max() > 0
    for frac in (8.0, 1.0):
        np.testing.assert_allclose(out[frac][0], f_all, atol=1e-6 * np.abs(f_all).max())
    # a flat sheet: nothing active, the one-slot room, no force
    flat = np.column_stack([x0[:, :2], np.zeros(len(x0))])
    load = _load(x0, t, active_fraction=1.0)
    xf = jnp.asarray(flat, jnp.float32)
    st = load.initial_state(xf)
    assert int(jnp.sum(st.candidates.active_nodes >= 0)) == 0 and int(jnp.sum(st.candidates.active_edges >= 0)) == 0
    assert float(jnp.abs(_force(load, xf, jnp.zeros_like(xf), 0.0, st)[0]).max()) == 0.0


def test_segment_closest_points_match_a_dense_sampling():
    rng = np.random.default_rng(3)
    p = rng.normal(size=(300, 4, 3))
    p[:30, 3] = p[:30, 2] + p[:30, 1] - p[:30, 0]  # parallel
    p[30:40, 1] = p[30:40, 0]  # a point
    s, t = (np.asarray(a) for a in closest_points_segments(p[:, 0], p[:, 1], p[:, 2], p[:, 3]))
    assert np.all((s >= 0) & (s <= 1) & (t >= 0) & (t <= 1))
    d = np.linalg.norm(p[:, 0] + s[:, None] * (p[:, 1] - p[:, 0]) - p[:, 2] - t[:, None] * (p[:, 3] - p[:, 2]), axis=1)
    g = np.linspace(0.0, 1.0, 201)
    a = p[:, None, 0] + g[None, :, None] * (p[:, None, 1] - p[:, None, 0])  # (300, 201, 3)
    b = p[:, None, 2] + g[None, :, None] * (p[:, None, 3] - p[:, None, 2])
    brute = np.sqrt(np.min(np.sum((a[:, :, None] - b[:, None, :]) ** 2, axis=-1), axis=(1, 2)))
    step = 0.005 * (np.linalg.norm(p[:, 1] - p[:, 0], axis=1) + np.linalg.norm(p[:, 3] - p[:, 2], axis=1))
    assert np.all(d <= brute + 1e-12) and np.all(d >= brute - step)  # the sampling is off by a step at most


def test_near_edges_table_matches_brute_force_reference_distances():
    """The host table of edges excluded from edge contact (same ply, no shared node, closer than
    the exclusion in the reference) against all pairs by dense sampling of the segments."""
    lower, tri = _wavy_ply(7, 6e-3, 0.0, 0.8e-3, 0.0)
    upper, _ = _wavy_ply(7, 6e-3, 0.3e-3, 0.8e-3, 0.4)
    x0, tris = np.vstack([lower, upper]), np.vstack([tri, tri + len(lower)])
    edges, _, _ = mesh_edges(tris, np.ones(len(tris)))
    group = (edges[:, 0] >= len(lower)).astype(int)
    excl = 1.3e-3
    table = near_edges(x0, edges, group, excl)
    got = {(i, int(j)) for i, row in enumerate(table) for j in row if j >= 0}
    g = np.linspace(0.0, 1.0, 21)
    pts = x0[edges[:, 0]][:, None] + g[None, :, None] * (x0[edges[:, 1]] - x0[edges[:, 0]])[:, None]  # (E, 21, 3)
    d = np.sqrt(np.min(np.sum((pts[:, None, :, None] - pts[None, :, None, :]) ** 2, axis=-1), axis=(2, 3)))
    shared = np.any(edges[:, None, :, None] == edges[None, :, None, :], axis=(2, 3))
    ok = (group[:, None] == group[None, :]) & ~shared
    length = np.linalg.norm(x0[edges[:, 1]] - x0[edges[:, 0]], axis=1)
    step = 0.025 * (length[:, None] + length[None, :])  # the sampling's error bound (half a spacing each)
    sure_in = {(int(i), int(j)) for i, j in zip(*np.nonzero(ok & (d < excl)))}
    sure_out = ok & (d - step > excl)
    assert len(sure_in) > 2 * len(edges)  # a real test: many pairs inside, many near the limit outside
    assert not any(sure_out[i, j] for i, j in got)
    assert sure_in <= got
    assert all(ok[i, j] for i, j in got)


def _ridges(dist):
    """Two creased sheets (roofs, 1 mm elements, 45 degree slopes), the upper one turned over, their
    ridges crossing at right angles ``dist`` apart, mid-edge: every node is far from the other
    sheet, only the ridges come close."""
    X, Y = np.meshgrid(np.linspace(-2e-3, 2e-3, 5) + 0.5e-3, np.linspace(-2e-3, 2e-3, 5), indexing="ij")
    idx = np.arange(25).reshape(5, 5)
    q = np.column_stack([idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()])
    t, _ = triangulate(q)
    lower = np.column_stack([X.ravel(), Y.ravel(), -np.abs(Y.ravel())])  # ridge along x at z = 0
    upper = np.column_stack([Y.ravel(), X.ravel(), dist + np.abs(Y.ravel())])  # ridge along y at z = dist
    flat = np.column_stack([X.ravel(), Y.ravel(), np.zeros(25)])
    return np.vstack([lower, upper]), np.vstack([flat, flat + [0.1, 0.0, 0.0]]), np.vstack([t, t + 25])


def test_crossing_ridges_are_held_apart_edge_to_edge_by_the_energy_gradient():
    nodes, x0, t = _ridges(0.8 * H)
    load = _load(x0, t)
    x = jnp.asarray(nodes)
    st = load.initial_state(x)
    fn = _ply_contact(x, jnp.zeros_like(x), load.slave, load.triangles, st.candidates[0], load.gap0,
                             load.area, load.params)
    assert float(jnp.min(fn.gap)) > 0.4 * H and float(jnp.abs(fn.force).max()) == 0.0  # nodes see nothing
    f, _, ex = _force(load, x, jnp.zeros_like(x), 0.0, st)
    f = np.asarray(f)
    np.testing.assert_allclose(float(ex["min_edge_gap"]), -0.2 * H, rtol=1e-6)
    assert f[25:, 2].sum() > 0 and f[:25, 2].sum() < 0  # the upper ridge up, the lower one down
    np.testing.assert_allclose(f.sum(axis=0), 0.0, atol=1e-12 * np.abs(f).max())
    np.testing.assert_allclose(np.cross(nodes, f).sum(axis=0), 0.0, atol=1e-12 * np.abs(f).max() * 1e-3)
    # conservative: the force is minus the gradient of the penalty energy (fixed candidates, at rest)
    ec = st.candidates[1]
    energy = lambda y: edge_contact(y, jnp.zeros_like(y), load.edges, ec, load.gap0, load.edge_area,  # noqa: E731
                                    load.params).energy
    np.testing.assert_allclose(f, -np.asarray(jax.jit(jax.grad(energy))(x)), rtol=1e-9, atol=1e-12 * np.abs(f).max())
    # 1.1 h apart: no force
    nodes2, _, _ = _ridges(1.1 * H)
    x2 = jnp.asarray(nodes2)
    assert float(jnp.abs(_force(load, x2, jnp.zeros_like(x2), 0.0, load.initial_state(x2))[0]).max()) == 0.0


def test_bending_and_a_flat_sheet_are_not_contact():
    # a sheet rolled to a cylinder of radius 2 h, one element = 0.5 h: its neighbourhood is excluded
    n_s, ny = 40, 5
    s = np.linspace(0.0, 0.9 * 2 * np.pi * 2 * H, n_s)
    y = np.linspace(0.0, 0.002, ny)
    S, Y = np.meshgrid(s, y, indexing="ij")
    R = 2 * H
    nodes = np.column_stack([R * np.sin(S.ravel() / R), Y.ravel(), R - R * np.cos(S.ravel() / R)])
    x0 = np.column_stack([S.ravel(), Y.ravel(), np.zeros(S.size)])
    idx = np.arange(n_s * ny).reshape(n_s, ny)
    q = np.column_stack([idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()])
    t, _ = triangulate(q)
    for x, ref in ((nodes, x0), (x0, x0)):
        load = _load(ref, t)
        xj = jnp.asarray(x, jnp.float32)
        f, _, ex = _force(load, xj, jnp.zeros_like(xj), 0.0, load.initial_state(xj))
        assert float(jnp.abs(f).max()) == 0.0 and float(ex["min_gap"]) > 0 and float(ex["min_edge_gap"]) > 0


def _rig_loads(name, *keys):
    """The contact loads the rig builds for a coarse preset (no compilation)."""
    from jaxform.forming import rig

    case = cases.apply_overrides(cases.with_element_size(cases.load(name), 25e-3), list(keys))
    mesh = rig.build_mesh(case)
    return case, mesh, rig._loads(case, mesh, rig.ply_fabrics(case), 1e-6, jnp.float32)[0]


def test_rig_wires_self_contact_by_default():
    case, mesh, loads = _rig_loads("case-a-ncf-nlbm")
    assert len(loads) == 4 and isinstance(loads[3], SelfContactLoad)
    sc = loads[3]
    h = case.ply_thickness
    assert float(sc.gap0) == pytest.approx(h) and float(sc.params.friction) == pytest.approx(0.36)
    np.testing.assert_allclose(np.asarray(sc.area).sum(), 0.5 * case.blank_size**2, rtol=1e-5)
    x = jnp.asarray(mesh.nodes, jnp.float32)
    f = jax.jit(lambda y: sc.force(y, jnp.zeros_like(y), 0.0, sc.initial_state(y))[0])(x)
    assert float(jnp.abs(f).max()) == 0.0  # the flat blank does not touch itself
    assert len(_rig_loads("case-a-ncf-nlbm", "contact.self_contact=false")[2]) == 3
    # a stack: neighbouring plies are the PlyLoad's, each ply with itself the self-contact's
    ok = np.asarray(_rig_loads("case-b-woven-nlbm")[2][4].pair_ok)
    assert ok[1, 1] and ok[2, 2] and not ok[1, 2] and not ok[2, 1]


def _squeeze_strip(self_contact, *, length=0.06, width=0.004, n_len=60, gap_h=6.0, squeeze=0.5, speed=0.5,
                   chunks=10, mass_scale=1000.0, bending=2e-3, damping=200.0):
    """A woven strip (bending made ``bending`` N·m, linear) pushed from both ends by ``squeeze`` of
    its length between two plates ``gap_h`` thicknesses apart, with a small initial wave: the
    final positions, the mesh, h and the self-contact load (``None`` when off)."""
    from jaxform import integrate, materials, tools
    from jaxform.materials.bending import LinearBending
    from jaxform.mesh import Mesh
    from jaxform.model import LinearDrive
    from jaxform.shell import Shell
    from jaxform.spectrum import stable_time_step

    law = LinearBending(bending)
    fab = materials.preset("woven-38616").replace(bending=(law, law))
    h = float(fab.thickness)
    mesh = Mesh.strip(length, width, n_len, 2, x0=-0.5 * length)
    shell = Shell.build(mesh, fab)
    X = np.asarray(mesh.nodes)
    n = len(X)
    ends = np.abs(X[:, 0]) > 0.5 * length - 1e-9
    vel = np.zeros((n, 3))
    vel[:, 0] = -np.sign(X[:, 0]) * speed * ends
    x_init = X.copy()
    x_init[:, 2] = 0.3 * h * np.sin(3 * np.pi * (X[:, 0] / length + 0.5)) * ~ends
    dt = 0.5 * stable_time_step(shell, mass_scale=mass_scale, safety=1.0)
    rho = float(fab.areal_mass) * mass_scale
    f32 = lambda a: jnp.asarray(a, jnp.float64)  # noqa: E731  (float64 as the shell: the tests' x64)
    params = penalty.contact_params(rho, dt, h, friction=0.23, slip_velocity=0.01 * speed)
    area = np.asarray(mesh.node_area)
    loads = [contact.ToolLoad(tool=tools.Plane(point=f32((0.0, 0.0, s * 0.5 * gap_h * h)), normal=f32((0.0, 0.0, -s))),
                              params=params, offset=f32(h / 2), area=f32(area), active=f32(np.ones(n)))
             for s in (-1.0, 1.0)]
    sc = None
    if self_contact:
        ps = penalty.contact_params(rho, dt, h, friction=0.36, slip_velocity=0.01 * speed, two_sided=True, interfaces=2)
        sc = self_contact_load(X, np.asarray(mesh.tris), area, np.zeros(n, int), h, ps, dtype=jnp.float64)
        loads.append(sc)
    model = integrate.make_model(shell, dt=dt, mass_scale=mass_scale, damping=damping,
                                 fixed=np.repeat(ends[:, None], 3, axis=1),
                                 drive=LinearDrive(x0=f32(X), velocity=f32(vel)), loads=tuple(loads), dtype=jnp.float64)
    ls = (None, None) + ((sc.initial_state(f32(x_init)),) if self_contact else ())
    state = integrate.init_state(model, x=x_init, load_states=ls)
    steps = int(np.ceil(squeeze * length / (2 * speed) / dt / chunks))
    run = jax.jit(lambda s: integrate.run_steps(model, s, steps, blowup_tol=1e9)[0])
    for _ in range(chunks):
        state = run(state)
    assert int(state.bad_step) < 0
    return np.asarray(state.x), mesh, h, sc


@pytest.mark.slow
def test_a_strip_squeezed_between_plates_folds_into_layers_that_do_not_cross():
    # measured: layers 0.974 h apart at the closest, 0 crossing pairs; 31 without self-contact
    # (node-to-face contact alone: 22, the edges of one-element kinks passing through each other)
    from jaxform.metrics.intersections import intersecting_pairs

    x, mesh, h, sc = _squeeze_strip(True)
    xj = jnp.asarray(x)
    cand, ecand, *_ = sc.search(xj)
    gap = np.asarray(_ply_contact(xj, jnp.zeros_like(xj), sc.slave, sc.triangles, cand, sc.gap0, sc.area,
                                         sc.params).gap)
    gap_e = np.asarray(edge_contact(xj, jnp.zeros_like(xj), sc.edges, ecand, sc.gap0, sc.edge_area, sc.params).gap)
    gap = np.minimum(gap.min(), gap_e.min())  # the distance of the layers: vertex-face or edge-edge
    pairs_on = len(intersecting_pairs(x, np.asarray(mesh.tris)))
    x_off, _, _, _ = _squeeze_strip(False)
    pairs_off = len(intersecting_pairs(x_off, np.asarray(mesh.tris)))
    print(f"min layer distance {(gap.min() + h) / h:.3f} h; intersecting pairs {pairs_on} with self-contact, "
          f"{pairs_off} without")
    assert pairs_off > 0
    assert gap.min() >= -0.1 * h and pairs_on == 0


def test_the_fold_s_normal_forces_integrated_backward_are_the_penalty_s_at_a_short_step_and_keep_momentum():
    """``implicit_normal``: the node-to-face and edge-to-edge rows of a fold pressed to 0.9 h, solved
    at the end of the step. At a step far below the contact's period they are the explicit penalty's
    forces (normal damping off, nothing moving: the same sum on each layer within 1 %); at a long
    one they are smaller, push the layers apart and keep momentum."""
    nodes, x0, t = _fold(0.9 * H)
    loads = {imp: dataclasses.replace(_load(x0, t, active_fraction=1.0), implicit_normal=imp) for imp in (False, True)}
    x = jnp.asarray(nodes, jnp.float32)
    v = jnp.zeros_like(x)
    st = loads[True].initial_state(x)
    upper = nodes[:, 2] > 0.5 * H
    f_exp = np.asarray(_force(loads[False], x, v, 0.0, st)[0])
    f0, _, ex = _force(loads[True], x, v, 0.0, st)
    assert float(jnp.abs(f0).max()) == 0.0  # the force comes in the hook
    mass = jnp.full(len(nodes), 3e-7, jnp.float32)
    hook = jax.jit(lambda h: loads[True].backward(ex["backward_support"], jnp.zeros_like(x), mass, h, h, {}, None)[0])
    f_short = np.asarray(hook(jnp.float32(1e-9)))
    assert np.sum(f_short[upper, 2]) == pytest.approx(np.sum(f_exp[upper, 2]), rel=0.01)
    assert np.sum(f_short[upper, 2]) > 0 and np.sum(f_short[~upper, 2]) < 0
    f_long = np.asarray(hook(jnp.float32(1e-5)))  # k dt^2 / rho_A = 3: beyond the explicit limit
    assert 0 < np.sum(f_long[upper, 2]) < np.sum(f_short[upper, 2])
    np.testing.assert_allclose(f_long.sum(axis=0), 0.0, atol=1e-5 * np.abs(f_long).max())
