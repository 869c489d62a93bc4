"""Host-side plotting with matplotlib (Agg backend). Kernels never import this package."""
