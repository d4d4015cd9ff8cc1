"""The paper's structural and contact formulas against their closed forms: the
cantilever's modes (the frequency equation's roots, the mode shapes as the reference
page writes them, their orthogonality by Gauss-Legendre quadrature), the Hertz
stiffness of spheres, and the adequacy table (the paper's Table 3), as
/work/shared/reference/paper-model.md gives them.
"""

from __future__ import annotations

import math
from functools import cache

import numpy as np
import pytest
from scipy.optimize import brentq

import vibroimpact as vi


def cantilever_equation(x: float) -> float:
    return math.cos(x) * math.cosh(x) + 1.0


@pytest.mark.parametrize(("mode", "tabulated"), [(1, 1.875104), (2, 4.694091), (3, 7.854757)])
def test_cantilever_roots(mode: int, tabulated: float) -> None:
    root = vi.cantilever_root(mode)
    assert root == pytest.approx(tabulated, abs=1e-6)
    independent = brentq(
        cantilever_equation, (mode - 1) * math.pi + 0.1, mode * math.pi, xtol=1e-14
    )
    assert root == pytest.approx(independent, rel=1e-12)


def test_higher_cantilever_roots_tend_to_the_asymptote() -> None:
    for mode in (4, 6, 10):
        independent = brentq(
            lambda x: math.cos(x) + 1.0 / math.cosh(x), (mode - 1) * math.pi, mode * math.pi
        )
        assert vi.cantilever_root(mode) == pytest.approx(independent, rel=1e-12)
        assert vi.cantilever_root(mode) == pytest.approx((mode - 0.5) * math.pi, rel=1e-3)


def page_mode_shape(beta_l: float, xi: np.ndarray) -> np.ndarray:
    """The reference page's (unnormalised) mode shape at x / L = xi."""
    z = beta_l * xi
    sigma = (math.sin(beta_l) + math.sinh(beta_l)) / (math.cos(beta_l) + math.cosh(beta_l))
    return np.sin(z) - np.sinh(z) - sigma * (np.cos(z) - np.cosh(z))


BEAM_LENGTH = 1.5
BEAM_X = np.linspace(0.0, BEAM_LENGTH, 1001)


@cache
def shape_samples(mode: int) -> np.ndarray:
    """cantilever_mode_shape of a 1.5 m cantilever at BEAM_X."""
    return np.array([vi.cantilever_mode_shape(BEAM_LENGTH, mode, float(x)) for x in BEAM_X])


def test_cantilever_mode_constants() -> None:
    length, e, i, rho, area = 0.7, 2.1e11, 3.0e-10, 7800.0, 1.2e-4
    beam = vi.cantilever_mode(length, e, i, rho, area)
    k = 12.362361 * e * i / length**3
    big_m = rho * area * length
    assert beam.modal_stiffness == pytest.approx(k, rel=1e-6)
    root = brentq(cantilever_equation, 1.0, 3.0, xtol=1e-14)
    assert beam.modal_stiffness == pytest.approx(root**4 * e * i / length**3, rel=1e-12)
    assert beam.modal_mass == pytest.approx(big_m, rel=1e-12)
    # The classical first natural frequency (b1 L)^2 sqrt(E I / (rho A L^4)).
    assert beam.angular_frequency == pytest.approx(
        root**2 * math.sqrt(e * i / (rho * area * length**4)), rel=1e-12
    )
    assert beam.position == length
    # Normalised to int phi^2 dx = L, the tip value is exactly 2 (reference page), so
    # the values at the tip are a quarter of the modal ones, to round-off.
    assert abs(beam.shape_at_position) == pytest.approx(2.0, rel=1e-13)
    assert abs(vi.cantilever_mode_shape(length, 1, length)) == pytest.approx(2.0, rel=1e-13)
    assert beam.stiffness_at_position == pytest.approx(root**4 * e * i / length**3 / 4, rel=1e-12)
    assert beam.mass_at_position == pytest.approx(big_m / 4, rel=1e-13)
    # The page: K_tip = 3.0906 EI/L^3, close to the static tip stiffness 3 EI/L^3.
    assert beam.stiffness_at_position == pytest.approx(3.0906 * e * i / length**3, rel=2e-5)


def test_cantilever_mode_at_an_inner_position() -> None:
    length = 2.0
    beam = vi.cantilever_mode(length, 1.0, 1.0, 1.0, 1.0, position=0.5)
    phi = vi.cantilever_mode_shape(length, 1, 0.5)
    assert beam.shape_at_position == pytest.approx(phi, rel=1e-12)
    assert beam.stiffness_at_position == pytest.approx(beam.modal_stiffness / phi**2, rel=1e-12)
    assert beam.mass_at_position == pytest.approx(beam.modal_mass / phi**2, rel=1e-12)


@pytest.mark.parametrize("mode", [1, 2, 3])
def test_mode_shape_is_the_page_formula_normalised(mode: int) -> None:
    length, x = BEAM_LENGTH, BEAM_X
    ours = shape_samples(mode)
    root = vi.cantilever_root(mode)
    page = page_mode_shape(root, x / length)
    # Normalised by 64-point Gauss-Legendre quadrature, exact to round-off for these
    # entire functions (not the samples' trapezoid rule).
    nodes, weights = gauss_legendre(length)
    page *= math.sqrt(length / np.sum(weights * page_mode_shape(root, nodes / length) ** 2))
    sign = np.sign(ours[-1]) * np.sign(page[-1])
    # The page's form subtracts hyperbolic terms of size ~exp(b L): about 4e-13 lost
    # for mode 3.
    np.testing.assert_allclose(ours, sign * page, rtol=0, atol=1e-11)
    assert ours[0] == pytest.approx(0.0, abs=1e-12)  # clamped end


def gauss_legendre(length: float, points: int = 64) -> tuple[np.ndarray, np.ndarray]:
    """Nodes and weights of Gauss-Legendre quadrature on [0, length]."""
    nodes, weights = np.polynomial.legendre.leggauss(points)
    return 0.5 * length * (nodes + 1.0), 0.5 * length * weights


def test_mode_shapes_are_orthogonal() -> None:
    length = BEAM_LENGTH
    nodes, weights = gauss_legendre(length)
    shapes = [
        np.array([vi.cantilever_mode_shape(length, mode, float(x)) for x in nodes])
        for mode in (1, 2, 3)
    ]
    for i, a in enumerate(shapes):
        for j, b in enumerate(shapes):
            integral = float(np.sum(weights * a * b))
            if i == j:
                assert integral == pytest.approx(length, rel=1e-12)
            else:
                assert abs(integral) < 1e-12 * length


@pytest.mark.parametrize(
    ("r", "e1", "nu1", "e2", "nu2"),
    [(0.01, 210e9, 0.3, 70e9, 0.33), (0.002, 3e9, 0.4, 200e9, 0.29), (0.05, 1e7, 0.49, 1e7, 0.0)],
)
def test_hertz_stiffness_matches_the_papers_form(
    r: float, e1: float, nu1: float, e2: float, nu2: float
) -> None:
    paper = (
        4
        / (3 * math.pi)
        * math.sqrt(r)
        / ((1 - nu1**2) / (math.pi * e1) + (1 - nu2**2) / (math.pi * e2))
    )
    assert vi.hertz_stiffness(r, e1, nu1, e2, nu2) == pytest.approx(paper, rel=1e-13)
    # Swapping the bodies changes nothing.
    assert vi.hertz_stiffness(r, e2, nu2, e1, nu1) == pytest.approx(paper, rel=1e-13)


def test_sphere_on_sphere_is_sphere_on_flat_with_effective_radius() -> None:
    r1, r2 = 0.01, 0.03
    effective = r1 * r2 / (r1 + r2)
    two = vi.hertz_stiffness(r1, 210e9, 0.3, 70e9, 0.33, other_radius=r2)
    flat = vi.hertz_stiffness(effective, 210e9, 0.3, 70e9, 0.33)
    assert two == pytest.approx(flat, rel=1e-13)
    swapped = vi.hertz_stiffness(r2, 70e9, 0.33, 210e9, 0.3, other_radius=r1)
    assert swapped == pytest.approx(two, rel=1e-13)
    # A very large second sphere tends to the flat.
    big = vi.hertz_stiffness(r1, 210e9, 0.3, 70e9, 0.33, other_radius=1e9)
    assert big == pytest.approx(vi.hertz_stiffness(r1, 210e9, 0.3, 70e9, 0.33), rel=1e-9)


PAPER_TABLE2 = [  # (method, dt, Tc, Tcpu, error %)
    ("newmark", 1e-3, 0.1100, 0.0624, 1.01),
    ("newmark", 1e-4, 0.1090, 0.2028, 0.09),
    ("newmark", 2e-5, 0.1089, 2.5584, 0.00),
    ("rk4", 1e-3, 0.1110, 0.0936, 1.93),
    ("rk4", 1e-4, 0.1092, 0.1404, 0.27),
    ("rk4", 2e-5, 0.1091, 0.3900, 0.18),
]


PAPER_TABLE3 = [
    [97.56, 87.58, 77.60, 67.63, 57.65, 47.67],
    [92.07, 92.73, 93.38, 94.03, 94.68, 95.34],
    [0.00, 20.00, 40.00, 60.00, 80.00, 100.00],
    [96.34, 77.07, 57.80, 38.54, 19.27, 0.00],
    [94.51, 92.81, 91.11, 89.41, 87.71, 86.01],
    [84.76, 85.94, 87.12, 88.31, 89.49, 90.67],
]


WEIGHTS = (0.0, 0.2, 0.4, 0.6, 0.8, 1.0)


def test_adequacy_reproduces_the_papers_table3() -> None:
    max_err = max(row[4] for row in PAPER_TABLE2)
    max_cpu = max(row[3] for row in PAPER_TABLE2)
    for row, printed in zip(PAPER_TABLE2, PAPER_TABLE3, strict=True):
        for wf1, value in zip(WEIGHTS, printed, strict=True):
            got = vi.adequacy(row[4], max_err, row[3], max_cpu, wf1)
            by_hand = ((1 - row[4] / max_err) * wf1 + (1 - row[3] / max_cpu) * (1 - wf1)) * 100
            assert got == pytest.approx(by_hand, abs=1e-10)
            assert got == pytest.approx(value, abs=0.01), (row, wf1)
