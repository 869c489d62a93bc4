"""Defect classification and wrinkle measures (source paper section 3.2, SPEC section 5).

All functions are pure JAX with fixed shapes (jit-able, vmap-able over frames); those that return
real numbers are differentiable where the quantity is (counts and labels are integers).

Zones (per node), from the distance to the tool ``d`` and ``kappa_max``:

- ``CONFORMING`` (0): ``d <= d_crit`` (paper's zone C);
- ``BRIDGING`` (1): ``d > d_crit`` and low curvature (zone B);
- ``WRINKLE`` (2): ``d > d_crit`` and high curvature (zone A).

"High curvature" is ``kappa_max >= kappa_threshold`` somewhere within ``rings`` rings of the node
(default one ring, so that the flanks of a wrinkle between its crest and trough, where the
curvature passes through zero, stay in the wrinkle). The default threshold, 100 1/m (radius 10
mm), separates the paper's wrinkles (radius 0.7-2 mm in NCF case B, up to a few mm in case A) from
bridging spans and the 50 mm punch (20 1/m); set it for your part.

Sections: the surface is projected on the tool's base plane (normal ``plane_normal``); a straight
line between two points of that plane is sampled and each sample takes the value of a nodal field
(by default the distance to the tool, the paper's "wrinkle amplitude") interpolated linearly on the
highest face above it (the one a scanner looking down would see).

Normalised RMSE between two sections (:func:`section_nrmse`): the RMS of the difference of the two
profiles, sampled at the reference's positions inside the range both cover, divided by the range
(max - min) of the reference profile. A fraction (0.011 = 1.1%).
"""
from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np

from jaxform.geometry import quads_to_triangles, safe_norm, safe_sqrt

__all__ = [
    "CONFORMING",
    "BRIDGING",
    "WRINKLE",
    "d_crit",
    "node_areas",
    "ring_max",
    "classify_zones",
    "zone_areas",
    "wrinkle_radius",
    "section_profile",
    "section_nrmse",
    "count_section_wrinkles",
    "count_wrinkle_regions",
    "rms_fibre_moment",
    "probability_density",
]

CONFORMING, BRIDGING, WRINKLE = 0, 1, 2


def d_crit(ply_thickness, ply_index: int = 1):
    """Critical distance from ply ``ply_index`` (1 = the ply on the tool) to the tool, m.

    ``(i - 1/2) h``: the distance from the mid-plane of ply i of a stack of plies of thickness h
    lying flat on the tool (h/2 for a single ply).

    Args:
      ply_thickness: ply thickness h, m.
      ply_index: 1-based position of the ply in the stack, counted from the tool.
    """
    if isinstance(ply_index, (int, np.integer)) and ply_index < 1:
        raise ValueError(f"ply_index counts from 1 (the ply touching the tool), got {ply_index}")
    return (ply_index - 0.5) * jnp.asarray(ply_thickness)


def node_areas(nodes, faces):
    """Lumped nodal areas: each face's area shared equally among its corners.

    Args:
      nodes: (N, 3) m. faces: (F, 3) or (F, 4) int.
    Returns:
      (N,) area, m^2 (sums to the surface area).
    """
    x = jnp.asarray(nodes)
    f = jnp.asarray(faces)
    k = f.shape[1]
    t = quads_to_triangles(f)
    area_t = 0.5 * safe_norm(jnp.cross(x[t[:, 1]] - x[t[:, 0]], x[t[:, 2]] - x[t[:, 0]]))
    if k == 4:
        n_f = f.shape[0]
        area_f = area_t[:n_f] + area_t[n_f:]
    else:
        area_f = area_t
    share = jnp.repeat(area_f / k, k)
    return jax.ops.segment_sum(share, f.reshape(-1), num_segments=x.shape[0])


def ring_max(values, faces, rings: int = 1):
    """Maximum of a nodal field ``values`` (N, ...) over the faces (F, k) around each node (the node
    itself included), repeated ``rings`` times."""
    f = jnp.asarray(faces)
    n = values.shape[0]
    for _ in range(rings):
        face_max = jnp.max(values[f], axis=1)
        values = jnp.maximum(
            values,
            jax.ops.segment_max(jnp.repeat(face_max, f.shape[1], axis=0), f.reshape(-1), num_segments=n),
        )
    return values


def classify_zones(distance, kappa_max, d_critical, *, kappa_threshold=100.0, faces=None,
                   rings: int = 1):
    """Zone label per node: CONFORMING (0), BRIDGING (1) or WRINKLE (2).

    Args:
      distance: (N,) distance to the tool, m.
      kappa_max: (N,) largest absolute principal curvature, 1/m.
      d_critical: critical distance (:func:`d_crit`), m.
      kappa_threshold: curvature above which a defect is a wrinkle, 1/m (default 100, radius 10 mm).
      faces: (F, 3|4) int; when given, the curvature test looks ``rings`` rings around each node.
      rings: neighbourhood for the curvature test (0: the node only).

    Returns:
      (N,) int32 labels.
    """
    k = jnp.asarray(kappa_max)
    if faces is not None and rings > 0:
        k = ring_max(k, faces, rings)
    defect = jnp.asarray(distance) > d_critical
    high = k >= kappa_threshold
    return jnp.where(defect, jnp.where(high, WRINKLE, BRIDGING), CONFORMING).astype(jnp.int32)


def zone_areas(labels, areas):
    """(N,) labels, (N,) nodal areas m^2 -> (3,) area of conforming, bridging, wrinkle zones, m^2."""
    return jax.ops.segment_sum(jnp.asarray(areas), jnp.asarray(labels), num_segments=3)


def wrinkle_radius(kappa_max, kappa_floor=1e-3):
    """Wrinkle radius ``1 / kappa_max``, m; nodes flatter than ``kappa_floor`` (1/m) get
    ``1 / kappa_floor`` (default 1 km), so the result is finite and differentiable."""
    return 1.0 / jnp.maximum(jnp.asarray(kappa_max), kappa_floor)


def _plane_basis(plane_normal, dtype):
    n = jnp.asarray(plane_normal, dtype)
    n = n / safe_norm(n)
    ref = jnp.where(jnp.abs(n[0]) < 0.9, jnp.array([1.0, 0, 0], dtype), jnp.array([0, 1.0, 0], dtype))
    u = ref - jnp.dot(ref, n) * n
    u = u / safe_norm(u)
    v = jnp.cross(n, u)
    # For the default normal +z this gives u = +x, v = +y: plane coordinates are (x, y).
    return u, v, n


def section_profile(nodes, faces, field, start, end, n_samples: int = 200,
                    plane_normal=(0.0, 0.0, 1.0)):
    """Sample a nodal field along a straight section of the surface projected on the base plane.

    Args:
      nodes: (N, 3) deformed node positions, m.
      faces: (F, 3|4) int.
      field: (N,) nodal values (e.g. the distance to the tool, m).
      start, end: (2,) end points of the section in base-plane coordinates, m (x, y for the
        default normal +z).
      n_samples: number of sample points (static).
      plane_normal: (3,) normal of the tool's base plane.

    Returns:
      s: (S,) position along the section from ``start``, m;
      values: (S,) field at the samples (0 where ``valid`` is False);
      valid: (S,) bool, the sample lies under/over the surface;
      height: (S,) height of the surface above the base plane at the samples, m.
    """
    x = jnp.asarray(nodes)
    dtype = x.dtype if jnp.issubdtype(x.dtype, jnp.floating) else jnp.result_type(float)
    x = x.astype(dtype)
    u, v, n = _plane_basis(plane_normal, dtype)
    p2 = jnp.stack([x @ u, x @ v], axis=1)
    hgt = x @ n
    t = quads_to_triangles(faces)
    a = jnp.asarray(start, dtype)
    b = jnp.asarray(end, dtype)
    s_frac = jnp.linspace(0.0, 1.0, n_samples, dtype=dtype)
    q = a[None] + s_frac[:, None] * (b - a)[None]  # (S, 2)
    A, B, C = p2[t[:, 0]], p2[t[:, 1]], p2[t[:, 2]]  # (T, 2)
    e1 = B - A
    e2 = C - A
    det = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
    ok_det = jnp.abs(det) > 0.0
    inv = 1.0 / jnp.where(ok_det, det, 1.0)
    r = q[:, None, :] - A[None]  # (S, T, 2)
    l1 = (r[..., 0] * e2[:, 1] - r[..., 1] * e2[:, 0]) * inv
    l2 = (e1[:, 0] * r[..., 1] - e1[:, 1] * r[..., 0]) * inv
    l0 = 1.0 - l1 - l2
    tol = 1e-9
    inside = ok_det & (l0 >= -tol) & (l1 >= -tol) & (l2 >= -tol)
    h_s = l0 * hgt[t[:, 0]] + l1 * hgt[t[:, 1]] + l2 * hgt[t[:, 2]]
    h_masked = jnp.where(inside, h_s, -jnp.inf)
    j = jnp.argmax(h_masked, axis=1)  # the highest face over each sample
    valid = jnp.any(inside, axis=1)
    take = lambda arr: jnp.take_along_axis(arr, j[:, None], axis=1)[:, 0]  # noqa: E731
    L0, L1, L2 = take(l0), take(l1), take(l2)
    fv = jnp.asarray(field, dtype)
    tj = t[j]
    val = L0 * fv[tj[:, 0]] + L1 * fv[tj[:, 1]] + L2 * fv[tj[:, 2]]
    height = L0 * hgt[tj[:, 0]] + L1 * hgt[tj[:, 1]] + L2 * hgt[tj[:, 2]]
    length = safe_norm(b - a)
    return (s_frac * length, jnp.where(valid, val, 0.0), valid, jnp.where(valid, height, 0.0))


def section_nrmse(s_ref, ref, s_other, other, valid_ref=None, valid_other=None):
    """Normalised RMSE between two section profiles (see module docstring), a fraction.

    Args:
      s_ref, ref: (S,) positions (m, increasing) and values of the reference (e.g. measured) profile.
      s_other, other: (S2,) positions (m, increasing) and values of the other (simulated) profile.
      valid_ref, valid_other: optional (S,), (S2,) bool masks of usable samples.

    Returns:
      scalar ``sqrt(mean((other(s) - ref(s))^2)) / (max(ref) - min(ref))`` over the reference
      samples inside the other profile's range.
    """
    s_ref = jnp.asarray(s_ref)
    ref = jnp.asarray(ref)
    s_other = jnp.asarray(s_other)
    other = jnp.asarray(other)
    w = jnp.ones_like(ref) if valid_ref is None else jnp.asarray(valid_ref).astype(ref.dtype)
    if valid_other is not None:
        vo = jnp.asarray(valid_other)
        lo = jnp.min(jnp.where(vo, s_other, jnp.inf))
        hi = jnp.max(jnp.where(vo, s_other, -jnp.inf))
    else:
        lo, hi = s_other[0], s_other[-1]
    w = w * ((s_ref >= lo) & (s_ref <= hi)).astype(ref.dtype)
    o = jnp.interp(s_ref, s_other, other)
    n = jnp.maximum(jnp.sum(w), 1.0)
    mse = jnp.sum(w * (o - ref) ** 2) / n
    span = jnp.max(jnp.where(w > 0, ref, -jnp.inf)) - jnp.min(jnp.where(w > 0, ref, jnp.inf))
    span = jnp.where(jnp.isfinite(span) & (span > 0.0), span, 1.0)
    return safe_sqrt(mse) / span


def count_section_wrinkles(values, valid=None, *, min_amplitude=0.0, min_prominence=0.5e-3):
    """Number of separate wrinkles (peaks) along a section profile.

    A peak counts when the profile rises by at least ``min_prominence`` above the lowest value
    since the previous peak, reaches at least ``min_amplitude``, then falls by at least
    ``min_prominence`` (or the section ends above ``min_amplitude`` after such a rise). Two crests
    that are not separated by a dip of ``min_prominence`` count as one wrinkle, and wrinkles need
    not come back down to the tool in between. A hysteresis scan: jit-able, fixed shape.

    Args:
      values: (S,) profile, e.g. distance to the tool, m.
      valid: (S,) bool; invalid samples (off the surface) end the current wrinkle's search.
      min_amplitude: minimum crest value, m (e.g. ``d_crit``).
      min_prominence: minimum rise and fall around a crest, m (default 0.5 mm).
    Returns:
      int32 scalar.
    """
    v = jnp.asarray(values)
    ok = jnp.ones(v.shape, bool) if valid is None else jnp.asarray(valid)

    def step(state, inp):
        low, high, rising, count = state
        val, good = inp
        # An invalid sample (off the surface) closes a rising wrinkle and restarts the search.
        gap_close = rising & ~good
        count = count + (gap_close & (high >= min_amplitude)).astype(jnp.int32)
        # Not rising: follow the lowest value; start a wrinkle once the rise is prominent.
        low_new = jnp.minimum(low, val)
        start = good & ~rising & (val - low_new >= min_prominence)
        # Rising: follow the crest; close the wrinkle once the fall is prominent.
        high_new = jnp.maximum(high, val)
        fall = good & rising & (high_new - val >= min_prominence)
        count = count + (fall & (high_new >= min_amplitude)).astype(jnp.int32)
        low = jnp.where(~good, jnp.inf, jnp.where(fall, val, jnp.where(rising, low, low_new)))
        high = jnp.where(start, val, jnp.where(good & rising & ~fall, high_new, -jnp.inf))
        rising = good & ((rising & ~fall) | start)
        return (low, high, rising, count), None

    dtype = v.dtype if jnp.issubdtype(v.dtype, jnp.floating) else jnp.result_type(float)
    init = (jnp.asarray(jnp.inf, dtype), jnp.asarray(-jnp.inf, dtype), jnp.asarray(False),
            jnp.asarray(0, jnp.int32))
    (low, high, rising, count), _ = jax.lax.scan(step, init, (v.astype(dtype), ok))
    return count + (rising & (high >= min_amplitude)).astype(jnp.int32)


def count_wrinkle_regions(labels, faces, nodal_area=None, *, min_area=0.0):
    """Number of connected wrinkle regions on the mesh (nodes labelled WRINKLE joined by faces).

    Args:
      labels: (N,) zone labels from :func:`classify_zones`.
      faces: (F, 3|4) int.
      nodal_area: (N,) nodal areas, m^2 (:func:`node_areas`); needed with ``min_area``.
      min_area: regions smaller than this (m^2) are not counted (noise, single nodes).

    Returns:
      (count int32 scalar, region id per node (N,) int32: the smallest node index of its region,
      or -1 outside wrinkles).
    """
    lab = jnp.asarray(labels)
    f = jnp.asarray(faces)
    n = lab.shape[0]
    is_w = lab == WRINKLE
    big = jnp.int32(n)
    comp0 = jnp.where(is_w, jnp.arange(n, dtype=jnp.int32), big)

    def propagate(comp):
        face_min = jnp.min(jnp.where(is_w[f], comp[f], big), axis=1)
        node_min = jax.ops.segment_min(jnp.repeat(face_min, f.shape[1]), f.reshape(-1), num_segments=n)
        return jnp.where(is_w, jnp.minimum(comp, node_min), big)

    def cond(state):
        return state[1]

    def body(state):
        comp, _ = state
        new = propagate(comp)
        return new, jnp.any(new != comp)

    comp, _ = jax.lax.while_loop(cond, body, (comp0, jnp.asarray(True)))
    roots = is_w & (comp == jnp.arange(n))
    if nodal_area is None:
        keep = roots
    else:
        area = jax.ops.segment_sum(jnp.where(is_w, jnp.asarray(nodal_area), 0.0),
                                   jnp.where(is_w, comp, 0), num_segments=n)
        keep = roots & (area >= min_area)
    return jnp.sum(keep).astype(jnp.int32), jnp.where(is_w, comp, -1).astype(jnp.int32)


def rms_fibre_moment(m1, m2):
    """RMS of the bending moments along the two fibre families, per element (paper's M_f^RMS).

    Args:
      m1, m2: (E,) bending moment per unit width about each fibre family, N (= N m/m).
    Returns:
      (E,) ``sqrt((m1^2 + m2^2) / 2)``, N; zero gradient at zero moment.
    """
    return safe_sqrt(0.5 * (jnp.asarray(m1) ** 2 + jnp.asarray(m2) ** 2))


def probability_density(values, bins: int = 50, value_range=None, weights=None):
    """Histogram estimate of the probability density of a field (e.g. M_f^RMS per element).

    Args:
      values: (M,) samples (any unit u).
      bins: number of bins (static).
      value_range: (lo, hi) in u; required under jit (default: the data range, concrete input).
      weights: optional (M,) weights (e.g. element or nodal areas, for an area-weighted density).

    Returns:
      density (bins,) in 1/u, integrating to 1 over the range; edges (bins + 1,) in u.
    """
    v = jnp.asarray(values)
    if value_range is None:
        value_range = (float(jnp.min(v)), float(jnp.max(v)))
        if value_range[1] <= value_range[0]:
            value_range = (value_range[0] - 0.5, value_range[0] + 0.5)
    density, edges = jnp.histogram(v, bins=bins, range=value_range, weights=weights, density=True)
    return density, edges
