"""The fixed model and the changing state of an explicit fabric simulation.

``Model`` holds everything that does not change during a run (shell, masses, boundary conditions,
loads, time step); ``State`` holds what does (positions, velocities, time, energy accounts, the
state of external loads such as tools). Every stage is a pure function ``f(model, state) -> state``
(:func:`jaxform.integrate.step`).

External-force hook (for tools and contact, issue 4)
----------------------------------------------------
``Model.loads`` is a tuple of pytrees, each with a method::

    load.force(x, v, t, load_state) -> (f, new_load_state, extras)

``x``, ``v`` (N, 3) positions (m) and velocities (m/s) at the start of the step, ``t`` (s);
``f`` (N, 3) the force on every node (N); ``load_state`` the load's own state (any pytree, e.g. a
force-controlled blank holder's height and velocity; ``None`` for stateless loads), kept in
``State.loads`` (same order as ``Model.loads``) and advanced by the load itself; ``extras`` a dict
of small arrays (contact force, tool position...) saved in every frame under
``frames.extras[i]``. The integrator adds ``f`` to the internal, gravity and damping forces and
books its work as external work. A load must be a pure function of its arguments.

Contact integrated backward (optional): a load whose ``extras`` hold a ``"backward_support"``
entry (taken out of the extras by the integrator) also has a method::

    load.backward(support, p, mass, h, dt, extras, load_state) -> (f, extras, load_state)

called once every load's force is in, in ``Model.loads`` order, with ``p`` (N, 3) the trial
momentum at the end of the step (all other forces, and the backward forces of the loads before it,
applied), ``mass`` (N,) the lumped masses, ``h`` the step the force acts over and ``dt`` the step:
``f`` (N, 3) the force it adds (its friction, :mod:`jaxform.friction`, and with an implicit normal
its normal force, :mod:`jaxform.backward_normal`; booked as external work with the load's force),
the load's extras updated with it (:class:`jaxform.contact.ToolLoad`: its reaction and friction
power) and its state (a force-controlled holder advanced with the reaction of the step).

Prescribed motion: ``Model.fixed`` (N, 3) bool marks the degrees of freedom that are driven;
their positions follow ``Model.drive.position(t)`` (any pytree with that method; the default
:class:`Hold` keeps them at their initial positions, :class:`LinearDrive` moves them at constant
velocity). Reactions at driven dofs are booked as boundary work.
"""
from __future__ import annotations

from typing import Any

import jax.numpy as jnp

from jaxform._pytree import pytree_dataclass, static_field
from jaxform.shell import Shell


@pytree_dataclass
class Hold:
    """Driven dofs stay at ``x0`` (N, 3), m."""

    x0: Any

    def position(self, t):
        return self.x0


@pytree_dataclass
class LinearDrive:
    """Driven dofs move as ``x0 + velocity * t``: x0 (N, 3) m, velocity (N, 3) m/s."""

    x0: Any
    velocity: Any

    def position(self, t):
        return self.x0 + self.velocity * t


@pytree_dataclass
class Model:
    """Fixed description of a run.

    Attributes:
        shell: the fabric shell (mesh, reference, fabrics).
        mass: (N,) lumped node masses, kg (mass scaling included).
        fixed: (N, 3) bool, driven degrees of freedom.
        drive: pytree with ``position(t) -> (N, 3)`` giving driven positions, m.
        gravity: (3,) gravitational acceleration, m/s².
        damping: mass-proportional damping coefficient, 1/s (force ``-damping * m * v``).
        dt: time step, s.
        loads: tuple of external loads (see the module docstring).
        mass_scale: the factor applied to the physical masses (1 = none), for reports.
        fibre_mass: ``None`` or a :class:`~jaxform.fibre_mass.FibreMass`: inertia added to fibre
            stretching only (the inverse mass becomes a polynomial in the fibre stiffness).
    """

    shell: Shell
    mass: Any
    fixed: Any
    drive: Any
    gravity: Any
    damping: Any
    dt: Any
    loads: tuple = ()
    mass_scale: Any = 1.0
    fibre_mass: Any = None

    def replace(self, **changes) -> "Model":
        import dataclasses

        return dataclasses.replace(self, **changes)


@pytree_dataclass
class Energies:
    """Energy accounts, J: elastic parts, kinetic, and the work of each outside agent."""

    kinetic: Any
    tension: Any
    shear: Any
    bending: Any
    gravity_work: Any
    external_work: Any
    boundary_work: Any
    damping_work: Any

    @staticmethod
    def zeros(dtype=jnp.float32) -> "Energies":
        z = jnp.zeros((), dtype)
        return Energies(z, z, z, z, z, z, z, z)

    @property
    def internal(self):
        return self.tension + self.shear + self.bending

    def balance(self, e0: "Energies"):
        """Energy-balance residual: change of stored energy minus net work in, J (0 when exact)."""
        stored = self.kinetic + self.internal - e0.kinetic - e0.internal
        work = (self.gravity_work + self.external_work + self.boundary_work - self.damping_work) - (
            e0.gravity_work + e0.external_work + e0.boundary_work - e0.damping_work
        )
        return stored - work

    def scale(self):
        """A magnitude against which the balance is judged, J."""
        return (jnp.abs(self.kinetic) + jnp.abs(self.internal) + jnp.abs(self.gravity_work)
                + jnp.abs(self.external_work) + jnp.abs(self.boundary_work) + jnp.abs(self.damping_work))


@pytree_dataclass
class State:
    """Changing state.

    Attributes:
        x: (N, 3) positions, m.
        v: (N, 3) velocities at the previous half step, m/s.
        t: time, s.
        step: step count (int).
        energies: :class:`Energies` at the current step.
        loads: tuple of load states (same order as ``Model.loads``).
        f_prev: ((3, N),)*3 load, damping and reaction forces of the previous step, N, in
            structure-of-arrays layout (work accounts by the trapezoidal rule).
        bad_step: -1 while the run is healthy, else the first step that failed (run is frozen).
        bad_code: 0 ok, 1 non-finite values, 2 energy blow-up.
        scale_max: the largest energy scale seen, J.
        momentum: (3, N) momenta of the free dofs at the previous half step (SoA), kg·m/s (0 on
            driven dofs): the integrated quantity, ``v = C p`` with ``C`` the inverse mass
            (``M^-1``, or the fibre mass of :mod:`jaxform.fibre_mass`).
        u: (3, N) displacements from the mesh nodes (SoA), m: the integrated quantity (``x`` is
            ``X + u``; the shell is evaluated on ``u``, see :class:`~jaxform.shell.ShellRef`).
        u_lost: (3, N) what rounding took from ``u``'s last increments, m (compensated summation,
            :func:`jaxform.integrate.compensated_add`): increments of about 1e-6 m a step added to
            displacements of up to 0.05 m lose 0.2 % each in float32, alike step after step.
    """

    x: Any
    v: Any
    t: Any
    step: Any
    energies: Any
    loads: tuple
    f_prev: Any
    bad_step: Any
    bad_code: Any
    scale_max: Any
    momentum: Any
    u: Any
    u_lost: Any


__all__ = ["Model", "State", "Energies", "Hold", "LinearDrive"]
_ = static_field
