"""Host-side input/output: files, meshio, trimesh. Kernels never import this package.

Conversion between host arrays and device arrays happens here, once, at the edge (STYLE habit 10).
"""
