"""Bezier polynomials of degree 6 in s = t/T (paper eq. 15, with binomial coefficients).

P(t) = Σ_k α_k C(M, k) s^k (1 − s)^(M−k), s = t/T. Eq. (15) as printed omits the binomial
coefficients C(M, k) (docs/conventions.md); with them, P(0) = α_0, P(T) = α_M and the curve
lies in the convex hull of the coefficients.
"""

from __future__ import annotations

from math import comb

import numpy as np

from flipkit.errors import ConfigError

DEGREE = 6


class Bezier:
    """Bezier basis of degree ``degree`` on [0, T].

    Args:
        degree: Polynomial degree M (paper: 6).
    """

    def __init__(self, degree: int = DEGREE):
        if int(degree) != degree or degree < 1:
            raise ConfigError(f"Bezier degree must be a positive integer, got {degree!r}")
        self.degree = int(degree)
        self.n_coeffs = self.degree + 1

    def basis(self, s, deriv: int = 0) -> np.ndarray:
        """B_k^(deriv)(s) for k = 0..M, d/ds taken ``deriv`` times (0 ≤ deriv ≤ M); shape (len(s), M+1)."""
        s = np.atleast_1d(np.asarray(s, dtype=float))
        M = self.degree
        if deriv == 0:
            return np.stack([comb(M, k) * s**k * (1 - s) ** (M - k) for k in range(M + 1)], axis=1)
        if int(deriv) != deriv or not 0 < deriv <= M:
            raise ConfigError(f"Bezier derivative order must be in 0..{M}, got {deriv!r}")
        lower = Bezier(M - 1).basis(s, deriv - 1)  # B'_k = M (B_{k-1}^{M-1} − B_k^{M-1})
        out = np.zeros((len(s), M + 1))
        out[:, 1:] += M * lower
        out[:, :-1] -= M * lower
        return out

    def evaluate(self, alpha, t, T: float, deriv: int = 0) -> np.ndarray:
        """d^deriv P / dt^deriv at times t (s); alpha has shape (n_joints, M+1); out (len(t), n_joints)."""
        alpha = np.asarray(alpha, dtype=float)
        s = np.asarray(t, dtype=float) / T
        return self.basis(s, deriv) @ alpha.T / T**deriv

    def d_dT(self, alpha, t, T: float, deriv: int = 0) -> np.ndarray:
        """∂/∂T of :meth:`evaluate` at fixed t (shape (len(t), n_joints))."""
        alpha = np.asarray(alpha, dtype=float)
        t = np.atleast_1d(np.asarray(t, dtype=float))
        s = t / T
        # d/dT [B^(r)(t/T) α / T^r] = −(t/T²) B^(r+1) α / T^r − r B^(r) α / T^(r+1)
        out = -(t / T**2)[:, None] * (self.basis(s, deriv + 1) @ alpha.T) / T**deriv
        if deriv:
            out -= deriv * (self.basis(s, deriv) @ alpha.T) / T ** (deriv + 1)
        return out
