"""In-plane shear laws: normalised shear force ``F_norm`` (N/m) against shear angle ``gamma`` (rad).

``gamma`` is the initial angle between the two fibre families minus the current one (SPEC
section 2). The laws here are generic and fittable; the paper's two fabrics are instances:

* :class:`PolynomialShear` — ``F(g) = sign(g) * sum_i c_i |g|^i`` (i = 1..n), odd in ``g``.
  The woven 38616 7th-order polynomial and the NCF yarn-rotation term are of this form.
* :class:`PiecewiseLinearShear` — linear between knots, zero outside them, applied to positive
  shear only (``positive_only=True``, the NCF stitch term) or odd-symmetrically.
* :class:`CompositeShear` — the sum of several laws (NCF = yarn rotation + stitch).

Each law offers ``force(gamma)`` (N/m), ``tangent(gamma) = dF/dgamma`` (N/m per rad),
``integral(gamma) = ∫_0^gamma F dg`` (N/m·rad = J/m²) and
``integral2(gamma) = ∫_0^|gamma| integral(g) dg`` (J/m²·rad). Both integrals are even in
``gamma`` for odd laws (and zero for ``gamma < 0`` for positive-only terms). How the shell turns
``F_norm`` into a stress is the shell's business (see ``jaxform.shell``): if ``F_norm`` is read as
the shear force conjugate to ``gamma`` the shear energy per area is ``integral``; the paper's
reading is a tangent shear modulus ``G12(gamma) = F_norm(gamma) / h`` (eq. A.14), whose shear
stress resultant is ``sign(gamma) * integral(gamma)`` and whose energy is ``integral2``.

All laws are pytrees of arrays, differentiable in every coefficient and finite at ``gamma = 0``.
"""
from __future__ import annotations

from typing import Any

import jax.numpy as jnp
import numpy as np

from jaxform import validate
from jaxform._pytree import as_leaf, is_concrete, pytree_dataclass, static_field
from jaxform.materials.bending import _split_sign


@pytree_dataclass
class PolynomialShear:
    """Odd-symmetric polynomial without constant term: ``F(g) = sign(g) * sum_{i=1}^n c_i |g|^i``.

    Attributes:
        coeffs: (n,) coefficients of ``|g|^1 .. |g|^n``, N/m (per rad^i).
    """

    coeffs: Any

    def __post_init__(self):
        object.__setattr__(self, "coeffs", as_leaf(self.coeffs))
        if is_concrete(self.coeffs):
            arr = np.asarray(self.coeffs, dtype=np.float64)
            if arr.ndim != 1 or arr.size == 0:
                raise ValueError(
                    f"PolynomialShear.coeffs has shape {arr.shape}: must be a non-empty 1-D sequence "
                    "of the coefficients of g^1, g^2, ... (N/m)"
                )
            validate.finite("PolynomialShear", "coeffs", arr, "N/m")
            object.__setattr__(self, "coeffs", arr)

    @property
    def degree(self) -> int:
        return int(np.shape(self.coeffs)[-1])

    def _series(self, a, weight, shift: int):
        """``sum_i weight(i) c_i a^(i + shift)`` for i = 1..n by Horner's rule (no pow: one multiply-add per term)."""
        n = self.degree
        acc = jnp.zeros_like(a)
        for i in range(n, 0, -1):
            acc = acc * a + weight(i) * self.coeffs[..., i - 1]
        # acc = sum_i w_i c_i a^(i-1); multiply by a^(1 + shift)
        return acc * a ** (1 + shift) if shift != -1 else acc

    def force(self, gamma):
        """Normalised shear force, N/m, for shear angle ``gamma`` (rad); any shape."""
        a, s = _split_sign(gamma)
        return s * self._series(a, lambda i: 1.0, 0)

    def tangent(self, gamma):
        """``dF/dgamma``, N/m per rad (even in ``gamma``)."""
        a, _ = _split_sign(gamma)
        return self._series(a, lambda i: float(i), -1)

    def integral(self, gamma):
        """``∫_0^gamma F dg``, J/m² (even in ``gamma``)."""
        a, _ = _split_sign(gamma)
        return self._series(a, lambda i: 1.0 / (i + 1), 1)

    def integral2(self, gamma):
        """``∫_0^|gamma| integral(g) dg``, J/m²·rad (even in ``gamma``)."""
        a, _ = _split_sign(gamma)
        return self._series(a, lambda i: 1.0 / ((i + 1) * (i + 2)), 2)


@pytree_dataclass
class PiecewiseLinearShear:
    """Piecewise-linear force between knots, zero outside ``[knots[0], knots[-1])``.

    With ``positive_only=True`` the term acts on positive shear only and is zero for
    ``gamma < 0`` (the NCF stitch, which only a shear that stretches it loads); otherwise it
    is applied odd-symmetrically, ``sign(g) * F(|g|)``.

    Attributes:
        gamma_knots: (k,) strictly increasing shear angles, rad (>= 0).
        force_knots: (k,) force at each knot, N/m.
        positive_only: static flag, see above.
    """

    gamma_knots: Any
    force_knots: Any
    positive_only: bool = static_field(default=True)

    def __post_init__(self):
        object.__setattr__(self, "gamma_knots", as_leaf(self.gamma_knots))
        object.__setattr__(self, "force_knots", as_leaf(self.force_knots))
        if is_concrete(self.gamma_knots, self.force_knots):
            g = np.asarray(self.gamma_knots, dtype=np.float64)
            f = np.asarray(self.force_knots, dtype=np.float64)
            if g.ndim != 1 or g.size < 2 or f.shape != g.shape:
                raise ValueError(
                    f"PiecewiseLinearShear: gamma_knots shape {g.shape} and force_knots shape {f.shape}: "
                    "need two 1-D sequences of the same length >= 2"
                )
            validate.nonnegative("PiecewiseLinearShear", "gamma_knots", g, "rad")
            validate.finite("PiecewiseLinearShear", "force_knots", f, "N/m")
            if np.any(np.diff(g) <= 0):
                raise ValueError(
                    f"PiecewiseLinearShear.gamma_knots = {g.tolist()}: must be strictly increasing (rad)"
                )
            object.__setattr__(self, "gamma_knots", g)
            object.__setattr__(self, "force_knots", f)

    def _segments(self, a):
        g0, g1 = self.gamma_knots[:-1], self.gamma_knots[1:]
        f0, f1 = self.force_knots[:-1], self.force_knots[1:]
        slope = (f1 - f0) / (g1 - g0)
        a = a[..., None]
        inside = (a >= g0) & (a < g1)
        return a, g0, g1, f0, slope, inside

    def _sided(self, gamma, value_of_abs, odd: bool):
        a, s = _split_sign(gamma)
        v = value_of_abs(a)
        if self.positive_only:
            return jnp.where(jnp.asarray(gamma) >= 0, v, 0.0)
        return s * v if odd else v

    def force(self, gamma):
        """Force, N/m."""

        def f(a):
            a, g0, _, f0, slope, inside = self._segments(a)
            return jnp.sum(jnp.where(inside, f0 + slope * (a - g0), 0.0), axis=-1)

        return self._sided(gamma, f, odd=True)

    def tangent(self, gamma):
        """``dF/dgamma``, N/m per rad (zero outside the knots; undefined exactly at a kink)."""

        def t(a):
            _, _, _, _, slope, inside = self._segments(a)
            return jnp.sum(jnp.where(inside, slope, 0.0), axis=-1)

        return self._sided(gamma, t, odd=False)

    def integral(self, gamma):
        """``∫_0^gamma F dg``, J/m²."""

        def e(a):
            a, g0, g1, f0, slope, _ = self._segments(a)
            x = jnp.clip(a, g0, g1) - g0  # covered part of each segment
            return jnp.sum(x * (f0 + 0.5 * slope * x), axis=-1)

        return self._sided(gamma, e, odd=False)

    def integral2(self, gamma):
        """``∫_0^|gamma| integral(g) dg``, J/m²·rad."""

        def e2(a):
            a, g0, g1, f0, slope, _ = self._segments(a)
            x = jnp.clip(a, g0, g1) - g0
            full = (g1 - g0) * (f0 + 0.5 * slope * (g1 - g0))  # whole segment's integral
            beyond = jnp.maximum(a - g1, 0.0)
            return jnp.sum(0.5 * f0 * x**2 + slope * x**3 / 6.0 + full * beyond, axis=-1)

        return self._sided(gamma, e2, odd=False)


@pytree_dataclass
class CompositeShear:
    """Sum of shear laws (e.g. NCF yarn rotation + stitch).

    Attributes:
        terms: tuple of shear laws.
    """

    terms: tuple

    def __post_init__(self):
        terms = tuple(self.terms)
        if not terms or not all(hasattr(t, "force") and hasattr(t, "integral") for t in terms):
            raise ValueError(f"CompositeShear.terms = {self.terms!r}: must be a non-empty tuple of shear laws")
        object.__setattr__(self, "terms", terms)

    def force(self, gamma):
        return sum(t.force(gamma) for t in self.terms)

    def tangent(self, gamma):
        return sum(t.tangent(gamma) for t in self.terms)

    def integral(self, gamma):
        return sum(t.integral(gamma) for t in self.terms)

    def integral2(self, gamma):
        return sum(t.integral2(gamma) for t in self.terms)


ShearLaw = PolynomialShear | PiecewiseLinearShear | CompositeShear


def ncf_shear(yarn_coeffs, stitch_gamma_knots, stitch_force_knots) -> CompositeShear:
    """The NCF form: an odd yarn-rotation polynomial plus a positive-only piecewise-linear stitch term."""
    return CompositeShear(
        (
            PolynomialShear(yarn_coeffs),
            PiecewiseLinearShear(stitch_gamma_knots, stitch_force_knots, positive_only=True),
        )
    )


__all__ = ["PolynomialShear", "PiecewiseLinearShear", "CompositeShear", "ShearLaw", "ncf_shear"]
