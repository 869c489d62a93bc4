"""The force-controlled blank holder: a 1-DOF rigid body under a clamping force, advanced with the
same central-difference (leapfrog) scheme as the fabric (:class:`jaxform.contact.ToolLoad` with
``force_controlled``)."""
from __future__ import annotations

from typing import Any

from jaxform._pytree import pytree_dataclass


@pytree_dataclass
class HolderState:
    """State of a force-controlled blank holder (1 DOF, vertical).

    Attributes:
        dz: () vertical displacement from its reference pose, m.
        vz: () vertical velocity at the last half step, m/s (leapfrog).
    """

    dz: Any = 0.0
    vz: Any = 0.0


def holder_step(state: HolderState, reaction_z, *, mass, force, dt, damping=0.0) -> HolderState:
    """Advance the blank holder one central-difference step.

    ``m a = -force + R_z - c v``, ``v_{n+1/2} = v_{n-1/2} + dt a_n``, ``z_{n+1} = z_n + dt
    v_{n+1/2}`` — the same leapfrog as the fabric.

    Args:
        state: :class:`HolderState` at step n.
        reaction_z: () vertical force of the fabric on the holder at step n, N (the ``reaction[2]``
            of :func:`tool_contact` for the holder).
        mass: () holder mass, kg (a numerical parameter: any mass with
            ``sqrt(k_contact / mass) dt < 2`` is stable).
        force: () prescribed clamping force pushing the holder down, N (1000 N for Case B),
            including the holder's weight.
        dt: () time step, s.
        damping: () viscous damping of the holder, N·s/m.
    """
    a = (-force + reaction_z - damping * state.vz) / mass
    vz = state.vz + dt * a
    return HolderState(dz=state.dz + dt * vz, vz=vz)


__all__ = ["HolderState", "holder_step"]
