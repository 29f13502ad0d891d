"""Exact solutions of the verification problems (numpy only).

Cantilever (Timoshenko & Goodier, Theory of Elasticity, 3rd ed., section 21; the form used by
Belytschko, Lu & Gu 1994): plane stress, beam of length L and depth D along x, origin at the
centre of the **supported** end (x = 0), free end x = L loaded by the parabolic shear traction

    t_y(y) = tau_xy(L, y) = P / (2 I) (D^2/4 - y^2),      I = b D^3 / 12,

whose resultant is P along +y. Stresses: sigma_xx = -P (L - x) y / I, sigma_yy = 0,
tau_xy = P / (2 I) (D^2/4 - y^2). Displacements:

    u_x = -P y / (6 E I) [ (6 L - 3 x) x + (2 + nu) (y^2 - D^2/4) ]
    u_y =  P / (6 E I) [ 3 nu y^2 (L - x) + (4 + 5 nu) D^2 x / 4 + (3 L - x) x^2 ]
    u_z =  nu P (L - x) y z / (E I)        (the plane-stress thickness strain, z from mid-plane)

Tip deflection v(L, 0) = P L^3 / (3 E I) + (4 + 5 nu) P D^2 L / (24 E I).

The fields satisfy equilibrium, plane-stress Hooke's law and the traction-free edges y = +-D/2
exactly (:func:`check_timoshenko_goodier` verifies it numerically).
"""
from __future__ import annotations

import numpy as np


def second_moment(depth: float, width: float) -> float:
    """I = b D^3 / 12 of the rectangular section (bending about z)."""
    return width * depth ** 3 / 12.0


def tip_deflection(load, length, depth, width, young, poisson):
    """v(L, 0) = P L^3 / (3 E I) + (4 + 5 nu) P D^2 L / (24 E I) (formulation section 7)."""
    inertia = second_moment(depth, width)
    return (load * length ** 3 / (3.0 * young * inertia)
            + (4.0 + 5.0 * poisson) * load * depth ** 2 * length / (24.0 * young * inertia))


def shear_traction(y, load, depth, width):
    """tau_xy(y) = P / (2 I) (D^2/4 - y^2) at the loaded end, y from the neutral axis."""
    inertia = second_moment(depth, width)
    return load / (2.0 * inertia) * (depth ** 2 / 4.0 - np.asarray(y, dtype=float) ** 2)


def timoshenko_goodier(points, load, length, depth, width, young, poisson):
    """Displacements (n, 3) of the plane-stress solution at points (n, 3): x from the supported
    end, y from the neutral axis, z from the mid-plane (see the module docstring)."""
    points = np.asarray(points, dtype=float)
    x, y, z = points[:, 0], points[:, 1], points[:, 2]
    inertia = second_moment(depth, width)
    factor = load / (6.0 * young * inertia)
    ux = -factor * y * ((6.0 * length - 3.0 * x) * x + (2.0 + poisson) * (y ** 2 - depth ** 2 / 4.0))
    uy = factor * (3.0 * poisson * y ** 2 * (length - x) + (4.0 + 5.0 * poisson) * depth ** 2 * x / 4.0
                   + (3.0 * length - x) * x ** 2)
    uz = poisson * load * (length - x) * y * z / (young * inertia)
    return np.column_stack([ux, uy, uz])


def timoshenko_goodier_stress(points, load, length, depth, width):
    """(sigma_xx, sigma_yy, tau_xy) of the solution at points (n, 3)."""
    points = np.asarray(points, dtype=float)
    x, y = points[:, 0], points[:, 1]
    inertia = second_moment(depth, width)
    return (-load * (length - x) * y / inertia, np.zeros_like(x),
            load / (2.0 * inertia) * (depth ** 2 / 4.0 - y ** 2))


def check_timoshenko_goodier(load=1e-3, length=50.0, depth=10.0, width=1.0, young=1.0,
                             poisson=0.3, step=1e-4):
    """Largest mismatch, relative to the largest stress, between the plane-stress stresses and
    Hooke's law applied to central differences of the displacements, at random points; and the
    equilibrium residual. Both are round-off / truncation sized (about 1e-7) when the formulas
    are right."""
    rng = np.random.default_rng(0)
    points = np.column_stack([rng.uniform(0, length, 50), rng.uniform(-depth / 2, depth / 2, 50),
                              np.zeros(50)])

    def gradient(p):
        """In-plane displacement gradients (n, 2, 2) by central differences."""
        grads = np.empty((len(p), 2, 2))
        for d in range(2):
            offset = np.zeros(3)
            offset[d] = step
            plus = timoshenko_goodier(p + offset, load, length, depth, width, young, poisson)
            minus = timoshenko_goodier(p - offset, load, length, depth, width, young, poisson)
            grads[:, :, d] = (plus[:, :2] - minus[:, :2]) / (2 * step)
        return grads

    g = gradient(points)
    exx, eyy, gxy = g[:, 0, 0], g[:, 1, 1], g[:, 0, 1] + g[:, 1, 0]
    c = young / (1.0 - poisson ** 2)
    sxx, syy, txy = c * (exx + poisson * eyy), c * (eyy + poisson * exx), young / (2 * (1 + poisson)) * gxy
    exact = timoshenko_goodier_stress(points, load, length, depth, width)
    scale = np.abs(exact[0]).max()
    hooke = max(np.abs(sxx - exact[0]).max(), np.abs(syy - exact[1]).max(),
                np.abs(txy - exact[2]).max()) / scale
    # equilibrium of the exact stresses: d sxx/dx + d txy/dy = P y / I - P y / I
    inertia = second_moment(depth, width)
    residual = np.abs(load * points[:, 1] / inertia + load / (2 * inertia) * (-2 * points[:, 1])).max()
    return hooke, residual / scale


def projected_corner_values(y_low, y_high, load, depth, width):
    """Linear traction (values at y_low, y_high) on one segment that is the L2 projection of the
    parabola: its consistent nodal forces, int N_a t dy, equal those of the exact traction, so the
    loaded nodes get the exact consistent forces and the resultant is exactly P."""
    gauss = np.array([-np.sqrt(0.6), 0.0, np.sqrt(0.6)])
    weights = np.array([5.0, 8.0, 5.0]) / 9.0
    span = y_high - y_low
    y = 0.5 * (y_low + y_high) + 0.5 * span * gauss
    t = shear_traction(y, load, depth, width)
    n_low, n_high = (y_high - y) / span, (y - y_low) / span
    forces = 0.5 * span * np.array([np.sum(weights * n_low * t), np.sum(weights * n_high * t)])
    mass = span / 6.0 * np.array([[2.0, 1.0], [1.0, 2.0]])
    return np.linalg.solve(mass, forces)


def affine_field(points, gradient, offset):
    """u = A X + c at points (n, 3)."""
    return np.asarray(points, dtype=float) @ np.asarray(gradient, dtype=float).T + np.asarray(offset, dtype=float)
