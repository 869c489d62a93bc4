"""Calibration: fit bending laws to cantilever side profiles and shear laws to picture-frame data.

Pure functions on arrays (no files, no printing): :mod:`~jaxform.calibrate.transforms` (the
law parameters and the strips' similarity), :mod:`~jaxform.calibrate.cantilever_data` (noise, bending
length and clamp moment read off a profile), :mod:`~jaxform.calibrate.profiles` (a simulated profile at
the measured points, its curvature), :mod:`~jaxform.calibrate.cantilever_fit` (bending laws through the
shell cantilever, on ``scipy.optimize.least_squares``) and :mod:`~jaxform.calibrate.shear_fit`
(shear laws, checked on the shell's picture frame), :mod:`~jaxform.calibrate.sections` (measured
wrinkle sections and their position-tolerant residual), :mod:`~jaxform.calibrate.section_runs` (the
forming runs behind them), :mod:`~jaxform.calibrate.starts` (the wrinkle fit's starting laws) and :mod:`~jaxform.calibrate.wrinkle_fit` (the bending law from wrinkle sections through the forming run, optionally with profiles). The scripts in ``calibration/`` and the readers
in :mod:`jaxform.io.calibration_files` sit on top. SI units throughout.
"""
from __future__ import annotations

from jaxform.calibrate.cantilever_fit import (
    CantileverFit,
    FitProgress,
    Profile,
    bounds,
    estimate_noise,
    fit_cantilever,
    initial_guess,
    peirce_b,
)
from jaxform.calibrate.sections import Section, check_section
from jaxform.calibrate.wrinkle_fit import WrinkleFit, fit_wrinkles
from jaxform.calibrate.profiles import discrete_curvature, interp_profile
from jaxform.calibrate.shear_fit import (
    ShearFit,
    check_shear_fit,
    fit_shear_ncf,
    fit_shear_polynomial,
    picture_frame_normalised_force,
    picture_frame_shear_angle,
)
from jaxform.calibrate.transforms import law_from_q, q_from_law
from jaxform.cantilever import chord_angle, standard_test
from jaxform.units import GRAVITY

__all__ = [
    "GRAVITY", "Profile", "CantileverFit", "FitProgress", "ShearFit", "law_from_q", "q_from_law", "interp_profile",
    "discrete_curvature", "peirce_b", "initial_guess", "bounds", "estimate_noise", "fit_cantilever", "standard_test", "chord_angle",
    "fit_shear_polynomial", "fit_shear_ncf", "picture_frame_normalised_force", "picture_frame_shear_angle",
    "check_shear_fit", "Section", "check_section", "WrinkleFit", "fit_wrinkles",
]
