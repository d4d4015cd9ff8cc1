"""A numerical-methods probe's findings (an expert trying to break the methods): a
compliant contact shorter than two fixed steps stops the run, naming dt, not resolved
wrongly; the
two-mass model's explicit step is held to the main mass's period as a system's is; a
random signal is sized by the run that uses it, not by a second of it; a whole number
no key takes is told its range. Independent values: the contact's duration measured by
an adaptive run, and the law's rebound (its restitution) once the step resolves it."""

from __future__ import annotations

import math
import re
import subprocess
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import vibroimpact as vi


def _stiff_contact() -> vi.System:
    """A 1 g damper on a 1e12 N/m^1.5 ``hertz-damped`` contact (e = 0.6): contacts of
    a few microseconds, in a forced 10 Hz oscillator's +-5 mm cavity."""
    return vi.System(
        structure=vi.Oscillator(mass=1.0, stiffness=3947.8, damping=2.513),
        dampers=[
            vi.Damper(
                mass=0.001,
                at=0,
                clearance=0.005,
                law="hertz-damped",
                stiffness=1e12,
                restitution=0.6,
            )
        ],
        excitations=[vi.Force(at=0, signal=vi.Harmonic(amplitude=5.0, frequency=10.0))],
    )


@pytest.mark.timeout(60)
@pytest.mark.parametrize(
    "settings",
    [
        {"method": "rk4", "dt": 1e-4},
        {"method": "rk4", "dt": 1e-4, "stepping": "fixed"},
        {"method": "newmark-implicit", "dt": 1e-5},
        {"method": "generalized-alpha", "dt": 1e-5},
    ],
    ids=["rk4", "rk4-fixed", "newmark-implicit", "generalized-alpha"],
)
def test_a_contact_shorter_than_two_steps_is_refused(settings: dict[str, Any]) -> None:
    # rk4 at dt = 1e-4 s rebounded at 0.71-1.0 for e = 0.6 and the ledger's contact
    # loss was 7 times dop853's; newmark-implicit rebounded at 1.0: no error.
    system = _stiff_contact()
    reference = vi.simulate(system, method="dop853", t_end=0.2, history=False)
    first = reference.contacts
    assert len(first) > 0
    with pytest.raises(vi.NumericalBlowUpError, match=r"^a contact beginning at") as refused:
        vi.simulate(system, t_end=0.2, history=False, **settings)
    said = re.search(r"at (\S+) m/s lasts about (\S+) s by its law", str(refused.value))
    assert said is not None, refused.value
    # The approach and the law's duration, as said, against the contact the adaptive
    # run resolved. Fixed stepping had said the interpolant's rate at the crossing of a
    # step far too long for the contact: 2.05e4 m/s for 0.23, a duration 10 times short.
    assert float(said.group(1)) == pytest.approx(first.approach_speed[0], rel=0.05)
    assert float(said.group(2)) == pytest.approx(first.duration[0], rel=0.3)


@pytest.mark.timeout(60)
def test_a_contact_the_fixed_step_resolves_rebounds_at_its_law() -> None:
    # The same contact with 20 steps of it: no refusal, and the law's rebound.
    system = _stiff_contact()
    reference = vi.simulate(system, method="dop853", t_end=0.2, history=False)
    assert len(reference.contacts) > 0
    dt = reference.contacts.duration[0] / 20
    end = reference.contacts.separation[0] + 1e-4
    run = vi.simulate(system, method="rk4", dt=dt, t_end=end, history=False)
    assert run.contacts.restitution[0] == pytest.approx(0.6, rel=2e-3)
    assert run.contacts.onset[0] == pytest.approx(reference.contacts.onset[0], rel=1e-6)


@pytest.mark.timeout(60)
def test_the_two_mass_models_explicit_step_is_held_to_its_period(
    tmp_path: Path, run_cli: Callable[..., subprocess.CompletedProcess[str]]
) -> None:
    # A 1 kg main mass on 1e12 N/m (a 1.6e5 Hz mode) by rk4 at dt = 1e-4 s blew up
    # ("NumericalBlowUpError", not a ValueError; exit 1), where the same structure
    # built as a system was refused up front.
    damper = vi.ImpactDamper(main_mass=1.0, stiffness=1e12, impact_mass=0.25, clearance=0.01)
    contact = vi.Contact("hertz", stiffness=3000.0)
    start = vi.InitialState(main_displacement=1e-3)
    frequency = math.sqrt(1e12 / 1.0) / (2 * math.pi)
    with pytest.raises(ValueError, match=r"\[solver\] dt: the fastest mode's period") as refused:
        vi.simulate(damper, contact, start, method="rk4", dt=1e-4, t_end=0.01)
    assert f"{frequency:.3g}" in str(refused.value)
    # A step the mode takes runs.
    run = vi.simulate(damper, contact, start, method="rk4", dt=1e-7, t_end=1e-4)
    assert np.all(np.isfinite(run.main_displacement))
    scenario = tmp_path / "stiff.toml"
    scenario.write_text(
        "[system]\nmain_mass = 1.0\nstiffness = 1e12\nimpact_mass = 0.25\nclearance = 0.01\n"
        '[contact]\nlaw = "hertz"\nstiffness = 3000.0\n'
        "[initial]\nmain_displacement = 1e-3\n"
        '[solver]\nmethod = "rk4"\ndt = 1e-4\nt_end = 0.01\n'
    )
    result = run_cli("simulate", str(scenario))
    assert result.returncode == 2, result.stderr
    assert "Traceback" not in result.stderr
    assert "the fastest mode's period" in result.stderr


@pytest.mark.timeout(60)
def test_a_random_signal_is_sized_by_the_run_that_uses_it() -> None:
    # Built without a solver, a white noise of cutoff 1e8 Hz was refused as "a random
    # signal of duration 1 s ... needs 2.000e8 samples": a second no one asked for.
    noise = vi.WhiteNoise(intensity=1.0, cutoff_frequency=1e8, seed=1)
    system = vi.System(
        structure=vi.Oscillator(mass=1.0, stiffness=3947.8, damping=2.513),
        excitations=[vi.Force(at=0, signal=noise)],
    )
    run = vi.simulate(system, method="dop853", t_end=1e-4, history=False)
    assert run.final_time == pytest.approx(1e-4)
    # A run that long is refused, its count of samples whole (1.000e8 had been
    # shown against "at most 100000000").
    with pytest.raises(ValueError, match=r"needs 200000001 samples; at most 100000000"):
        vi.simulate(system, method="dop853", t_end=1.0, history=False)


@pytest.mark.timeout(60)
@pytest.mark.parametrize("written", ["1e19", "1e30", "-1e19"])
def test_a_whole_number_no_key_takes_is_told_its_range(
    tmp_path: Path, run_cli: Callable[..., subprocess.CompletedProcess[str]], written: str
) -> None:
    # 1e30 was told "written as an integer (1e+30, not 1e+30)", 1e19 to be written as
    # 10000000000000000000, beyond 2^63 - 1.
    scenario = tmp_path / "steps.toml"
    scenario.write_text(
        '[structure]\nkind = "oscillator"\nmass = 1.0\nstiffness = 100.0\n'
        f'[solver]\nmethod = "dop853"\nt_end = 0.1\nmax_steps = {written}\n'
    )
    result = run_cli("simulate", str(scenario))
    assert result.returncode == 2, result.stderr
    assert "[solver] max_steps: must be a whole number in [1, 2^63 - 1]" in result.stderr
    high = vi.METHODS["rk4"]["options"]["max_steps"]["high"]
    assert high == pytest.approx(2.0**63)


@pytest.mark.timeout(60)
def test_an_implicit_step_that_creates_a_contacts_energy_on_entry_is_refused() -> None:
    # A 1 kg mass at 1 m/s onto a lossless linear stop (1e6 N/m: a contact of pi ms),
    # generalized-alpha with fixed steps of a quarter of it: the step entering the
    # contact created 3.8 % of the energy, and the mass left at 1.019 m/s (a lossless
    # contact cannot speed it up). The contact's own balance began at the end of that
    # step and did not see it; the run finished (a numerical-analysis probe). It now
    # begins at the step's start, and the run stops naming the contact.
    duration = math.pi * math.sqrt(1.0 / 1e6)
    system = vi.System(
        structure=vi.Oscillator(mass=1.0, stiffness=0.0, damping=0.0),
        stops=[vi.Stop(at=0, side="lower", gap=0.01, law="linear", stiffness=1e6)],
        initial=vi.Initial(structure_velocity=[-1.0]),
    )
    fixed = {"method": "generalized-alpha", "stepping": "fixed", "t_end": 0.02, "history": False}
    with pytest.raises(vi.EnergyBalanceError, match=r"^the contact from t = 1\.0\d*e-2 s"):
        vi.simulate(system, dt=duration / 4, **fixed)
    # Ten steps across it: within the contacts' 1 % (the speed within 1e-3 of 1 m/s).
    run = vi.simulate(system, dt=duration / 10, **fixed)
    assert run.final_state["structure_velocity"][0] == pytest.approx(1.0, abs=1e-3)
