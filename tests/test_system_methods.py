"""Every method on 0.2 systems of every kind: the same run to each method's accuracy,
their energy balances closed, the implicit methods' second order, and a harmonic's
work (a constant force as a 0 Hz harmonic, every harmonic in the exact flow).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from vibroimpact.system import simulate_system


@pytest.mark.parametrize("method", ["newmark-implicit", "generalized-alpha"])
def test_implicit_methods_take_systems_at_second_order(method: str) -> None:
    # The base-excited oscillator from its steady state: the error at 0.5 s falls
    # by 4 when the step halves.
    m, k, c, a0, f = 0.5, 200.0, 0.4, 3.0, 2.2
    w = 2 * math.pi * f
    x = -m * a0 / (k - m * w * w + 1j * c * w)
    exact = (x * np.exp(1j * w * 0.5)).real

    def error(dt: float) -> float:
        sol = simulate_system(
            {"kind": "oscillator", "mass": m, "stiffness": k, "damping": c},
            excitation=[{"kind": "base", "signal": "harmonic", "amplitude": a0, "frequency": f}],
            initial={"structure_displacement": [x.real], "structure_velocity": [-w * x.imag]},
            t_end=0.5,
            method=method,
            dt=dt,
            history=False,
        )
        return abs(float(sol.final_state["structure_displacement"][0]) - exact)

    order = math.log2(error(1e-3) / error(5e-4))
    assert abs(order - 2) < 0.05, order


# An aluminium cantilever, 0.5 m long, 2 % damping in every mode.
BEAM = {
    "kind": "cantilever",
    "length": 0.5,
    "youngs_modulus": 7e10,
    "second_moment": 1e-10,
    "mass_per_length": 0.27,
    "damping_ratio": 0.02,
}


EVERY_KIND = {
    "compliant damper, force": {
        "structure": {"kind": "oscillator", "mass": 1.0, "stiffness": 400.0, "damping": 0.5},
        "damper": [
            {
                "mass": 0.1,
                "at": 0,
                "clearance": 0.002,
                "law": "hertz-damped",
                "stiffness": 1e6,
                "restitution": 0.7,
            }
        ],
        "excitation": [
            {"kind": "force", "at": 0, "signal": "harmonic", "amplitude": 5.0, "frequency": 3.0}
        ],
    },
    "rigid damper, base motion, gravity": {
        "structure": {"kind": "oscillator", "mass": 1.0, "stiffness": 400.0, "damping": 0.5},
        "damper": [{"mass": 0.1, "at": 0, "clearance": 0.002, "law": "rigid", "restitution": 0.6}],
        "gravity": {},
        "excitation": [{"kind": "base", "signal": "harmonic", "amplitude": 20.0, "frequency": 3.0}],
    },
    "beam with a linear stop, two harmonics": {
        "structure": BEAM | {"modes": 2},
        "stop": [{"at": 0.5, "side": "upper", "gap": 5e-4, "law": "linear", "stiffness": 2e4}],
        "excitation": [
            {
                "kind": "force",
                "at": 0.5,
                "signal": "harmonics",
                "amplitudes": [0.5, 0.2],
                "frequencies": [10.0, 25.0],
            }
        ],
    },
    "two structures pounding (rigid and compliant), base motion": {
        "structure": {
            "kind": "matrices",
            "mass": [[1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 1.0]],
            "stiffness": [[1000.0, 0.0, 0.0], [0.0, 5000.0, 0.0], [0.0, 0.0, 2000.0]],
            "damping": [[1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 1.0]],
        },
        "stop": [
            {
                "at": 0,
                "against": 1,
                "side": "upper",
                "gap": 1e-3,
                "law": "rigid",
                "restitution": 0.6,
            },
            {
                "at": 2,
                "against": 1,
                "side": "lower",
                "gap": 1e-3,
                "law": "linear",
                "stiffness": 1e5,
            },
        ],
        "excitation": [{"kind": "base", "signal": "harmonic", "amplitude": 20.0, "frequency": 3.0}],
    },
    "beam tip pounding on mid-span (m along the beam)": {
        "structure": BEAM | {"modes": 3},
        "stop": [
            {
                "at": 0.5,
                "against": 0.25,
                "side": "upper",
                "gap": 2e-4,
                "law": "linear",
                "stiffness": 1e4,
            }
        ],
        "excitation": [
            {"kind": "force", "at": 0.5, "signal": "harmonic", "amplitude": 0.5, "frequency": 8.0}
        ],
    },
}


# Each method at settings where it is accurate: (settings, tolerance on the end state
# relative to its size, tolerance on the energy residual relative to the energies).
METHODS = {
    "rk4": ({"dt": 1e-5}, 1e-8, 1e-9),
    "dopri5": ({"rtol": 1e-10, "atol": 1e-14}, 1e-7, 1e-8),
    "newmark-implicit": ({"dt": 1e-5}, 1e-4, 1e-5),
    "generalized-alpha": ({"dt": 1e-5}, 1e-4, 1e-5),
}


@pytest.mark.parametrize("kind", list(EVERY_KIND))
def test_every_method_gives_the_same_run_and_closes_its_energy_balance(kind: str) -> None:
    """Contacts one by one and the end state against DOP853 at rtol 1e-12, and the
    energy balance of every method, for a compliant and a rigid damper, force and base
    excitation, gravity, and a beam hitting a stop."""
    case = EVERY_KIND[kind]
    ref = simulate_system(**case, t_end=0.5, method="dop853", rtol=1e-12, atol=1e-15)
    end = ref.final_state["structure_displacement"]
    assert len(ref.contacts) > 5
    for method, (settings, state_tolerance, energy_tolerance) in METHODS.items():
        sol = simulate_system(**case, t_end=0.5, method=method, **settings)
        assert sol.contacts.pair == ref.contacts.pair and sol.contacts.kind == ref.contacts.kind
        np.testing.assert_allclose(sol.contacts.onset, ref.contacts.onset, atol=1e-4)
        error = np.max(np.abs(sol.final_state["structure_displacement"] - end))
        assert error < state_tolerance * np.max(np.abs(end)), (method, error)
        e = sol.energy
        scale = abs(e["input_work"]) + e["dissipated"] + abs(e["stored_end"])
        assert abs(e["residual"]) < energy_tolerance * scale, (method, e)


@pytest.mark.parametrize("method", ["exact", "dop853"])
def test_a_constant_force_as_a_0_hz_harmonic_does_its_work(method: str) -> None:
    # A step force F0 on a damped oscillator from rest: x = F0/k (1 - e^(-z w t) (cos wd t +
    # z / sqrt(1 - z^2) sin wd t)), and the force's work is F0 x (the exact flow used to
    # count a 0 Hz force as a potential, like gravity, and failed its energy balance).
    m, k, c, force, t = 0.05, 100.0, 0.01, 0.1, 0.5
    w = math.sqrt(k / m)
    zeta = c / (2 * math.sqrt(k * m))
    wd = w * math.sqrt(1 - zeta * zeta)
    decay = math.exp(-zeta * w * t)
    x = (
        force
        / k
        * (1 - decay * (math.cos(wd * t) + zeta / math.sqrt(1 - zeta**2) * math.sin(wd * t)))
    )
    settings = {"rtol": 1e-12, "atol": 1e-15} if method == "dop853" else {}
    sol = simulate_system(
        {"kind": "oscillator", "mass": m, "stiffness": k, "damping": c},
        excitation=[
            {"kind": "force", "at": 0, "signal": "harmonic", "amplitude": force, "frequency": 0.0}
        ],
        t_end=t,
        method=method,
        **settings,
    )
    assert sol.final_state["structure_displacement"][0] == pytest.approx(x, rel=1e-9)
    assert sol.energy["input_work"] == pytest.approx(force * x, rel=1e-9)
    assert abs(sol.energy["residual"]) < 1e-12 * sol.energy["input_work"]


@pytest.mark.parametrize(("first", "second"), [(5.0, 15.0), (15.0, 5.0), (7.0, 15.0)])
def test_the_exact_flow_takes_the_work_of_every_harmonic(first: float, second: float) -> None:
    # Two harmonic forces at different frequencies on a damped oscillator: the exact flow's
    # input work against DOP853 at rtol 1e-12 (its quadrature once took the first
    # harmonic's power with the rates of the harmonics before it only, and 5 + 15 Hz
    # failed its energy balance).
    structure = {"kind": "oscillator", "mass": 1.0, "stiffness": 3947.8, "damping": 2.513}
    excitation = [
        {"kind": "force", "at": 0, "signal": "harmonic", "amplitude": 5.0, "frequency": first},
        {"kind": "force", "at": 0, "signal": "harmonic", "amplitude": 1.0, "frequency": second},
    ]
    exact = simulate_system(structure, excitation=excitation, t_end=2.0, method="exact")
    ref = simulate_system(
        structure, excitation=excitation, t_end=2.0, method="dop853", rtol=1e-12, atol=1e-15
    )
    assert exact.energy["input_work"] == pytest.approx(ref.energy["input_work"], rel=1e-9)
    assert abs(exact.energy["residual"]) < 1e-12 * exact.energy["input_work"]
