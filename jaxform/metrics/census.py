"""Wrinkle census of a formed flange: the discrete wrinkles an engineer would count, each with its
position, size and amplitude.

A wrinkle is a ridge of the out-of-plane deviation (the distance of the ply from the tool, d_P,
SPEC section 5) running across the flange. The census finds them in four steps:

1. The deviation is resampled on a polar grid about the punch axis in the top view of the ply:
   rings every ``dr`` from ``r_inner`` outwards, ``n_theta`` angles per ring (linear
   interpolation on the ply's own faces, the highest over each sample as a scanner sees it, or
   without faces on the Delaunay triangulation of the nodes' top view).
2. On each ring, smoothed along its arc over an element size, the crests: peaks standing out by at least ``prominence`` from
   the troughs on both sides, with their width at half prominence (``scipy.signal``). A flange
   lifted uniformly, or by an amount that varies with the radius only, has no crests.
3. Crests on rings up to ``max_gap + 1`` rings apart whose arc distance is within ``link`` are
   joined; each connected set of crests is one wrinkle (a ridge that forks stays one wrinkle; two
   ridges separated by a dip deeper than ``prominence`` are two). Sets that span less than
   ``min_length`` radially are dropped (a local bump is not a wrinkle), and, where ``max_width``
   is given, those whose crests are wider (median width at half prominence): lifted lobes.
4. Each wrinkle is described by :class:`Wrinkle`.

Host-side numpy/scipy: a census counts, which is not differentiable (the differentiable wrinkle
measures are in :mod:`jaxform.metrics.wrinkles`).
"""
from __future__ import annotations

import dataclasses
import warnings

import numpy as np

__all__ = ["Wrinkle", "wrinkle_census", "polar_deviation"]


@dataclasses.dataclass(frozen=True)
class Wrinkle:
    """One wrinkle of a census (SI units; angles in degrees, counter-clockwise from +x).

    Attributes:
        angle_deg: prominence-weighted circular mean of its crests' angles, [0, 360).
        quadrant: 1-4 (1: 0-90 deg, 2: 90-180, ...), from ``angle_deg``.
        r_inner_m, r_outer_m: radial extent (top view, m).
        length_m: length of the ridge line through its crests, taken every two element sizes
            along it (top view, m).
        width_m: median width of its crests at half prominence (arc length, m; the ring
            smoothing taken out as for a Gaussian ridge).
        amplitude_m: largest prominence of a crest over the troughs beside it (m).
        max_deviation_m: largest deviation on the ridge (m).
        n_crests: crests joined into it.
    """

    angle_deg: float
    quadrant: int
    r_inner_m: float
    r_outer_m: float
    length_m: float
    width_m: float
    amplitude_m: float
    max_deviation_m: float
    n_crests: int

    def to_dict(self) -> dict:
        """JSON-ready dict of the attributes."""
        return dataclasses.asdict(self)


def _element_size(p2: np.ndarray) -> float:
    from scipy.spatial import cKDTree

    d, _ = cKDTree(p2).query(p2, k=2)
    return float(np.median(d[:, 1]))


def polar_deviation(x, deviation, *, faces=None, r_inner: float, r_outer: float | None = None, dr: float = 1e-3,
                    n_theta: int = 720, centre=(0.0, 0.0)):
    """The deviation on a polar grid in the top view (step 1 of the census).

    Args:
        x: (N, 3) node positions of one ply, m; deviation: (N,) m.
        faces: (F, 3|4) its faces: the deviation is interpolated on the highest face over each
            sample (folds seen from above, like a scanner); without them, on the Delaunay
            triangulation of the nodes' top view (samples farther than 1.5 element sizes from
            every node are off the part).
        r_inner, r_outer: radii of the first and last ring, m (``r_outer`` default: the farthest node).
        dr: ring spacing, m; n_theta: angles per ring; centre: (2,) punch axis in the top view, m.

    Returns:
        ``(r (R,), theta (T,), values (R, T))``: NaN where a sample is off the part.
    """
    from scipy.spatial import cKDTree

    x = np.asarray(x, np.float64)
    dev = np.asarray(deviation, np.float64)
    if x.ndim != 2 or x.shape[1] != 3 or dev.shape != (x.shape[0],):
        raise ValueError(f"wrinkle census: x must be (N, 3) and deviation (N,); got {x.shape} and {dev.shape}")
    if not np.all(np.isfinite(x)) or not np.all(np.isfinite(dev)):
        raise ValueError("wrinkle census: x and deviation must be finite")
    if not dr > 0 or n_theta < 8:
        raise ValueError(f"wrinkle census: need dr > 0 and n_theta >= 8; got dr = {dr}, n_theta = {n_theta}")
    p2 = x[:, :2] - np.asarray(centre, np.float64)
    rad = np.hypot(p2[:, 0], p2[:, 1])
    r_out = float(rad.max()) if r_outer is None else float(r_outer)
    if not r_out > r_inner:
        raise ValueError(f"wrinkle census: the part ends at r = {r_out:.4g} m, inside r_inner = {r_inner:.4g} m")
    r = np.arange(float(r_inner), r_out + 0.5 * dr, dr)
    th = np.linspace(0.0, 2 * np.pi, n_theta, endpoint=False)
    q = np.stack([np.outer(r, np.cos(th)).ravel(), np.outer(r, np.sin(th)).ravel()], 1)
    if faces is None:
        from scipy.interpolate import griddata

        vals = griddata(p2, dev, q, method="linear")
        far, _ = cKDTree(p2).query(q)
        vals[far > 1.5 * _element_size(p2)] = np.nan
    else:
        vals = _on_faces(p2, x[:, 2], dev, np.asarray(faces), q)
    return r, th, vals.reshape(len(r), n_theta)


def _on_faces(p2, z, dev, faces, q, k: int = 12):
    """``dev`` interpolated at the top-view points ``q`` (Q, 2) on the highest face above each
    (NaN off the part). Quads are cut into four triangles at their centre (no diagonal chosen,
    so a mirror-symmetric mesh samples mirror-symmetrically)."""
    from scipy.spatial import cKDTree

    if faces.ndim != 2 or faces.shape[1] not in (3, 4) or faces.min() < 0 or faces.max() >= len(p2):
        raise ValueError(f"wrinkle census: faces must be (F, 3|4) node indices below {len(p2)}; got {faces.shape}")
    if faces.shape[1] == 4:
        c = len(p2) + np.arange(len(faces))
        p2 = np.concatenate([p2, p2[faces].mean(axis=1)])
        z = np.concatenate([z, z[faces].mean(axis=1)])
        dev = np.concatenate([dev, dev[faces].mean(axis=1)])
        faces = np.concatenate([np.stack([faces[:, i], faces[:, (i + 1) % 4], c], 1) for i in range(4)])
    A, B, C = p2[faces[:, 0]], p2[faces[:, 1]], p2[faces[:, 2]]
    _, cand = cKDTree((A + B + C) / 3.0).query(q, k=min(k, len(faces)))  # (Q, k)
    a, e1, e2 = A[cand], B[cand] - A[cand], C[cand] - A[cand]
    det = e1[..., 0] * e2[..., 1] - e1[..., 1] * e2[..., 0]
    rr = q[:, None, :] - a
    with np.errstate(divide="ignore", invalid="ignore"):
        l1 = (rr[..., 0] * e2[..., 1] - rr[..., 1] * e2[..., 0]) / det
        l2 = (e1[..., 0] * rr[..., 1] - e1[..., 1] * rr[..., 0]) / det
    l0 = 1.0 - l1 - l2
    inside = (det != 0) & (l0 >= -1e-9) & (l1 >= -1e-9) & (l2 >= -1e-9)
    f = faces[cand]  # (Q, k, 3)
    height = np.where(inside, l0 * z[f[..., 0]] + l1 * z[f[..., 1]] + l2 * z[f[..., 2]], -np.inf)
    j = np.argmax(height, axis=1)
    pick = lambda a: np.take_along_axis(a, j[:, None], axis=1)[:, 0]  # noqa: E731
    fj = f[np.arange(len(q)), j]
    vals = pick(l0) * dev[fj[:, 0]] + pick(l1) * dev[fj[:, 1]] + pick(l2) * dev[fj[:, 2]]
    return np.where(np.any(inside, axis=1), vals, np.nan)


def _ring_crests(v: np.ndarray, prominence_n: float):
    """Crests of one ring ``v`` (T,) with NaN off the part: ``(index, prominence, width)`` arrays
    (width in samples at half prominence); periodic where the whole ring is on the part."""
    from scipy.signal import find_peaks, peak_widths

    n = len(v)
    ok = np.isfinite(v)
    if not ok.any():
        return np.zeros(0, int), np.zeros(0), np.zeros(0)
    if ok.all():
        ext = np.concatenate([v, v, v])
        pk, props = find_peaks(ext, prominence=prominence_n)
        w = peak_widths(ext, pk, rel_height=0.5, prominence_data=(props["prominences"], props["left_bases"],
                                                                  props["right_bases"]))[0]
        mid = (pk >= n) & (pk < 2 * n)
        return pk[mid] - n, props["prominences"][mid], w[mid]
    # runs of samples on the part, taken circularly (a run may wrap past theta = 0)
    start = int(np.argmin(ok))  # an off-part sample: runs do not wrap past it
    order = (np.arange(n) + start) % n
    vv, oo = v[order], ok[order]
    idx, prom, wid = [], [], []
    edges = np.flatnonzero(np.diff(np.concatenate([[0], oo.astype(int), [0]])))
    for a, b in zip(edges[::2], edges[1::2]):
        seg = vv[a:b]
        if len(seg) < 3:
            continue
        pk, props = find_peaks(seg, prominence=prominence_n)
        if len(pk):
            w = peak_widths(seg, pk, rel_height=0.5, prominence_data=(props["prominences"], props["left_bases"],
                                                                      props["right_bases"]))[0]
            idx.append(order[a + pk])
            prom.append(props["prominences"])
            wid.append(w)
    if not idx:
        return np.zeros(0, int), np.zeros(0), np.zeros(0)
    return np.concatenate(idx), np.concatenate(prom), np.concatenate(wid)


def _smooth_rings(vals, r, dth, sigma):
    """Each ring smoothed along its arc by a Gaussian of standard deviation ``sigma`` (m), NaN
    (off the part) left out (normalised convolution): kinks of the piecewise-linear surface at
    element scale make no crests; a wrinkle narrower than an element is not resolved anyway."""
    from scipy.ndimage import gaussian_filter1d

    if sigma <= 0:
        return vals
    out = np.empty_like(vals)
    for i, v in enumerate(vals):
        ok = np.isfinite(v)
        sd = sigma / (r[i] * dth)
        num = gaussian_filter1d(np.where(ok, v, 0.0), sd, mode="wrap")
        den = gaussian_filter1d(ok.astype(float), sd, mode="wrap")
        out[i] = np.where(ok, num / np.maximum(den, 1e-12), np.nan)
    return out


def _raw_prominence(v, idx, half: int):
    """Prominence of the crests ``idx`` of a smoothed ring measured on the ring ``v`` itself (the
    highest sample within ``half`` samples of each; off-part samples as the ring's lowest value)."""
    from scipy.signal import peak_prominences

    if not len(idx):
        return np.zeros(0)
    n = len(v)
    w = np.where(np.isfinite(v), v, np.nanmin(v))
    ext = np.concatenate([w, w, w])
    win = (idx[:, None] + np.arange(-half, half + 1)[None]) % n
    top = win[np.arange(len(idx)), np.argmax(w[win], axis=1)]
    with warnings.catch_warnings():  # a highest sample on a plateau's edge: prominence 0, fine
        warnings.simplefilter("ignore")
        return peak_prominences(ext, top + n, wlen=n)[0]


def _vertex_offset(v: np.ndarray, j: int) -> float:
    """Sub-sample position of the crest at ``j`` of the periodic ring ``v``: the vertex of the
    parabola through it and its neighbours (0 where a neighbour is off the part), in (-0.5, 0.5)."""
    a, b, c = v[(j - 1) % len(v)], v[j], v[(j + 1) % len(v)]
    den = a - 2.0 * b + c
    if not (np.isfinite(a) and np.isfinite(c)) or den >= 0.0:
        return 0.0
    return float(np.clip(0.5 * (a - c) / den, -0.5, 0.5))


def wrinkle_census(x, deviation, *, faces=None, r_inner: float, r_outer: float | None = None, prominence: float = 0.5e-3,
                   max_width: float | None = None, min_length: float = 8e-3, link: float | None = None, max_gap: int = 2,
                   smooth: float | None = None, dr: float = 1e-3, n_theta: int = 720,
                   centre=(0.0, 0.0)) -> list[Wrinkle]:
    """The wrinkles of a flange (module docstring), largest amplitude first.

    Args:
        x: (N, 3) node positions of one ply, m; deviation: (N,) its deviation from the tool, m.
        faces: (F, 3|4) its faces (recommended; :func:`polar_deviation`).
        r_inner: the flange's inner radius, m (e.g. the die opening plus its fillet); r_outer:
            default the farthest node.
        prominence: least rise of a crest over the troughs on both sides, m (default 0.5 mm).
        max_width: widest ridge (median crest width at half prominence, arc length) that is a
            wrinkle, m; wider ones are lifted lobes (default None: every ridge counts; the 8 mm
            woven Case A flange has mid-side lobes 33 mm and diagonal ridges 45 mm wide, so a
            width alone does not tell them apart there).
        min_length: least radial extent of a wrinkle, m (default 8 mm).
        link: largest arc distance between crests of neighbouring rings of one ridge, m (default
            twice the element size, at least 3 mm).
        max_gap: rings a ridge may skip (crests dipping below ``prominence`` there).
        smooth: standard deviation of the Gaussian smoothing along each ring, m (default the
            element size; 0: none).
        dr, n_theta, centre: the polar grid (:func:`polar_deviation`).

    Returns:
        list of :class:`Wrinkle`.
    """
    r, th, vals = polar_deviation(x, deviation, faces=faces, r_inner=r_inner, r_outer=r_outer, dr=dr, n_theta=n_theta,
                                  centre=centre)
    p2 = np.asarray(x, np.float64)[:, :2]
    h = _element_size(p2)
    link = max(2.0 * h, 3e-3) if link is None else float(link)
    dth = 2 * np.pi / n_theta
    sigma = h if smooth is None else float(smooth)
    raw = vals
    vals = _smooth_rings(vals, r, dth, sigma)
    crests = []  # (ring, angle (sub-sample), prominence, width m, value)
    for i, v in enumerate(vals):
        idx, prom_s, wid = _ring_crests(v, prominence)
        # on the ring itself (smoothing lowers a narrow crest); never below the smoothed value
        prom = np.maximum(_raw_prominence(raw[i], idx, int(np.ceil(sigma / (r[i] * dth))) if sigma > 0 else 0), prom_s)
        # the width at half prominence with the smoothing taken out (exact for a Gaussian ridge)
        w_m = np.sqrt(np.maximum((wid * dth * r[i]) ** 2 - (2.3548 * sigma) ** 2, 0.0))
        for j, p, w in zip(idx, prom, w_m):
            crests.append((i, j + _vertex_offset(v, int(j)), float(p), float(w), float(v[j])))
    if not crests:
        return []
    ring = np.array([c[0] for c in crests])
    ang = np.array([c[1] for c in crests]) * dth
    parent = list(range(len(crests)))

    def find(a):
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a

    # crests come ring by ring (ring ascending): those of the next max_gap + 1 rings are a slice
    stop = np.searchsorted(ring, ring + max_gap + 1, side="right")
    first = np.searchsorted(ring, ring, side="right")
    for a in range(len(crests)):
        later = np.arange(first[a], stop[a])
        if not len(later):
            continue
        d = np.abs((ang[later] - ang[a] + np.pi) % (2 * np.pi) - np.pi) * np.minimum(r[ring[later]], r[ring[a]])
        for b in later[d <= link]:
            parent[find(int(b))] = find(a)
    groups: dict[int, list[int]] = {}
    for a in range(len(crests)):
        groups.setdefault(find(a), []).append(a)
    out = []
    for members in groups.values():
        rr = r[ring[members]]
        width = float(np.median([crests[m][3] for m in members]))
        if rr.max() - rr.min() < min_length or (max_width is not None and width > max_width):
            continue
        prom = np.array([crests[m][2] for m in members])
        a = ang[members]
        mean = float(np.degrees(np.arctan2(np.sum(prom * np.sin(a)), np.sum(prom * np.cos(a)))) % 360.0)
        # the ridge line: per ring, the prominence-weighted mean position of its crests
        pts = []
        for k in np.unique(ring[members]):
            sel = [m for m in members if ring[m] == k]
            w = np.array([crests[m][2] for m in sel])
            aa = ang[sel]
            c = np.arctan2(np.sum(w * np.sin(aa)), np.sum(w * np.cos(aa)))
            pts.append((r[k] * np.cos(c), r[k] * np.sin(c)))
        # every two element sizes (and the last): no zigzag from crests snapping to the mesh
        step = max(1, int(round(2.0 * h / dr)))
        pts = np.asarray(pts)
        pts = np.concatenate([pts[:-1:step], pts[-1:]])
        length = float(np.sum(np.hypot(*np.diff(pts, axis=0).T))) if len(pts) > 1 else 0.0
        out.append(Wrinkle(angle_deg=mean, quadrant=int(mean // 90.0) % 4 + 1, r_inner_m=float(rr.min()),
                           r_outer_m=float(rr.max()), length_m=length,
                           width_m=width,
                           amplitude_m=float(prom.max()), max_deviation_m=float(max(crests[m][4] for m in members)),
                           n_crests=len(members)))
    out.sort(key=lambda w: -w.amplitude_m)
    return out
