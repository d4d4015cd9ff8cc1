"""A tangent-dynamics probe's findings (a nonlinear-dynamics user's trial): a
Neimark-Sacker crossing of an orbit with a second complex pair inside the unit circle
is located (it was flagged "not located": the test function took the smallest pair's
modulus), and a tangent map's run is bounded as an analysis's periods are. Independent
value: the moduli of the multipliers of orbits shot on either side of the located
frequency with central differences (no tangent flow)."""

from __future__ import annotations

import numpy as np
import pytest

import vibroimpact as vi
from vibroimpact import analysis as an

SYSTEM = vi.System(
    structure=vi.Oscillator(mass=1.0, stiffness=3947.8, damping=0.3),
    dampers=[vi.Damper(mass=0.05, at=0, clearance=0.005, law="rigid", restitution=0.9)],
    excitations=[vi.Force(at=0, signal=vi.Harmonic(amplitude=5.0, frequency=11.5))],
    initial=vi.Initial(
        structure_displacement=[-0.0026049180857950394],
        damper_displacement=[-0.007308121091932428],
        structure_velocity=[0.0247977300100351],
        damper_velocity=[-0.3487195867093229],
    ),
    solver=vi.Solver(method="exact", t_end=1.0),
)


def _at(frequency: float) -> vi.System:
    return SYSTEM.replace(
        excitations=[vi.Force(at=0, signal=vi.Harmonic(amplitude=5.0, frequency=frequency))]
    )


@pytest.mark.timeout(120)
def test_a_neimark_sacker_beside_a_second_complex_pair_is_located() -> None:
    branch = vi.continue_orbit(SYSTEM, "excitation.0.frequency", stop=15.0)
    (found,) = [b for b in branch.bifurcations if b.kind == "neimark-sacker"]
    moduli = np.sort(np.abs(found.floquet_multipliers))
    # Two complex pairs: one on the unit circle, one well inside it.
    assert abs(moduli[-1] - 1.0) < 1e-7 and moduli[0] < 0.9
    # Shot apart from the branch, by differences, 2e-5 Hz either side: the crossing pair
    # inside the circle below, outside above.
    nearest = []
    for frequency in (found.value - 2e-5, found.value + 2e-5):
        orbit = vi.orbit(_at(frequency), found.state, jacobian="differences")
        assert orbit.converged
        m = np.abs(orbit.floquet_multipliers)
        nearest.append(m[np.argmin(np.abs(m - 1.0))])
    assert nearest[0] < 1.0 < nearest[1], nearest


@pytest.mark.timeout(60)
def test_a_tangent_maps_run_is_bounded_as_an_analysiss_periods_are() -> None:
    # 1e9 s of a bouncing ball ran for hours; 1e12 s stopped as a chattering it has not.
    run = an.runner(vi.load("examples/bouncing_ball_table.toml"))
    state = run.initial_state()
    with pytest.raises(ValueError, match=r"t_end: 1e\+09 s is .* forcing periods, more than"):
        run.tangent(state, 1e9)
    for bad in (0.0, float("nan"), -1.0):
        with pytest.raises(ValueError, match="t_end"):
            run.tangent(state, bad)
    assert run.tangent(state, 10 * run.period)["matrix"].shape == (2, 2)
