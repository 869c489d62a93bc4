"""Analytic test surfaces meshed with quads or triangles, with their exact principal curvatures.

Shared by the metric tests (not a test module itself). Lengths in m, curvatures in 1/m."""
from __future__ import annotations

import numpy as np


def grid_faces(nx: int, ny: int, kind: str) -> np.ndarray:
    """Faces of an nx-by-ny node grid (node id i*ny + j), counter-clockwise in the (i, j) plane."""
    i, j = np.meshgrid(np.arange(nx - 1), np.arange(ny - 1), indexing="ij")
    a = (i * ny + j).ravel()
    b, c, d = a + ny, a + ny + 1, a + 1
    if kind == "quad":
        return np.stack([a, b, c, d], axis=1)
    # triangles: alternate the diagonal in a checkerboard, so no direction is favoured
    flip = ((i + j) % 2 == 1).ravel()
    t1 = np.where(flip[:, None], np.stack([a, b, d], 1), np.stack([a, b, c], 1))
    t2 = np.where(flip[:, None], np.stack([b, c, d], 1), np.stack([a, c, d], 1))
    return np.concatenate([t1, t2])


def ring_depth(nx: int, ny: int) -> np.ndarray:
    """(N,) number of rings between each grid node and the boundary (0 on the boundary)."""
    i, j = np.meshgrid(np.arange(nx), np.arange(ny), indexing="ij")
    return np.minimum(np.minimum(i, nx - 1 - i), np.minimum(j, ny - 1 - j)).ravel()


def graph_curvatures(fx, fy, fxx, fxy, fyy):
    """Exact principal curvatures of z = f(x, y), upward normal, positive bending away from it."""
    g = 1.0 + fx**2 + fy**2
    K = (fxx * fyy - fxy**2) / g**2
    H = -((1 + fy**2) * fxx - 2 * fx * fy * fxy + (1 + fx**2) * fyy) / (2 * g**1.5)
    root = np.sqrt(np.maximum(H**2 - K, 0.0))
    return H + root, H - root


def surface(name: str, h: float, kind: str):
    """Mesh of an analytic surface with element size h (m); returns nodes, faces, k1, k2, depth."""
    if name == "torus":
        R, r = 0.040, 0.015
        nu = int(round(0.5 * R / h)) + 1  # u arc (at the tube centre) 20 mm
        nv = int(round(r * 2 * np.pi / 3 / h)) + 1  # a third of the tube
        u = np.linspace(0, (nu - 1) * h / R, nu)
        v = np.linspace(np.pi / 6, np.pi / 6 + (nv - 1) * h / r, nv)
        U, V = np.meshgrid(u, v, indexing="ij")
        rr = R + r * np.cos(V)
        x = np.stack([rr * np.cos(U), rr * np.sin(U), r * np.sin(V)], -1).reshape(-1, 3)
        # outward normal: (cos v cos u, cos v sin u, sin v); away-from-normal positive
        k_tube = np.full(U.size, 1.0 / r)
        k_ring = (np.cos(V) / rr).ravel()
        k1, k2 = np.maximum(k_tube, k_ring), np.minimum(k_tube, k_ring)
        # grid (u, v) wound counter-clockwise seen from outside: normal = x_u x x_v points out? check
        faces = grid_faces(nu, nv, kind)
        return x, faces, k1, k2, ring_depth(nu, nv)
    L = {"sphere": 0.020, "cylinder": 0.015, "saddle": 0.020, "wrinkle": 0.030}[name]
    n = int(round(2 * L / h)) + 1
    s = np.linspace(-L, L, n)
    X, Y = np.meshgrid(s, s, indexing="ij")
    if name == "sphere":
        R = 0.050
        Z = np.sqrt(R**2 - X**2 - Y**2)
        k1 = k2 = np.full(X.size, 1.0 / R)
    elif name == "cylinder":
        R = 0.020
        Z = np.sqrt(R**2 - X**2)
        k1, k2 = np.full(X.size, 1.0 / R), np.zeros(X.size)
    else:
        if name == "saddle":
            R = 0.030
            f = (X**2 - Y**2) / (2 * R)
            fx, fy, fxx, fxy, fyy = X / R, -Y / R, 1 / R + 0 * X, 0 * X, -1 / R + 0 * X
        else:  # sinusoidal wrinkle: 2 mm amplitude, 20 mm wavelength
            A, lam = 0.002, 0.020
            w = 2 * np.pi / lam
            f = A * np.sin(w * X)
            fx, fy = A * w * np.cos(w * X), 0 * X
            fxx, fxy, fyy = -A * w**2 * np.sin(w * X), 0 * X, 0 * X
        Z = f
        k1, k2 = graph_curvatures(fx, fy, fxx, fxy, fyy)
        k1, k2 = k1.ravel(), k2.ravel()
    x = np.stack([X, Y, Z], -1).reshape(-1, 3)
    return x, grid_faces(n, n, kind), k1, k2, ring_depth(n, n)


def cube_sphere(R: float, h: float, kind: str):
    """Closed sphere of radius R meshed from a subdivided cube (element size about h), outward
    counter-clockwise faces. Returns nodes (N, 3) m and faces."""
    m = max(2, int(round(0.5 * np.pi * R / h)))
    t = np.tan(np.linspace(-np.pi / 4, np.pi / 4, m + 1))  # equal-angle cube grid
    pts, faces = [], []
    for axis in range(3):
        for sign in (-1.0, 1.0):
            A, B = np.meshgrid(t, t, indexing="ij")
            P = np.zeros(A.shape + (3,))
            P[..., axis] = sign
            P[..., (axis + 1) % 3] = A
            P[..., (axis + 2) % 3] = B
            base = sum(len(p) for p in pts)
            pts.append(P.reshape(-1, 3))
            f = grid_faces(m + 1, m + 1, "quad") + base
            if sign < 0:
                f = f[:, ::-1]
            faces.append(f)
    P = np.concatenate(pts)
    F = np.concatenate(faces)
    key = np.round(P * 1e9).astype(np.int64)
    _, first, inv = np.unique(key, axis=0, return_index=True, return_inverse=True)
    nodes = P[first]
    nodes = R * nodes / np.linalg.norm(nodes, axis=1, keepdims=True)
    F = inv.reshape(-1)[F]
    if kind == "tri":
        F = np.concatenate([F[:, [0, 1, 2]], F[:, [0, 2, 3]]])
    return nodes, F


def draped_sheet(h=0.001, half=0.035, R=0.05, H_PLY=0.3e-3):
    """A ply of thickness ``H_PLY`` lying on a hemisphere of radius ``R`` (mid-plane at 0.9 h/2 from it), with a 1.5 mm bump of
    radius ~2 mm (a wrinkle) at (18, 0) mm and a region lifted smoothly by 2 mm over a 14 mm radius
    (bridging) at (-20, 0) mm; ``h`` is the node spacing. Returns nodes, faces, bump and lift (m) per node."""
    n = int(round(2 * half / h)) + 1
    s = np.linspace(-half, half, n)
    X, Y = np.meshgrid(s, s, indexing="ij")
    bump = 0.0015 * np.exp(-((X - 0.018) ** 2 + Y**2) / 0.0015**2)
    rho = np.hypot(X + 0.020, Y)
    lift = np.where(rho < 0.014, 0.002 * np.cos(0.5 * np.pi * rho / 0.014) ** 2, 0.0)
    extra = bump + lift
    r = R + 0.45 * H_PLY + extra  # radial position: distance to the sphere = 0.45 h + extra
    dirs = np.stack([X, Y, np.sqrt(R**2 - X**2 - Y**2)], -1) / R
    nodes = (dirs * r[..., None]).reshape(-1, 3)
    return nodes, grid_faces(n, n, "quad"), bump.ravel(), lift.ravel()
