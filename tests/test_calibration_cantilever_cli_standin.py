"""The small stand-in cantilever as an importable MODULE:FUNCTION for the command-line test."""
import functools

from test_calibration_standin import simulate_standin

simulate = functools.partial(simulate_standin, n=16, steps=4, newton=5)
