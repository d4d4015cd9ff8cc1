"""Studies with ``stepping = "fixed"``: the runs advanced in lockstep by the core's
ensemble kernel. Each run is the fixed-step RK4 run that ``vi.simulate`` makes of the
same two-mass damper (its contacts, and its history's peak and RMS, to round-off in the
sums: the lanes' states are the single run's bit for bit); the event-driven study of the
same grid agrees to the methods' accuracy; the same results whatever the number of
threads; a run that blows up fails alone; scenarios the kernel cannot take are refused
naming the key."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import docs_blocks
import vibroimpact as vi
from study_checks import assert_refused, load_study  # noqa: E402
from vibroimpact import study as st

M, K, C, MD, D, KHZ, C1 = 1.0, 1.0, 0.01, 0.25, 0.01, 3000.0, 0.01
DT, T_END = 1e-4, 3.0

BASE = f"""
[structure]
kind = "oscillator"
mass = {M}
stiffness = {K}
damping = {C}

[[damper]]
mass = {MD}
at = 0
clearance = {D}
law = "hertz"
stiffness = {KHZ}
damping = {C1}

[solver]
method = "rk4"
dt = {DT}
t_end = {T_END}
"""

STUDY = """
[study]
analysis = "run"
stepping = "fixed"
metrics = ["peak", "rms", "impacts"]
chunk_size = 5

[study.axes]
"initial.damper_velocity.0" = [0.06, 0.1, 0.14]
"damper.0.clearance" = [0.005, 0.01, 0.02]
"""


def load(tmp_path: Path, text: str) -> st.Study:
    return load_study(tmp_path / "study.toml", text)


def test_each_run_is_the_fixed_step_kernels_run(tmp_path: Path) -> None:
    ds = st.run(load(tmp_path, BASE + STUDY), tmp_path / "out.nc", threads=2)
    assert int(ds["status"].max()) == 0
    for velocity in (0.06, 0.1, 0.14):
        for clearance in (0.005, 0.01, 0.02):
            sol = vi.simulate(
                vi.ImpactDamper(
                    main_mass=M, stiffness=K, damping=C, impact_mass=MD, clearance=clearance
                ),
                vi.Contact("hertz", stiffness=KHZ, damping=C1),
                vi.InitialState(impact_velocity=velocity),
                method="rk4",
                stepping="fixed",
                dt=DT,
                t_end=T_END,
            )
            point = ds.sel({"initial.damper_velocity.0": velocity, "damper.0.clearance": clearance})
            assert point["impacts"].item() == len(sol.contacts.onset) > 0
            w = sol.main_displacement
            # RMS: the trapezoidal rule over the same step ends (summed in another order).
            rms = np.sqrt(np.trapezoid(w * w, dx=DT) / T_END)
            assert point["rms"].item() == pytest.approx(rms, rel=1e-12)
            # Peak: at least the largest step end, above it only by the located
            # extremum inside a step (the curvature over one step: ~ (w dt)^2).
            peak = point["peak"].item()
            top = np.abs(w).max()
            assert top <= peak <= top * (1 + 1e-7)


def test_fixed_and_event_stepping_agree_to_the_methods_accuracy(tmp_path: Path) -> None:
    fixed = st.run(load(tmp_path, BASE + STUDY), tmp_path / "fixed.nc")
    events = st.run(
        load(tmp_path, BASE + STUDY.replace('stepping = "fixed"', 'stepping = "events"')),
        tmp_path / "events.nc",
    )
    assert np.array_equal(fixed["impacts"].values, events["impacts"].values)
    # The fixed steps run through each contact onset, where the contact damper's force
    # jumps (first order there); the event-driven steps end on it.
    for key in ("peak", "rms"):
        assert np.allclose(fixed[key].values, events[key].values, rtol=1e-5, atol=0), key
        assert not np.array_equal(fixed[key].values, events[key].values), key


def test_results_do_not_depend_on_the_number_of_threads(tmp_path: Path) -> None:
    study = load(tmp_path, BASE + STUDY)
    one = study.run_chunk(range(0, study.runs), threads=1)
    two = study.run_chunk(range(1, study.runs), threads=2)
    for key in ("peak", "rms", "impacts"):
        a, b = np.asarray(one[key]), np.asarray(two[key])
        assert np.array_equal(a[1:], b), key


def test_a_run_that_blows_up_fails_alone(tmp_path: Path) -> None:
    text = BASE + STUDY.replace(
        '"damper.0.clearance" = [0.005, 0.01, 0.02]',
        '"damper.0.stiffness" = [3000.0, 1e13, 3000.0]',
    )
    ds = st.run(load(tmp_path, text), tmp_path / "out.nc")
    status = ds["status"].values
    assert (status[:, 1] > 0).all() and (status[:, [0, 2]] == 0).all()
    reasons = json.loads(ds.attrs["reasons"])
    assert reasons and all("reduce dt" in r for r in reasons)
    assert np.isnan(ds["peak"].values[:, 1]).all()


def test_a_run_that_creates_energy_fails_alone(tmp_path: Path) -> None:
    # A linear contact of 1e6 N/m on the 0.25 kg mass (2000 rad/s) at dt = 1e-2 s:
    # RK4 is unstable across the contact, which rebounds with thousands of times the
    # energy it met, and the run ends (0.5 s) before a second contact could overflow
    # it: the check finds growth, not a state no longer finite. At 100 N/m
    # (20 rad/s) the step is stable. The single-run kernel refuses the same system from
    # its own start (where the contact's onset falls at a step's end: stopped there, the
    # contact far under two steps).
    text = BASE.replace('law = "hertz"', 'law = "linear"').replace(
        f"dt = {DT}", "dt = 1e-2"
    ).replace(f"t_end = {T_END}", "t_end = 0.5") + STUDY.replace(
        '"damper.0.clearance" = [0.005, 0.01, 0.02]', '"damper.0.stiffness" = [100.0, 1e6]'
    )
    ds = st.run(load(tmp_path, text), tmp_path / "out.nc")
    status = ds["status"].values
    assert (status[:, 0] == 0).all() and (status[:, 1] > 0).all()
    reasons = json.loads(ds.attrs["reasons"])
    assert reasons and all("energy created" in r for r in reasons), reasons
    assert np.isnan(ds["peak"].values[:, 1]).all()
    with pytest.raises(vi.NumericalBlowUpError):
        vi.simulate(
            vi.ImpactDamper(main_mass=M, stiffness=K, damping=C, impact_mass=MD, clearance=D),
            vi.Contact("linear", stiffness=1e6, damping=C1),
            vi.InitialState(impact_velocity=0.1),
            method="rk4",
            stepping="fixed",
            dt=1e-2,
            t_end=0.5,
        )


@pytest.mark.parametrize(
    ("change", "words"),
    [
        (('stepping = "fixed"', 'stepping = "lockstep"'), ["stepping", "fixed"]),
        (
            ('metrics = ["peak", "rms", "impacts"]', 'metrics = ["energy_dissipated"]'),
            ["energy_dissipated", "stepping"],
        ),
        (('analysis = "run"', 'analysis = "steady-state"'), ["stepping", "analysis"]),
        (('method = "rk4"', 'method = "dop853"'), ["stepping", "rk4"]),
        (
            (
                f'law = "hertz"\nstiffness = {KHZ}\ndamping = {C1}',
                'law = "rigid"\nrestitution = 0.5',
            ),
            ["stepping", "rigid"],
        ),
        # Unequal clearances and gravity are taken by the compact lanes; a base
        # excitation is not.
        (
            (
                "[solver]",
                '[[excitation]]\nkind = "base"\nsignal = "harmonic"\n'
                "amplitude = 1.0\nfrequency = 1.0\n[solver]",
            ),
            ["stepping", "small modal"],
        ),
    ],
)
def test_what_the_lockstep_kernel_cannot_take_exits_2_naming_the_key(
    tmp_path: Path, run_cli: Callable[..., Any], change: tuple[str, str], words: list[str]
) -> None:
    text = (BASE + STUDY).replace(*change)
    assert text != BASE + STUDY
    path = tmp_path / "study.toml"
    path.write_text(text)
    done = run_cli("study", str(path), "--out", str(tmp_path / "r.nc"))
    assert_refused(done, words, tmp_path / "r.nc")


def test_the_docs_lockstep_block_runs(tmp_path: Path) -> None:
    lockstep = docs_blocks.section("analyses", "Lockstep ensembles")
    block = docs_blocks.blocks(lockstep, "toml")[0]
    # Fewer runs than the page's 10000, to keep the test short.
    assert "count = 10000" in block
    ds = st.run(
        load(tmp_path, BASE + block.replace("count = 10000", "count = 16")), tmp_path / "r.nc"
    )
    assert int(ds["status"].max()) == 0
    assert (ds["impacts"].values > 0).all()
    # A faster loose mass rattles harder: the peak grows along the axis.
    assert (np.diff(ds["peak"].values[:, 0]) > 0).all()


def test_structure_axes_run_in_lockstep_too(tmp_path: Path) -> None:
    text = BASE + STUDY.replace(
        '"damper.0.clearance" = [0.005, 0.01, 0.02]', '"structure.stiffness" = [0.5, 1.0, 4.0]'
    )
    ds = st.run(load(tmp_path, text), tmp_path / "out.nc")
    assert int(ds["status"].max()) == 0
    for stiffness in (0.5, 4.0):
        sol = vi.simulate(
            vi.ImpactDamper(
                main_mass=M, stiffness=stiffness, damping=C, impact_mass=MD, clearance=D
            ),
            vi.Contact("hertz", stiffness=KHZ, damping=C1),
            vi.InitialState(impact_velocity=0.1),
            method="rk4",
            stepping="fixed",
            dt=DT,
            t_end=T_END,
        )
        point = ds.sel({"initial.damper_velocity.0": 0.1, "structure.stiffness": stiffness})
        assert point["impacts"].item() == len(sol.contacts.onset)
        w = sol.main_displacement
        assert point["rms"].item() == pytest.approx(
            np.sqrt(np.trapezoid(w * w, dx=DT) / T_END), rel=1e-12
        )


# The acceptance case of issue 24: a forced 2-mode cantilever with two hertz-damped
# dampers, 1,000 runs in compact lockstep lanes, each equal bit for bit to the single
# fixed-step run of the same system (t_end shortened to keep the test fast).
FREQUENCIES = [4.0 + 0.9 * i for i in range(40)]
CLEARANCES = [1e-4 + 1.6e-5 * j for j in range(25)]
CANTILEVER = {
    "kind": "cantilever",
    "length": 0.5,
    "youngs_modulus": 7e10,
    "second_moment": 1e-10,
    "mass_per_length": 0.27,
    "modes": 2,
    "damping_ratio": 0.01,
}


def _damper(at: float, clearance: float) -> dict[str, Any]:
    return {
        "mass": 0.01,
        "at": at,
        "clearance": clearance,
        "law": "hertz-damped",
        "stiffness": 1e7,
        "restitution": 0.6,
    }


def _force(frequency: float) -> dict[str, Any]:
    return {
        "kind": "force",
        "at": 0.5,
        "signal": "harmonic",
        "amplitude": 2.0,
        "frequency": frequency,
    }


def _toml(value: Any) -> str:
    return json.dumps(value)


def test_a_forced_cantilever_study_in_lanes_is_its_single_fixed_runs(tmp_path: Path) -> None:
    dt, t_end, record_from = 1e-5, 4e-3, 1e-3
    lines = ["[structure]", *(f"{k} = {_toml(v)}" for k, v in CANTILEVER.items())]
    for at, clearance in ((0.5, 2e-4), (0.25, 1e-4)):
        lines += ["[[damper]]", *(f"{k} = {_toml(v)}" for k, v in _damper(at, clearance).items())]
    lines += ["[[excitation]]", *(f"{k} = {_toml(v)}" for k, v in _force(8.0).items())]
    lines += [
        "[solver]",
        'method = "rk4"',
        f"dt = {dt}",
        f"t_end = {t_end}",
        "[study]",
        'analysis = "run"',
        'stepping = "fixed"',
        f"record_from = {record_from}",
        'metrics = ["peak", "rms", "impacts"]',
        "chunk_size = 1000",
        "[study.axes]",
        f'"excitation.0.frequency" = {_toml(FREQUENCIES)}',
        f'"damper.0.clearance" = {_toml(CLEARANCES)}',
    ]
    study = load(tmp_path, "\n".join(lines) + "\n")
    assert study.runs == 1000
    out = study.run_chunk(range(study.runs), threads=2)
    peak = np.asarray(out["peak"]).reshape(1000, 2)
    rms = np.asarray(out["rms"]).reshape(1000, 2)
    impacts = np.asarray(out["impacts"])
    assert int(np.asarray(out["status"]).max()) == 0
    assert impacts.sum() > 100
    for row in range(1000):
        frequency, clearance = FREQUENCIES[row // 25], CLEARANCES[row % 25]
        sol = vi.simulate_system(
            CANTILEVER,
            damper=[_damper(0.5, clearance), _damper(0.25, 1e-4)],
            excitation=[_force(frequency)],
            method="rk4",
            dt=dt,
            t_end=t_end,
            stepping="fixed",
            record_from=record_from,
        )
        onsets = np.asarray(sol.contacts.onset)
        assert impacts[row] == np.count_nonzero(onsets >= record_from), row
        # Bit for bit: the same float64 values.
        assert peak[row].tobytes() == np.asarray(sol.peak).tobytes(), row
        assert rms[row].tobytes() == np.asarray(sol.rms).tobytes(), row
