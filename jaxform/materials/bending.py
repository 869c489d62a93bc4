"""Fibre bending laws: moment per unit width as a function of fibre curvature.

Sign convention (SPEC section 2): curvature is positive when the fibre bends away from the ply
normal ``n``. All laws are odd in ``kappa`` — a symmetric law gives ``M(-k) = -M(k)`` — and
:class:`AsymmetricBending` uses a separate law for each sign (the NCF's face-up / face-down
behaviour).

Every law is a pytree of arrays (its parameters are leaves), so it can be jitted, vmapped over
parameter sets (leaves with a leading batch axis) and differentiated with respect to every
parameter. The functions are written so that derivatives are exact and finite at ``kappa = 0``
(no ``abs`` or ``sign`` whose derivative vanishes there).

Units: ``kappa`` 1/m, ``M`` N (N·m per m width), ``B`` N·m, energy J/m² (per unit area of fabric
per unit length of fibre, i.e. ``∫ M dkappa``).
"""
from __future__ import annotations

import dataclasses
from typing import Any

import jax.numpy as jnp
import numpy as np

from jaxform import validate
from jaxform._pytree import as_leaf, is_concrete, pytree_dataclass, static_field


def _split_sign(kappa):
    """Return ``(a, s)`` with ``a = |kappa|`` and ``s = ±1`` such that d a / d kappa = s, also at 0.

    Using ``jnp.where`` instead of ``abs``/``sign`` keeps the derivative of ``s * f(a)`` equal to
    ``f'(a)`` on both sides of zero (``jnp.sign`` has derivative 0 and would lose ``m0/kappa0``).
    """
    kappa = jnp.asarray(kappa)
    pos = kappa >= 0
    return jnp.where(pos, kappa, -kappa), jnp.where(pos, 1.0, -1.0).astype(kappa.dtype if jnp.issubdtype(kappa.dtype, jnp.floating) else jnp.float32)


@pytree_dataclass
class LinearBending:
    """Linear bending model (LBM): ``M = b * kappa``.

    Attributes:
        b: bending stiffness per unit width, N·m (scalar or batch array).
    """

    b: Any

    def __post_init__(self):
        if is_concrete(self.b):
            validate.positive("LinearBending", "b", self.b, "N·m")
            object.__setattr__(self, "b", as_leaf(self.b))

    def moment(self, kappa):
        """Bending moment per unit width, N, for curvature ``kappa`` (1/m); any shape."""
        return self.b * kappa

    def stiffness(self, kappa):
        """Tangent bending stiffness ``dM/dkappa``, N·m, same shape as ``kappa``."""
        return self.b * jnp.ones_like(jnp.asarray(kappa))

    def energy(self, kappa):
        """Stored energy ``∫_0^kappa M dk``, J/m², same shape as ``kappa``."""
        return 0.5 * self.b * kappa**2

    @property
    def b_init(self):
        """Stiffness at zero curvature, N·m."""
        return self.b

    @property
    def b_inf(self):
        """Stiffness at large curvature, N·m."""
        return self.b

    def as_voce(self) -> "VoceBending":
        """The same law as a :class:`VoceBending` (``b_inf = b``, ``m0 = 0``): the same moment,
        stiffness and energy; ``m0`` and ``kappa0`` of ``b``'s type (float or array)."""
        return VoceBending(b_inf=self.b, m0=self.b * 0.0, kappa0=self.b * 0.0 + 1.0)


@pytree_dataclass
class VoceBending:
    """Non-linear bending model (NLBM), Voce form, odd in ``kappa``:

    ``M(kappa) = b_inf*kappa + sign(kappa) * m0 * (1 - exp(-|kappa|/kappa0))``

    so ``B_init = b_inf + m0/kappa0`` and ``B_inf = b_inf`` (SPEC section 3).

    Attributes:
        b_inf: asymptotic stiffness at large curvature, N·m (>= 0).
        m0: moment amplitude of the saturating term, N (>= 0).
        kappa0: curvature scale of the saturating term, 1/m (> 0).
    """

    b_inf: Any
    m0: Any
    kappa0: Any

    def __post_init__(self):
        if is_concrete(self.b_inf, self.m0, self.kappa0):
            validate.nonnegative("VoceBending", "b_inf", self.b_inf, "N·m")
            validate.nonnegative("VoceBending", "m0", self.m0, "N")
            validate.positive("VoceBending", "kappa0", self.kappa0, "1/m")
            b_init = self.b_inf + self.m0 / self.kappa0
            if np.any(np.asarray(b_init) <= 0):  # numpy: concrete values, and no JAX backend started on import
                raise ValueError(
                    f"VoceBending: b_inf + m0/kappa0 = {b_init!r} N·m: the law has no stiffness; "
                    "at least one of b_inf, m0 must be > 0"
                )
            for name in ("b_inf", "m0", "kappa0"):
                object.__setattr__(self, name, as_leaf(getattr(self, name)))

    def moment(self, kappa):
        """Bending moment per unit width, N, for curvature ``kappa`` (1/m); any shape."""
        a, s = _split_sign(kappa)
        return self.b_inf * kappa + s * self.m0 * -jnp.expm1(-a / self.kappa0)

    def stiffness(self, kappa):
        """Tangent bending stiffness ``dM/dkappa``, N·m."""
        a, _ = _split_sign(kappa)
        return self.b_inf + self.m0 / self.kappa0 * jnp.exp(-a / self.kappa0)

    def energy(self, kappa):
        """Stored energy ``∫_0^kappa M dk``, J/m²."""
        a, _ = _split_sign(kappa)
        return 0.5 * self.b_inf * kappa**2 + self.m0 * (a + self.kappa0 * jnp.expm1(-a / self.kappa0))

    @property
    def b_init(self):
        """Stiffness at zero curvature ``b_inf + m0/kappa0``, N·m."""
        return self.b_inf + self.m0 / self.kappa0

    @classmethod
    def from_stiffnesses(cls, b_init, b_inf, kappa0) -> "VoceBending":
        """Build from ``B_init``, ``B_inf`` (N·m) and ``kappa0`` (1/m): ``m0 = (B_init - B_inf) kappa0``."""
        if is_concrete(b_init, b_inf) and jnp.any(jnp.asarray(b_init) < jnp.asarray(b_inf)):
            raise ValueError(
                f"VoceBending.from_stiffnesses: b_init = {b_init!r} < b_inf = {b_inf!r}: "
                "the Voce law softens, b_init must be >= b_inf"
            )
        return cls(b_inf=b_inf, m0=(b_init - b_inf) * kappa0, kappa0=kappa0)


@pytree_dataclass
class AsymmetricBending:
    """Different laws for positive and negative bending (SPEC section 2).

    ``pos`` applies where ``kappa >= 0`` (fibre bends away from the ply normal), ``neg`` where
    ``kappa < 0``. Each side is a symmetric (odd) law evaluated on its own sign, so the moment is
    continuous at zero; the tangent stiffness may jump there (``pos.b_init != neg.b_init``).

    ``b_init`` and ``b_inf`` return ``(pos, neg)`` pairs.
    """

    pos: Any
    neg: Any

    def __post_init__(self):
        for name in ("pos", "neg"):
            law = getattr(self, name)
            if not all(hasattr(law, m) for m in ("moment", "stiffness", "energy")):
                raise ValueError(
                    f"AsymmetricBending.{name} = {law!r}: must be a bending law "
                    "(LinearBending or VoceBending)"
                )

    def moment(self, kappa):
        kappa = jnp.asarray(kappa)
        return jnp.where(kappa >= 0, self.pos.moment(kappa), self.neg.moment(kappa))

    def stiffness(self, kappa):
        kappa = jnp.asarray(kappa)
        return jnp.where(kappa >= 0, self.pos.stiffness(kappa), self.neg.stiffness(kappa))

    def energy(self, kappa):
        kappa = jnp.asarray(kappa)
        return jnp.where(kappa >= 0, self.pos.energy(kappa), self.neg.energy(kappa))

    @property
    def b_init(self):
        return (self.pos.b_init, self.neg.b_init)

    @property
    def b_inf(self):
        return (self.pos.b_inf, self.neg.b_inf)


BendingLaw = LinearBending | VoceBending | AsymmetricBending


def max_stiffness(law) -> Any:
    """The largest tangent stiffness the law can have, N·m (for stable time steps).

    Monotone-softening laws (linear, Voce) are stiffest at zero curvature.
    """
    if isinstance(law, AsymmetricBending):
        return jnp.maximum(jnp.asarray(max_stiffness(law.pos)), jnp.asarray(max_stiffness(law.neg)))
    return law.b_init


__all__ = ["LinearBending", "VoceBending", "AsymmetricBending", "BendingLaw", "max_stiffness"]
_ = dataclasses  # dataclasses.replace works on every law (frozen dataclasses)
_ = static_field
