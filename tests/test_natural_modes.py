"""vi.natural_modes: the undamped natural frequencies (Hz) and mode shapes of a system
between contacts, of the structure alone or with the dampers' masses attached.

Independent references: closed forms (sqrt(k/m)/(2 pi); a two-mass chain's sqrt(k/m) and
sqrt(3k/m); a clamped-free beam's roots of 1 + cos(bL) cosh(bL) = 0 and its mode
shape; a cantilever with a tip mass's frequency equation), the roots found here by
scipy's brentq."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

import vibroimpact as vi

BEAM = {
    "length": 0.4,
    "section": "rectangle",
    "width": 0.02,
    "height": 0.004,
    "material": "aluminium",
    "damping_ratio": 0.01,
}


def beam_roots(count: int, tip_mass_ratio: float = 0.0) -> list[float]:
    """The first ``count`` roots b L of a clamped-free beam's frequency equation, with a
    tip mass of ``tip_mass_ratio`` times the beam's (0: none), bracketed near
    (n - 1/2) pi."""

    def equation(c: float) -> float:
        return (
            1
            + math.cos(c) * math.cosh(c)
            + tip_mass_ratio * c * (math.cos(c) * math.sinh(c) - math.sin(c) * math.cosh(c))
        )

    roots, grid = [], np.linspace(0.1, (count + 1) * math.pi, 4000)
    values = [equation(c) for c in grid]
    for a, b, fa, fb in zip(grid[:-1], grid[1:], values[:-1], values[1:], strict=True):
        if fa * fb < 0 and len(roots) < count:
            roots.append(brentq(equation, a, b, xtol=1e-14))
    return roots


def test_an_oscillator_is_sqrt_k_over_m() -> None:
    mass, stiffness, damper = 1.3, 4000.0, 0.2
    system = vi.System(
        structure=vi.Oscillator(mass=mass, stiffness=stiffness, damping=3.0),
        dampers=[vi.Damper(mass=damper, at=0, clearance=0.01, law="rigid", restitution=0.5)],
    )
    free = vi.natural_modes(system)
    assert free.frequencies == pytest.approx([math.sqrt(stiffness / mass) / (2 * math.pi)])
    stuck = vi.natural_modes(system, attach_dampers=True)
    assert stuck.frequencies == pytest.approx(
        [math.sqrt(stiffness / (mass + damper)) / (2 * math.pi)], rel=1e-12
    )
    # Unit modal mass: phi^2 (m + m_d) = 1.
    assert stuck.shapes[0, 0] == pytest.approx(1 / math.sqrt(mass + damper), rel=1e-12)


def test_a_two_mass_chain_has_its_closed_form_modes() -> None:
    m, k = 2.0, 500.0
    system = vi.System(
        structure=vi.Matrices(mass=[[m, 0], [0, m]], stiffness=[[2 * k, -k], [-k, 2 * k]])
    )
    modes = vi.natural_modes(system)
    expected = [math.sqrt(k / m) / (2 * math.pi), math.sqrt(3 * k / m) / (2 * math.pi)]
    assert modes.frequencies == pytest.approx(expected, rel=1e-12)
    # In phase, then in opposition; unit modal mass; the sign: largest entry positive.
    in_phase, opposed = modes.shapes[:, 0], modes.shapes[:, 1]
    assert in_phase == pytest.approx([1 / math.sqrt(2 * m)] * 2, rel=1e-12)
    assert abs(opposed[0]) == pytest.approx(abs(opposed[1]), rel=1e-12)
    assert opposed[0] * opposed[1] < 0
    np.testing.assert_allclose(modes.shapes.T @ modes.mass @ modes.shapes, np.eye(2), atol=1e-12)
    assert modes.at([1]) == pytest.approx(modes.shapes[1:2, :])


def test_a_cantilever_has_the_clamped_free_roots() -> None:
    beam = vi.Cantilever(**BEAM, modes=4)
    r = beam.resolved()
    scale = math.sqrt(r["youngs_modulus"] * r["second_moment"] / r["mass_per_length"])
    roots = beam_roots(4)
    assert roots[:3] == pytest.approx([1.8751, 4.6941, 7.8548], abs=1e-4)
    expected = [c**2 / (2 * math.pi * r["length"] ** 2) * scale for c in roots]
    modes = vi.natural_modes(vi.System(structure=beam))
    assert modes.frequencies == pytest.approx(expected, rel=1e-9)
    # The first shape along the beam, against the closed form's ratio to its tip.
    c = roots[0] / r["length"]
    sigma = (math.cosh(roots[0]) + math.cos(roots[0])) / (math.sinh(roots[0]) + math.sin(roots[0]))

    def shape(x: float) -> float:
        return math.cosh(c * x) - math.cos(c * x) - sigma * (math.sinh(c * x) - math.sin(c * x))

    along = modes.at([0.1, 0.25, 0.4])[:, 0]
    assert along / along[-1] == pytest.approx([shape(x) / shape(0.4) for x in (0.1, 0.25, 0.4)])


def test_a_cantilever_with_its_damper_attached_approaches_the_tip_mass_equation() -> None:
    beam = vi.Cantilever(**BEAM, modes=12)
    r = beam.resolved()
    tip = 0.25 * r["mass_per_length"] * r["length"]
    system = vi.System(
        structure=beam,
        dampers=[vi.Damper(mass=tip, at=0.4, clearance=1e-3, law="rigid", restitution=0.5)],
    )
    scale = math.sqrt(r["youngs_modulus"] * r["second_moment"] / r["mass_per_length"])
    exact = [c**2 / (2 * math.pi * r["length"] ** 2) * scale for c in beam_roots(3, 0.25)]
    stuck = vi.natural_modes(system, attach_dampers=True).frequencies[:3]
    # Rayleigh-Ritz over 12 clamped-free modes: from above, and close.
    assert np.all(stuck >= np.array(exact) * (1 - 1e-12))
    assert stuck == pytest.approx(exact, rel=2e-3)
    # Free, the damper changes nothing.
    assert vi.natural_modes(system).frequencies == pytest.approx(
        vi.natural_modes(vi.System(structure=beam)).frequencies, rel=1e-14
    )


def test_the_notebook_summary_shows_the_first_frequencies() -> None:
    system = vi.System(
        structure=vi.Oscillator(mass=1.0, stiffness=(2 * math.pi * 10.0) ** 2),
        dampers=[vi.Damper(mass=0.21, at=0, clearance=0.01, law="rigid", restitution=0.5)],
    )
    html = system._repr_html_()
    assert "natural frequencies" in html
    assert "structure: 10 Hz" in html
    assert f"attached: {10 / math.sqrt(1.21):.4g} Hz" in html


def test_a_bad_argument_is_named() -> None:
    with pytest.raises(vi.InvalidInputError, match="system"):
        vi.natural_modes("oscillator")  # type: ignore[arg-type]
    system = vi.System(structure=vi.Oscillator(mass=1.0, stiffness=1.0))
    with pytest.raises(vi.InvalidInputError, match="attach_dampers"):
        vi.natural_modes(system, attach_dampers="yes")  # type: ignore[arg-type]
