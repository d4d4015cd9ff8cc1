"""Cantilever modes against independent values, for any mode.

The references: published roots b_i L, the characteristic equation solved here by
scipy's brentq, the textbook shape formula where it is still accurate (low modes),
orthonormality by a Gauss-Legendre quadrature assembled here, the boundary
conditions, and the Euler-Bernoulli equation phi'''' = b^4 phi.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from functools import cache

import numpy as np
import pytest
from scipy.optimize import brentq

import vibroimpact as vi

EPS = float(np.finfo(float).eps)


def characteristic(x: float) -> float:
    """cos x cosh x + 1 divided by cosh x, from e^-x so that it never overflows."""
    e = math.exp(-x)
    return math.cos(x) + 2.0 * e / (1.0 + e * e)


def textbook_shape(beta_l: float, xi: np.ndarray) -> np.ndarray:
    """cosh z - cos z - sigma (sinh z - sin z): exact, but its terms grow as e^(b L) / 2."""
    z = beta_l * xi
    sigma = (math.sinh(beta_l) - math.sin(beta_l)) / (math.cosh(beta_l) + math.cos(beta_l))
    return np.cosh(z) - np.cos(z) - sigma * (np.sinh(z) - np.sin(z))


@cache
def quadrature(panels: int) -> tuple[np.ndarray, np.ndarray]:
    """Composite 20-point Gauss-Legendre rule on [0, 1]: points and weights."""
    nodes, weights = np.polynomial.legendre.leggauss(20)
    edges = np.linspace(0.0, 1.0, panels + 1)
    half = 0.5 * np.diff(edges)
    mid = 0.5 * (edges[1:] + edges[:-1])
    points = (mid[:, None] + half[:, None] * nodes[None, :]).ravel()
    return points, (half[:, None] * weights[None, :]).ravel()


def shape_at(length: float, mode: int, xs: np.ndarray, derivative: int = 0) -> np.ndarray:
    return np.array([vi.cantilever_mode_shape(length, mode, float(x), derivative) for x in xs])


# --------------------------------------------------------------------------- roots


@pytest.mark.parametrize(
    ("mode", "published"),
    # b_i L of a clamped-free beam, 16 digits (Blevins, Formulas for Natural
    # Frequency and Mode Shape, table 8-1).
    [
        (1, 1.875104068711961),
        (2, 4.694091132974175),
        (3, 7.854757438237613),
        (4, 10.99554073487547),
        (5, 14.13716839104647),
    ],
)
def test_first_roots_match_the_published_values(mode: int, published: float) -> None:
    assert vi.cantilever_root(mode) == pytest.approx(published, rel=2e-15, abs=0)


def test_roots_are_those_of_the_characteristic_equation_for_1000_modes() -> None:
    for mode in range(1, 1001):
        root = vi.cantilever_root(mode)
        centre = (2 * mode - 1) * math.pi / 2
        # The i-th root (bracketed by its neighbours' centres), to a few ulp.
        independent = brentq(
            characteristic, centre - math.pi / 2, centre + math.pi / 2, xtol=1e-300, rtol=4 * EPS
        )
        assert abs(root - independent) <= 8 * EPS * root, mode
        assert abs(characteristic(root)) <= 4 * EPS * root, mode


def test_root_spacing_tends_to_pi() -> None:
    roots = np.array([vi.cantilever_root(mode) for mode in range(1, 301)])
    spacing = np.diff(roots)
    # b_i L = (2i - 1) pi / 2 + (-1)^(i+1) / cosh((2i - 1) pi / 2) + ...: the spacing
    # differs from pi by at most about twice the first correction, then by round-off.
    centres = (2 * np.arange(1, 300) - 1) * math.pi / 2
    bound = 5.0 * np.exp(-centres) + 8 * EPS * roots[1:]  # 2.5 / cosh without overflow
    assert np.all(np.abs(spacing - math.pi) <= bound)
    assert abs(spacing[0] - math.pi) > 0.1  # not vacuous: the first gap is 2.82
    assert np.all(np.abs(spacing[20:] - math.pi) < 1e-12)


def test_frequencies_of_the_first_30_modes_to_1e_10() -> None:
    length, e, i, rho, area = 0.45, 7.0e10, 2.0e-11, 2700.0, 6.0e-5
    for mode in range(1, 31):
        centre = (2 * mode - 1) * math.pi / 2
        root = brentq(
            characteristic, centre - math.pi / 2, centre + math.pi / 2, xtol=1e-300, rtol=4 * EPS
        )
        omega = root**2 * math.sqrt(e * i / (rho * area * length**4))
        beam = vi.cantilever_mode(length, e, i, rho, area, mode=mode)
        assert beam.angular_frequency == pytest.approx(omega, rel=1e-10)


# -------------------------------------------------------------------------- shapes


@pytest.mark.parametrize("mode", [1, 2, 3, 4, 5, 6])
def test_low_modes_agree_with_the_textbook_formula(mode: int) -> None:
    """The textbook form loses digits as e^(b L) eps: still 1e-9 at mode 6."""
    length = 1.3
    xs = np.linspace(0.0, length, 201)
    root = vi.cantilever_root(mode)
    expected = textbook_shape(root, xs / length)
    tolerance = 16 * EPS * math.exp(root)
    np.testing.assert_allclose(shape_at(length, mode, xs), expected, rtol=0, atol=tolerance)


def test_tip_value_is_two_for_modes_up_to_1000() -> None:
    """0.1 gave 1.996 at mode 12, 0 from mode 13 and NaN from mode 227."""
    for mode in range(1, 1001):
        tip = vi.cantilever_mode_shape(1.0, mode, 1.0)
        assert tip == pytest.approx(2.0 if mode % 2 else -2.0, abs=1e-14 + 16 * EPS * mode), mode


def test_modes_up_to_40_are_orthonormal() -> None:
    length = 2.5
    points, weights = quadrature(64)  # 64 panels: exact far beyond mode 40's 40 half-waves
    shapes = np.array([shape_at(length, mode, points * length) for mode in range(1, 41)])
    # int_0^L phi_i phi_j dx / L = int_0^1 phi_i phi_j d xi.
    gram = (shapes * weights) @ shapes.T
    np.testing.assert_allclose(gram, np.eye(40), rtol=0, atol=1e-13)


@pytest.mark.parametrize(("i", "j"), [(227, 227), (226, 227), (1000, 1000), (999, 1000)])
def test_modes_227_and_1000_are_finite_and_orthonormal(i: int, j: int) -> None:
    points, weights = quadrature(1024)
    a, b = shape_at(1.0, i, points), shape_at(1.0, j, points)
    assert np.all(np.isfinite(a)) and np.all(np.isfinite(b))
    assert float(np.sum(weights * a * b)) == pytest.approx(1.0 if i == j else 0.0, abs=1e-12)


@pytest.mark.parametrize("mode", [*range(1, 31), 227, 1000])
def test_boundary_conditions(mode: int) -> None:
    """phi(0) = phi'(0) = 0 (clamped), phi''(L) = phi'''(L) = 0 (free), each on the scale
    (b_i L / L)^k of its derivative; elsewhere the same derivatives are of order one."""
    length = 0.6
    b = vi.cantilever_root(mode) / length
    tolerance = 32 * EPS * mode

    def scaled(x: float, k: int) -> float:
        return vi.cantilever_mode_shape(length, mode, x, derivative=k) / b**k

    assert abs(scaled(0.0, 0)) <= tolerance
    assert abs(scaled(0.0, 1)) <= tolerance
    assert abs(scaled(length, 2)) <= tolerance
    assert abs(scaled(length, 3)) <= tolerance
    assert abs(scaled(0.0, 2)) > 1.0 and abs(scaled(length, 1)) > 1.0


def central_difference(f: Callable[[float], float], x: float, h: float) -> float:
    """Fourth-order central difference."""
    return (8 * (f(x + h) - f(x - h)) - (f(x + 2 * h) - f(x - 2 * h))) / (12 * h)


@pytest.mark.parametrize("mode", [1, 2, 7, 30])
def test_derivatives_are_the_shapes_and_solve_the_beam_equation(mode: int) -> None:
    """Each derivative against a finite difference of the one below; the fourth, from
    the third, against b^4 phi (Euler-Bernoulli)."""
    length = 1.9
    b = vi.cantilever_root(mode) / length
    h = 1e-3 / b
    for x in np.linspace(0.05, 0.95, 7) * length:
        values = [vi.cantilever_mode_shape(length, mode, float(x), derivative=k) for k in range(4)]
        for k in range(3):
            fd = central_difference(
                lambda y, k=k: vi.cantilever_mode_shape(length, mode, y, derivative=k),
                float(x),
                h,
            )
            assert fd == pytest.approx(values[k + 1], abs=1e-8 * b ** (k + 1))
        fourth = central_difference(
            lambda y: vi.cantilever_mode_shape(length, mode, y, derivative=3), float(x), h
        )
        assert fourth == pytest.approx(b**4 * values[0], abs=1e-8 * b**4)


# -------------------------------------------------------------------- reduced mode


def test_each_of_30_modes_referred_to_its_tip_is_a_quarter_of_its_modal_values() -> None:
    length, e, i, rho, area = 0.7, 2.1e11, 3.0e-10, 7800.0, 1.2e-4
    for mode in range(1, 31):
        beam = vi.cantilever_mode(length, e, i, rho, area, mode=mode)
        assert abs(beam.shape_at_position) == pytest.approx(2.0, abs=1e-13)
        assert beam.stiffness_at_position == pytest.approx(beam.modal_stiffness / 4, rel=1e-13)
        assert beam.mass_at_position == pytest.approx(rho * area * length / 4, rel=1e-13)


def test_a_high_mode_at_an_inner_point_is_not_mistaken_for_a_node() -> None:
    """0.1 called every point of mode 13 and above a node."""
    beam = vi.cantilever_mode(1.0, 1.0, 1.0, 1.0, 1.0, mode=40, position=0.3)
    phi = vi.cantilever_mode_shape(1.0, 40, 0.3)
    assert abs(phi) > 0.1
    assert beam.shape_at_position == phi
    assert beam.stiffness_at_position == pytest.approx(beam.modal_stiffness / phi**2, rel=1e-14)


def test_bad_derivative_order_is_refused() -> None:
    for bad in (-1, 4, 10**400):
        with pytest.raises(vi.InvalidInputError, match="derivative"):
            vi.cantilever_mode_shape(1.0, 1, 0.5, derivative=bad)
