"""Laminate view of a fabric ply (source paper, appendix A, eqs. A.1 and A.2).

Abaqus users model a ply as a three-layer laminate: two surface layers of modulus ``E_surf`` and a
core of thickness ``t_core`` and modulus ``E_core``, so that membrane and bending stiffness are
decoupled:

* (A.1) ``B = E_surf (h - t_core) (h + t_core)^2 / 16``
* (A.2) ``E_ply = E_surf (h - t_core)/h + E_core t_core/h``

jaxform computes bending directly from the moment–curvature law; these conversions let a user move
numbers between an Abaqus layup and jaxform, both ways. SI units: moduli Pa, lengths m, B N·m.
"""
from __future__ import annotations

import numpy as np

from jaxform import validate


def _check_geometry(owner: str, h, t_core) -> None:
    validate.positive(owner, "h", h, "m")
    validate.positive(owner, "t_core", t_core, "m")
    if np.any(np.asarray(t_core) >= np.asarray(h)):
        raise ValueError(
            f"{owner}.t_core = {t_core!r} m >= h = {h!r} m: the core must be thinner than the ply (0 < t_core < h)"
        )


def laminate_moduli(e_ply, b, h, t_core):
    """Surface and core moduli of the three-layer laminate that gives ``e_ply`` and ``b``.

    Args:
        e_ply: nominal ply modulus along the fibre, Pa (> 0).
        b: bending stiffness per unit width along that fibre, N·m (> 0).
        h: ply thickness, m (> 0).
        t_core: core thickness, m (0 < t_core < h).

    Returns:
        ``(e_surf, e_core)`` in Pa.

    Raises:
        ValueError: on invalid input, or when ``b`` is too high for ``e_ply`` with this core
            (the core modulus would have to be negative).
    """
    owner = "laminate_moduli"
    validate.positive(owner, "e_ply", e_ply, "Pa")
    validate.positive(owner, "b", b, "N·m")
    _check_geometry(owner, h, t_core)
    e_surf = 16.0 * b / ((h - t_core) * (h + t_core) ** 2)
    e_core = (e_ply - e_surf * (h - t_core) / h) * h / t_core
    if np.any(np.asarray(e_core) < 0):
        raise ValueError(
            f"laminate_moduli: b = {b!r} N·m needs surface layers of {e_surf!r} Pa, which alone exceed "
            f"e_ply = {e_ply!r} Pa for h = {h!r} m, t_core = {t_core!r} m (core modulus would be negative); "
            "use a thicker core or check the units of b and e_ply"
        )
    return e_surf, e_core


def ply_properties(e_surf, e_core, h, t_core):
    """Nominal ply modulus and bending stiffness of a three-layer laminate.

    Args:
        e_surf: modulus of the two surface layers, Pa (> 0).
        e_core: modulus of the core, Pa (>= 0).
        h: ply thickness, m (> 0).
        t_core: core thickness, m (0 < t_core < h).

    Returns:
        ``(e_ply, b)``: Pa and N·m.
    """
    owner = "ply_properties"
    validate.positive(owner, "e_surf", e_surf, "Pa")
    validate.nonnegative(owner, "e_core", e_core, "Pa")
    _check_geometry(owner, h, t_core)
    b = e_surf * (h - t_core) * (h + t_core) ** 2 / 16.0
    e_ply = e_surf * (h - t_core) / h + e_core * t_core / h
    return e_ply, b


__all__ = ["laminate_moduli", "ply_properties"]
