"""The contact's parameters for an explicit step: the automatic penalty stiffness, its checks, and
the same contact for another step or stiffness (host-side choices; the physics is
:mod:`jaxform.contact`).

Penalty stiffness (automatic)
    A node of mass ``m = rho_A A`` on a contact spring ``k A`` oscillates at ``omega**2 = k /
    rho_A``, independent of the mesh. :func:`auto_penalty_stiffness` takes ``k = s * rho_A /
    dt**2`` (default ``s = 0.1``: ``omega dt = 0.32``, which takes about 1% off the stable step of
    a shell already at 90% of its own) and reports the penetration ``p / k`` under an expected
    pressure, which should stay small against the ply thickness.
"""
from __future__ import annotations

import dataclasses
import math

import jax.numpy as jnp

from jaxform import validate
from jaxform._pytree import is_concrete
from jaxform.contact import ContactParams, ToolLoad

EXPECTED_PRESSURE = 1.0e5  # Pa, where the penetration is checked (above the paper's 1000 N holder pressure)
MAX_PENETRATION = 0.1  # the largest penetration under EXPECTED_PRESSURE, a fraction of the ply thickness


def auto_penalty_stiffness(areal_mass, dt, *, safety: float = 0.1):
    """Penalty stiffness per unit area, Pa/m, that keeps the contact stable in an explicit step.

    ``k = safety * areal_mass / dt**2``: the contact frequency of a node is ``sqrt(k / rho_A)``
    whatever its area, so ``omega_c dt = sqrt(safety)``.

    Args:
        areal_mass: mass per unit area the integrator uses (after mass scaling; for a node shared
            by a stack, the smallest ply's), kg/m².
        dt: time step, s.
        safety: ``(omega_c dt)**2``, default 0.1.
    """
    if is_concrete(areal_mass, dt, safety):
        validate.positive("auto_penalty_stiffness", "areal_mass", areal_mass, "kg/m²")
        validate.positive("auto_penalty_stiffness", "dt", dt, "s")
        validate.in_range("auto_penalty_stiffness", "safety", safety, 0.0, 1.0)
    return safety * areal_mass / dt**2


def stable_damping_ratio(safety: float) -> float:
    """Largest contact damping ratio a stable explicit step allows with the automatic stiffness
    ``k = safety rho_A / dt^2`` (``omega dt = sqrt(safety)``): central differences with velocity
    damping stay stable while ``omega dt <= 2 (sqrt(1 + zeta^2) - zeta)``, i.e. ``zeta <= (4 -
    safety) / (4 sqrt(safety))``."""
    return (4.0 - safety) / (4.0 * math.sqrt(safety))


def contact_params(areal_mass, dt, thickness, *, friction: float = 0.23, slip_velocity: float = 1.0e-3,
                   stiffness=None, damping_ratio: float = 0.1, expected_pressure: float = EXPECTED_PRESSURE,
                   max_penetration: float = MAX_PENETRATION, safety: float = 0.1, two_sided: bool = False,
                   interfaces: int = 1) -> ContactParams:
    """:class:`ContactParams` with the penalty stiffness chosen automatically (or ``stiffness``)
    and the stick limit ``interfaces * dt / areal_mass``, doubled for ``two_sided`` (ply-on-ply)
    contact; ``interfaces``: how many explicitly integrated frictional contacts a node can have at
    once (the stick dampers of all act on it and their ratios add up; 0 where the loads integrate
    the friction backward, without a limit: :class:`jaxform.contact.ToolLoad`,
    :class:`jaxform.contact.PlyLoad` and the self-contact, as the forming rig builds them).

    Also checks, at the edge, that the penetration under ``expected_pressure`` (Pa; 1e5 Pa is well
    above the holder pressure of the paper's 1000 N case) stays below ``max_penetration`` times
    the ply ``thickness``; otherwise the step is too large for a stiff enough contact and a
    ``ValueError`` says so. ``damping_ratio`` sets ``c = 2 zeta sqrt(k rho_A)``.
    """
    k = auto_penalty_stiffness(areal_mass, dt, safety=safety) if stiffness is None else stiffness
    if is_concrete(k, thickness, expected_pressure):
        validate.positive("contact_params", "stiffness", k, "Pa/m")
        pen = float(expected_pressure) / float(k)
        if pen > max_penetration * float(thickness):
            raise ValueError(
                f"contact_params: stiffness = {float(k):.3g} Pa/m gives a penetration of {pen * 1e3:.3g} mm "
                f"under {float(expected_pressure):.3g} Pa, more than {max_penetration:g} x the ply thickness "
                f"({float(thickness) * 1e3:.3g} mm); use a smaller time step (less mass scaling) or give "
                "a larger stiffness with a smaller step"
            )
    c = 2.0 * damping_ratio * jnp.sqrt(k * areal_mass) if damping_ratio else 0.0
    limit = (2.0 if two_sided else 1.0) * interfaces * dt / areal_mass
    return ContactParams(stiffness=k, friction=friction, slip_velocity=slip_velocity, stick_limit=limit,
                         damping=float(c) if is_concrete(c) else c)


def rescaled_load(load, *, step: float = 1.0, stiffness: float = 1.0):
    """A load with contact ``params`` (:class:`ToolLoad`, :class:`PlyLoad`, a self-contact) for a
    step ``step`` times as long and a penalty ``stiffness`` times as stiff, in the same pytree
    structure: the stick limit follows the step (``n dt / rho_A``), the damping ``sqrt(k)`` (the
    same ratio); so do a force-controlled holder's step and its damping on the contact."""
    p = load.params
    out = dataclasses.replace(load, params=dataclasses.replace(
        p, stiffness=p.stiffness * stiffness, damping=p.damping * math.sqrt(stiffness), stick_limit=p.stick_limit * step))
    if isinstance(load, ToolLoad):
        out = dataclasses.replace(out, dt=load.dt * step, damping=load.damping * math.sqrt(stiffness))
    return out


__all__ = ["EXPECTED_PRESSURE", "MAX_PENETRATION", "auto_penalty_stiffness", "stable_damping_ratio", "contact_params",
           "rescaled_load"]
