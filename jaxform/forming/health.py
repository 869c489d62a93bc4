"""The physical bounds of a forming run and their words: what the driver checks after every chunk
(:func:`physical_causes`), and how a run that crossed them says so (:func:`out_of_bounds_message`).

Two kinds of crossing. A numerical one (fibres stretched tenfold, nodes flung at 100 times the
punch speed, the part out of the rig, a penetration deeper than the contact was set for): the
driver tries what may keep the run stable (:meth:`jaxform.forming.driver.Standing.recover`)
and else stops, calling it an unstable or badly set-up run. A physical one: the blank's edge
drawn into the die opening (:data:`DRAWN_IN`): the flange is gone, the forming has failed as a
forming would (a ply that cannot hold its flange, such as a membrane without bending stiffness
under an open holder, or a blank too small for the stroke); nothing numerical is changed, the run
stops there and says so.
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np

from jaxform.forming.case import Case
from jaxform.forming.numerics import STIFFEN_PENETRATION


@dataclasses.dataclass(frozen=True)
class HealthBounds:
    """Bounds a physically sound forming run never crosses (derived from the case by :func:`health_bounds`).

    Attributes:
        fibre_strain: largest ``|fibre strain|`` of any element (the fibres' 3 GPa modulus keeps
            real strains below 1%); speed: largest node speed, m/s; box_lo, box_hi: (3,) corners
            of the box the part stays in, m; penetration: deepest penetration of a node into a
            tool or ply, m; stiffen_penetration: the penetration beyond which an automatic contact
            is stiffened (:data:`jaxform.forming.numerics.STIFFEN_PENETRATION`), m; edge: the
            node indices of every ply's outer edge; die_opening: m, no edge node comes closer to
            the punch axis (the blank's flange is then gone: :data:`DRAWN_IN`).
    """

    fibre_strain: float
    speed: float
    box_lo: tuple
    box_hi: tuple
    penetration: float = math.inf
    stiffen_penetration: float = math.inf
    edge: tuple = ()
    die_opening: float = 0.0


def health_bounds(case: Case, edge=()) -> HealthBounds:
    """The bounds of :class:`HealthBounds` for a case: fibre strain 10% (ten times what the fibres
    carry), node speed 100 times the punch speed (at least 10 m/s: a snap-through of the flange
    stays well below), and a box of twice the blank's half-size across, from the punch's lowest
    reach minus a blank half-size below to the holder's top plus a blank half-size above; a
    penetration of half the ply thickness (five times what the automatic contact allows at its
    expected pressure: the pressures exceed it and the contact is too soft), and beyond
    :data:`~jaxform.forming.numerics.STIFFEN_PENETRATION` of it the automatic contact stiffens;
    the blank's edge nodes ``edge`` (indices) outside the die opening's radius."""
    half = 0.5 * case.blank_size
    t = case.tools
    top = (case.holder.gap or case.stack_thickness) + t.holder_thickness + half
    bottom = -(case.process.stroke + t.die_thickness + half)
    return HealthBounds(fibre_strain=0.1, speed=max(100.0 * case.process.speed, 10.0),
                        box_lo=(-2 * half, -2 * half, bottom), box_hi=(2 * half, 2 * half, top),
                        penetration=0.5 * float(case.ply_thickness),
                        stiffen_penetration=STIFFEN_PENETRATION * float(case.ply_thickness),
                        edge=tuple(int(i) for i in edge), die_opening=float(t.die_opening_radius))


PENETRATED = "a node penetrated a tool or ply by"
"""How a cause of :func:`physical_causes` about a penetration begins (:func:`penetrated`)."""
DEEPER = "the pressures exceed those the automatic contact was chosen for"
"""How a cause about a penetration beyond ``stiffen_penetration`` (not half the ply) ends."""
FORMING_FAILED = "the forming failed"
"""How the message of a run stopped by a physical crossing begins (:func:`out_of_bounds_message`)."""
DRAWN_IN = "the blank's edge was drawn into the die opening"
"""How the cause of a run whose flange is gone begins (:func:`drawn_in`): an outcome of the case, not
of the numerics, so the driver changes nothing and stops."""


def penetrated(cause: str) -> bool:
    """Whether a failure's cause (``"; "``-joined) names a penetration (:func:`physical_causes`)."""
    return PENETRATED in cause


def drawn_in(cause: str) -> bool:
    """Whether a failure's cause (``"; "``-joined) is the blank's edge gone into the die (:data:`DRAWN_IN`)
    and nothing else: beside a numerical cause (a node flung at 100 times the punch speed may be an
    edge node) it is the numerics' failure first, and the driver's remedies are tried."""
    return bool(cause) and all(DRAWN_IN in c for c in cause.split("; "))


def physical_causes(x, fl, bounds: HealthBounds, stiffen_above: float = np.inf) -> list[str]:
    """Host: how a state (positions ``x`` (N, 3) m, its fields ``fl``) left the physical bounds of
    a run, in words; empty when it did not. A run can blow up without a NaN or an energy-balance
    jump: nodes flung away by an over-damped contact still balance their energy. A penetration
    beyond ``bounds.stiffen_penetration`` counts too where it is also deeper than ``stiffen_above``
    (m; the penetration at the chunk's start where the contact may be stiffened: a growing one,
    not one that heals; ``inf``: never)."""
    b = bounds
    x = np.asarray(x)
    strain, speed = float(fl["max_fibre_strain"]), float(fl["max_node_speed"])
    causes = []
    if not strain <= b.fibre_strain:
        causes.append(f"fibre strain {strain:.3g} beyond {b.fibre_strain:g} (the fibres carry < 0.01)")
    if not speed <= b.speed:
        causes.append(f"a node moves at {speed:.3g} m/s, beyond {b.speed:.3g} m/s (100 x the punch speed)")
    pen = float(fl.get("max_penetration", 0.0))
    if not pen <= b.penetration:
        causes.append(f"{PENETRATED} {pen * 1e3:.3g} mm, beyond {b.penetration * 1e3:.3g} mm "
                      "(half the ply): the contact is too soft for this case's pressures (raise "
                      "contact.expected_pressure_Pa)")
    elif not pen <= max(b.stiffen_penetration, stiffen_above):
        causes.append(f"{PENETRATED} {pen * 1e3:.3g} mm, beyond {b.stiffen_penetration * 1e3:.3g} mm and growing: {DEEPER}")
    lo, hi = x.min(axis=0), x.max(axis=0)
    if not (np.all(lo >= np.asarray(b.box_lo)) and np.all(hi <= np.asarray(b.box_hi))):
        far = max(float(np.max(np.asarray(b.box_lo) - lo)), float(np.max(hi - np.asarray(b.box_hi))))
        causes.append(f"the part left the rig (nodes {far * 1e3:.3g} mm outside the box of twice the blank)")
    if b.edge:
        r = float(np.min(np.hypot(*x[np.asarray(b.edge), :2].T)))
        if r < b.die_opening:  # a non-finite position is the numerics' (the checks above), not a drawn-in blank
            causes.append(f"{DRAWN_IN} (an edge node {r * 1e3:.3g} mm from the punch axis, inside the die's "
                          f"{b.die_opening * 1e3:.3g} mm opening)")
    return causes


def out_of_bounds_message(step: int, t: float, punch_m: float, causes) -> str:
    """The words of a run that left its physical bounds (:func:`physical_causes`)."""
    where = f"near step {step} (t = {t:.6e} s, punch {punch_m * 1e3:.2f} mm)"
    if drawn_in("; ".join(causes)):
        return (f"{FORMING_FAILED} {where}: {'; '.join(causes)}. Nothing held the flange: a ply without the bending "
                "stiffness to carry the flange's compression (membrane only) under an open holder, or a blank too small "
                "for the stroke. An outcome of the case, not a numerical failure; the run stops here, the frames up to "
                "the last good one are kept.")
    return (f"the run left its physical bounds {where}: {'; '.join(causes)}. Likely cause: an unstable or badly "
            "set-up run (time step, contact stiffness or damping, mass scaling); the frames up to the last good one are kept.")


def failure_reason(message: str) -> str:
    """A summary's ``reason`` for a run stopped with ``message``: a failed forming is not a failed simulation."""
    return message if message.startswith(FORMING_FAILED) else f"simulation failed: {message}"


__all__ = ["HealthBounds", "health_bounds", "PENETRATED", "DEEPER", "FORMING_FAILED", "DRAWN_IN", "penetrated", "drawn_in",
           "physical_causes", "out_of_bounds_message", "failure_reason"]
