"""Shared by the fillet scripts (tests/cli/*fillet*.sh): the analytic Hermite section of the
floor-and-wall corner (Masalha et al. 2021, Alg. 1, Eq. 1). In (X, Z) = (x - 2, z) the section is the cubic
Bezier C1, C1 + T1/3, C2 - T2/3, C2 with C1 = (d1, 0), C2 = (0, d2) and |T_i| = tau |C1 - C2|
along the faces; with the legs through the origin its area is (1/2) int (X Z' - Z X') (Green's
theorem), exact with 8 Gauss points (the integrand has degree 5)."""
import numpy as np


def hermite_section(d1, d2, tau):
    """The section at the 8 Gauss points of [0, 1]: X, Z, X', Z' and the weights (on [0, 1])."""
    w = tau * np.hypot(d1, d2)
    P = np.array([[d1, 0], [d1 - w / 3, 0], [0, d2 - w / 3], [0, d2]])
    v, wts = np.polynomial.legendre.leggauss(8)
    v = 0.5 * (v + 1)
    B = np.array([(1 - v) ** 3, 3 * v * (1 - v) ** 2, 3 * v ** 2 * (1 - v), v ** 3])
    dB = np.array([-3 * (1 - v) ** 2, 3 * (1 - v) ** 2 - 6 * v * (1 - v), 6 * v * (1 - v) - 3 * v ** 2, 3 * v ** 2])
    return B.T @ P[:, 0], B.T @ P[:, 1], dB.T @ P[:, 0], dB.T @ P[:, 1], 0.5 * wts


def hermite_area(d1, d2, tau):
    X, Z, dX, dZ, wts = hermite_section(d1, d2, tau)
    return 0.5 * np.sum(wts * (X * dZ - Z * dX))


def hermite_length(d1, d2, tau):
    """The section's arc length, by Gauss on |P'| (not exact: a square root; ample for bounds)."""
    X, Z, dX, dZ, wts = hermite_section(d1, d2, tau)
    return np.sum(wts * np.hypot(dX, dZ))


def hermite_moment(d1, d2, tau):
    """int X dA over the same region (X the distance from the Z axis): by Green's theorem
    oint X^2 / 2 dZ, where only the section contributes (degree 8: exact with 8 points). A
    quarter turn of the section about the Z axis (a bridging fillet about a vertical edge on a
    plane, Masalha et al. 2021, Sec. 6.1) has volume (pi / 2) times this (Pappus)."""
    X, Z, dX, dZ, wts = hermite_section(d1, d2, tau)
    return np.sum(wts * 0.5 * X * X * dZ)
