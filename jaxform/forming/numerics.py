"""The numerics of a forming run chosen from the case: the fibre-mass factor, and the time step
with the contact stiffness (host-side, no physics of its own; :mod:`jaxform.forming.rig` builds
the run with them).

* :func:`auto_fibre_mass`: ``numerics.fibre_mass_scaling = "auto"``;
* :func:`contact_numerics`: ``contact.safety = "auto"`` (the presets' default): a contact stiff
  enough, and a step stable with four contacts pressing one node.
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np

from jaxform.penalty import EXPECTED_PRESSURE, MAX_PENETRATION
from jaxform.forming.case import Case
from jaxform.forming.speed import along_edges
from jaxform.shell import Shell
from jaxform.spectrum import ply_frequencies

FIBRE_MASS_MAX = 12.0
"""The largest automatic fibre-mass factor for plies whose fibres run along the square blank's
edges: the largest run to completion here (woven Case A at 2 mm, twice). More fails: woven Case A
NLBM at 4 mm (``benchmarks/results/fibre-springs-20261207``) with 24 blew up at 27 mm of stroke
without the momentum term and at 35 and 48 mm with it (the step cut to 1/8 did not save it), and
with 48 at 17 mm, then needed the term, step cuts to 1/8 and the contact 64x stiffer to finish,
9.7 deg (p95) from the run with 12; the products a larger factor costs would have bought at most
2.3x fewer steps' time at 2 mm. Measured again with the contact the numerics now choose at 24 (its
normal forces backward, as stiff as with 12; ``benchmarks/results/step-pieces-20261207``): the
energy balance failed at 27.2 mm without the term and at 34.2 mm with it, the contact went 64x
stiffer, KE/IE 0.23, the symmetry lost, and it took twice as long as with 12 (308 s against 149 s)."""
FIBRE_MASS_MAX_OFF_AXIS = 3.0
"""The largest automatic factor for plies whose fibres run off the blank's edges (more than 10
degrees, e.g. the +-45 deg NCF). Their corners are held in-plane by shear alone and whip, and the
position-dependent inverse mass (it follows the fibre directions without the term a varying mass
adds to the momentum balance) pumps energy into them: measured on NCF Case A, 4 mm: 3 completes,
6 and 12 blow up at 94% and 88% of the stroke; 2 mm: 6 completed, 12 blew up at 79% (a 3 m/s
corner oscillation growing to 170 m/s in 150 steps, with the step within the linear limit,
omega dt / 2 = 0.24 by power iteration on C K at that state; half the step, or no fibre mass, ran
on). With the term (``numerics.fibre_mass_momentum_term``) the cap does not apply: both ran to
completion with 12."""
FIBRE_MASS_RESERVE = 1.25
"""The automatic fibre-mass factor brings the step to within this factor of the bending limit."""


def auto_fibre_mass(shell: Shell, mass_scale=1.0, momentum_term: bool = False, frequencies: list | None = None) -> float:
    """``numerics.fibre_mass_scaling = "auto"``: the smallest factor ``s`` that brings the shell's
    stable step to within :data:`FIBRE_MASS_RESERVE` of its bending limit (``sqrt(omega_b^2 +
    (omega_m / s)^2) <= 1.25 omega_b``, i.e. ``s >= omega_m / (0.75 omega_b)``: more would buy
    less than 25% of step), rounded up to a whole number, at most :data:`FIBRE_MASS_MAX`
    (:data:`FIBRE_MASS_MAX_OFF_AXIS` when a ply's fibres run off the blank's edges); 1 where the
    membrane does not set the step (``omega_m / omega_b`` grows with the element size). Woven
    Case A: 12 at 8, 4 and 2 mm (285, 147 and 74 wanted with the bending eigenvalue of
    :func:`jaxform.spectrum.ply_frequencies`); NCF (+-45 deg): 3 (72, 37 and 18 wanted at 8, 4
    and 2 mm); membrane only: 12. With the fibre mass's momentum term (``momentum_term``,
    :func:`jaxform.fibre_mass.geometric_force`) the off-axis cap does not apply: NCF Case A ran to
    completion with 12 at 4 mm (183 s, as with 3) and 2 mm (2449 s; 6 without the term: 1385 s).
    ``frequencies``: :func:`jaxform.spectrum.ply_frequencies` where the caller has them."""
    need, cap = 1.0, FIBRE_MASS_MAX
    for (wm, wb), fab in zip(ply_frequencies(shell, mass_scale) if frequencies is None else frequencies, shell.fabrics):
        need = max(need, FIBRE_MASS_MAX if wb <= 0 else wm / (math.sqrt(FIBRE_MASS_RESERVE**2 - 1.0) * wb))
        if not along_edges(fab.fibre_angles) and not momentum_term:
            cap = min(cap, FIBRE_MASS_MAX_OFF_AXIS)
    return float(min(cap, math.ceil(need)))


STEP_BUDGET = 0.9
"""The explicit step's budget: ``omega dt <= 2 x STEP_BUDGET`` at the stiffest node, its shell and
its contacts together (``omega^2`` adds up: the largest eigenvalue of ``M^-1 (K_shell + K_contact)``
is at most the sum of theirs); the margin below 2 covers the contacts' normal damping."""
EXPLICIT_STEP = 0.75
"""The step as a fraction of the shell's stable step where the contacts' normal forces are explicit:
the rest of the budget (:data:`STEP_BUDGET`) is the contacts' room, 0.2475 of safety with
:data:`STACKED_CONTACTS` of them on a node."""
BACKWARD_STEP = STEP_BUDGET
"""The step as a fraction of the shell's stable step where the contacts' normal forces are integrated
backward (:mod:`jaxform.backward_normal`): they take nothing from the step, so the shell has the
whole budget (``omega dt / 2 = 0.9`` at its stiffest mode), 1.2x the explicit :data:`EXPLICIT_STEP`."""
STACKED_CONTACTS = 4
"""Contact springs counted on one node: a node of a layer pressed between two others (a fold
under the holder, a stack) has two, and the highest mode of a chain of such layers approaches
``omega^2 = 4 k / m`` (Gershgorin), so 4 covers any depth of stacking."""
AUTO_SAFETY = 0.1
"""The least automatic contact safety ``(omega_c dt)^2``: where the shell sets the step the contact
takes the room it leaves in the step budget (0.2475 at 0.75 x the shell's stable step), this where
the room is smaller (a step closer to the shell's limit)."""
GAP_EXPECTED_PRESSURE = 1.0e4
"""Pa: the expected pressure where nothing clamps the blank (a holder at a fixed gap, Case A):
the tools then press the fabric only with its own tension and bending. Largest nodal contact
pressure over the frames of Case A at 62.5 mm/s: woven NLBM 1.7 kPa at 8 mm, 0.91 kPa at 4 mm;
woven LBM B_inf 3.2 kPa at 4 mm. A run that exceeds it is seen: its deepest penetration is
recorded, and beyond half the ply it stops (:func:`jaxform.forming.rig.health_bounds`)."""

STIFFEN_PENETRATION = 0.25
"""A fraction of the ply thickness: where a node of a run with an automatic contact penetrates a
tool or ply deeper than this (2.5 times what the contact is chosen for at its expected pressure),
the run's pressures exceed that expectation and the driver stiffens the contact
(:data:`CONTACT_STIFFEN`, :meth:`jaxform.forming.driver.Standing.recover`). Measured at 8 mm and
the automatic speeds: every NCF Case A preset went beyond (0.31-0.50 h; 23-46 kPa on the die's
entry radius, where the +-45 deg fibres are drawn over it in tension, against 0.4 kPa woven),
Case B NCF to 0.45 h (0.46 MPa there, against its 0.1 MPa); woven Case A stays below 0.08 h."""
CONTACT_STIFFEN = 4.0
"""The factor by which the driver stiffens an automatic contact each time (with the step halved:
``k dt^2``, the contact's share of the step budget, stays, so the step stays as stable as it was)."""
CONTACT_RAMP = CONTACT_STIFFEN ** (1.0 / 8.0)
"""The most the driver stiffens the contact from one chunk to the next (so 8 chunks to
:data:`CONTACT_STIFFEN`): a node held at a penetration ``delta`` is kicked off at about
``omega delta (1 - 1/f)`` by a contact ``f`` times as stiff at once."""


def expected_pressure(case: Case) -> tuple[float, str]:
    """``(pressure Pa, why)``: the contact pressure the automatic penalty keeps below
    ``MAX_PENETRATION`` of the ply (``contact.expected_pressure_Pa``; ``"auto"``: :data:`GAP_EXPECTED_PRESSURE`
    with a holder at a fixed gap, :data:`EXPECTED_PRESSURE` with a clamped one (5x the mean
    pressure of the paper's 1000 N on Case B's flange, where wrinkle crests carry it)). A softer
    contact allows a longer step; the run checks its penetration (:mod:`jaxform.forming.driver`)."""
    if case.contact.expected_pressure is not None:
        return float(case.contact.expected_pressure), "given"
    if case.holder.mode == "gap":
        return GAP_EXPECTED_PRESSURE, "auto: nothing clamps the blank (holder at a fixed gap)"
    return EXPECTED_PRESSURE, "auto: a clamped holder"


@dataclasses.dataclass(frozen=True)
class ContactNumerics:
    """The time step and contact stiffness chosen together (:func:`contact_numerics`).

    Attributes:
        dt_max: the largest step allowed, s (the frame intervals then round it down).
        safety: contact safety ``(omega_c dt)^2`` at ``dt_max`` (``k = safety rho_A / dt^2``).
        governed_by: ``"shell"`` (the shell's stable step times ``dt_safety``), ``"contact"``
            (a stiff enough contact needs a smaller step), or ``"user"`` (a given ``dt``).
        budget: ``(omega dt / 2)`` at the stiffest node with :data:`STACKED_CONTACTS` contacts,
            at ``dt_max`` (stable below 1; the automatic choice keeps it <= :data:`STEP_BUDGET`).
        why: one sentence for the summary.
        implicit_normal: the contacts' normal forces are integrated backward
            (:mod:`jaxform.backward_normal`; ``contact.implicit_normal``, automatic: see
            :func:`contact_numerics`).
    """

    dt_max: float
    safety: float | None
    governed_by: str
    budget: float
    why: str
    implicit_normal: bool = False


def _choose(case: Case, fabrics, stable: float, dt: float | None, dt_safety: float | None,
            implicit: bool) -> ContactNumerics:
    """Choose the time step and the contact safety together (the automatic numerics of contact),
    with the contacts' normal forces explicit or, ``implicit``, backward.

    The contact must be stiff enough: ``k >= k_need = p / (f h)`` (``p`` from :func:`expected_pressure`,
    ``f`` :data:`MAX_PENETRATION`), and the
    step stable with :data:`STACKED_CONTACTS` contacts on a node: ``(omega_s dt)^2 + n_c safety <=
    (2 STEP_BUDGET)^2`` with ``omega_s = 2 / stable`` the shell's (fibre mass included) and
    ``safety = k dt^2 / rho_A``. ``dt_safety`` (default :data:`EXPLICIT_STEP`, with the normal
    backward :data:`BACKWARD_STEP`): the step's fraction of ``stable``. Automatic safety
    (``contact.safety = "auto"``): the step is ``dt_safety x stable`` and the safety the room the shell leaves in the budget
    (``((2 STEP_BUDGET)^2 - (omega_s dt)^2) / n_c``: 0.2475 at ``dt_safety`` 0.75; at least
    :data:`AUTO_SAFETY`) where that is stiff enough for ``k_need``: the stiffest contact the step
    allows, at no cost (a softer one only penetrates deeper: NCF Case A at 4 mm with 0.1 sank
    0.132 h into a tool, beyond the 0.1 h the penalty is chosen for); beyond that the step shrinks to
    ``dt = 2 STEP_BUDGET / sqrt(omega_s^2 + n_c k_need / rho_A)`` with ``k = k_need`` (2% above
    the limit). Backward (``implicit``): any stiffness is stable, so the step is the shell's alone
    and the penalty at least as stiff as the explicit rule's at its own step (and ``k_need``). A given
    safety or stiffness is kept (the step capped so that ``k >= k_need`` as before), and a budget
    above 1 is reported (``budget``) and warned about.
    """
    c = case.contact
    rho = float(np.max(np.asarray(fabrics[0].areal_mass))) * float(case.mass_scaling)
    p_exp = expected_pressure(case)[0]
    k_lim = p_exp / (MAX_PENETRATION * float(case.ply_thickness))
    k_need = 1.02 * k_lim  # 2% stiffer, so that rounding never trips contact_params' penetration check
    w_s2 = (2.0 / stable) ** 2
    n_c, lim = STACKED_CONTACTS, (2.0 * STEP_BUDGET) ** 2

    def budget(dt_, s_):
        return 0.5 * math.sqrt(w_s2 * dt_**2 + n_c * s_)

    def room(dt_):  # the safety the shell leaves the contacts in the budget at step dt_ (at least AUTO_SAFETY)
        return max(AUTO_SAFETY, (lim - w_s2 * dt_**2) / n_c)

    if implicit and (case.holder.mode == "force" or case.n_plies > 1):
        raise ValueError(
            "contact.implicit_normal = true: not with a clamped holder (holder.mode = 'force') or a stack of "
            f"plies (here {case.n_plies}): there contacts press nodes from both sides, where the backward "
            "normal's local solve holds a penalty no stiffer than about rho_A / dt^2 (a clamped stack needs "
            "about 9x that at the shell's step to keep 1e5 Pa within 0.1 h); use the explicit contact "
            "(contact.implicit_normal = false, or \"auto\", the default)")
    if dt is not None:
        s_ = c.safety if c.safety is not None else AUTO_SAFETY
        if c.penalty_stiffness is not None:
            s_ = float(c.penalty_stiffness) * float(dt) ** 2 / rho
        return ContactNumerics(float(dt), c.safety if c.safety is not None else AUTO_SAFETY, "user",
                               budget(float(dt), 0.0 if implicit else s_), "the time step was given", implicit)
    if dt_safety is None:
        dt_safety = BACKWARD_STEP if implicit else EXPLICIT_STEP
    dt0 = dt_safety * stable
    if implicit and c.safety is None:  # the contact takes nothing from the step (jaxform.backward_normal)
        dt_e = EXPLICIT_STEP * stable  # the explicit rule's step and room: a contact at least as stiff as that one
        k = c.penalty_stiffness if c.penalty_stiffness is not None else max(k_need, room(dt_e) * rho / dt_e**2)
        s_ = k * dt0**2 / rho
        return ContactNumerics(dt0, s_, "shell", 0.5 * math.sqrt(w_s2) * dt0,
                               f"step {dt_safety:g} x the shell's stable step; the contacts' normal forces integrated "
                               f"backward (any stiffness stable): safety {s_:.3g} (penetration below "
                               f"{MAX_PENETRATION:g} h at {p_exp:.3g} Pa, at least as stiff as the explicit contact)", True)
    if c.penalty_stiffness is not None:
        s_ = float(c.penalty_stiffness) * dt0**2 / rho
        return ContactNumerics(dt0, None, "shell", budget(dt0, s_), "the contact stiffness was given; "
                               f"step {dt_safety:g} x the shell's stable step", implicit)
    if c.safety is not None:  # the user's safety: the step capped so that k >= k_need
        dt_c = 0.98 * math.sqrt(c.safety * rho / k_lim)
        dt_ = min(dt0, dt_c)
        return ContactNumerics(dt_, c.safety, "shell" if dt0 <= dt_c else "contact",
                               budget(dt_, 0.0 if implicit else c.safety),
                               f"contact.safety = {c.safety:g} was given", implicit)
    s_need = k_need * dt0**2 / rho
    if s_need <= room(dt0):
        s_ = room(dt0)  # the room the shell leaves in the budget: the stiffest contact at no step cost
        return ContactNumerics(dt0, s_, "shell", budget(dt0, s_),
                               f"step {dt_safety:g} x the shell's stable step; contact safety {s_:.3g} "
                               f"(penetration below {MAX_PENETRATION:g} h at {p_exp:.3g} Pa)", implicit)
    dt_ = 2.0 * STEP_BUDGET / math.sqrt(w_s2 + n_c * k_need / rho)
    s_ = k_need * dt_**2 / rho
    return ContactNumerics(dt_, s_, "contact", budget(dt_, s_),
                           f"a contact stiff enough for a penetration below {MAX_PENETRATION:g} h at "
                           f"{p_exp:.3g} Pa and stable with {n_c} contacts on a node needs a step of "
                           f"{dt_:.3g} s (shell: {dt0:.3g} s); contact safety {s_:.3g}", implicit)


def contact_numerics(case: Case, fabrics, stable: float, dt: float | None,
                     dt_safety: float | None = None) -> ContactNumerics:
    """Choose the time step, the contact safety and how the contacts' normal forces are integrated.

    ``contact.implicit_normal = "auto"`` (the default): integrated backward
    (:mod:`jaxform.backward_normal`) wherever that holds, i.e. one ply under a holder at a fixed gap
    with the step and the contact's safety and stiffness automatic: the contact then takes nothing
    from the step, which is :data:`BACKWARD_STEP` (0.9) of the shell's stable step against the
    explicit rule's :data:`EXPLICIT_STEP` (0.75; less where a stiff enough contact sets it), with a
    penalty at least as stiff as the explicit rule's. Explicit everywhere else (a clamped holder or a
    stack: refused, :func:`_choose`; a given step, safety or stiffness). Woven Case A at 8 mm, where
    the explicit contact set the step: 35,600 steps of 2.36e-5 s instead of 48,000 of 1.75e-5 s at
    0.75 (README, "Contact normal forces integrated backward"), now 0.9. ``true``/``false`` are kept
    as given. ``dt_safety``: the step's fraction of ``stable`` (default by the integration chosen).
    The explicit and backward choices: :func:`_choose`."""
    c = case.contact
    if c.implicit_normal is not None:
        return _choose(case, fabrics, stable, dt, dt_safety, bool(c.implicit_normal))
    n = _choose(case, fabrics, stable, dt, dt_safety, False)
    if (dt is not None or case.holder.mode != "gap" or case.n_plies != 1 or c.safety is not None
            or c.penalty_stiffness is not None):
        return n
    m = _choose(case, fabrics, stable, dt, dt_safety, True)
    return dataclasses.replace(m, why=f"{m.why} (contact.implicit_normal auto; the explicit contact: "
                                      f"{n.dt_max:.3g} s)")


__all__ = ["FIBRE_MASS_MAX", "FIBRE_MASS_MAX_OFF_AXIS", "FIBRE_MASS_RESERVE", "auto_fibre_mass", "STEP_BUDGET", "EXPLICIT_STEP",
           "BACKWARD_STEP", "STACKED_CONTACTS",
           "AUTO_SAFETY", "GAP_EXPECTED_PRESSURE", "STIFFEN_PENETRATION", "CONTACT_STIFFEN", "CONTACT_RAMP", "expected_pressure", "ContactNumerics", "contact_numerics"]
