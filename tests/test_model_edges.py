"""The typed model and its results at the edges a new user's probe found (issue 24):
results compared and hashed, a System's analyses its own, the folder of a record read
by a relative path counted in a System's equality, a short repr of a long record, the
contact table's units, the history's whole results in xarray, what ``simulate`` and
``System`` say to a wrong argument, and an initial state of the wrong length refused
when the System is built."""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest

import vibroimpact as vi
from model_checks import ROOT


def _oscillator(**keys: object) -> vi.System:
    return vi.System(structure=vi.Oscillator(mass=1.0, stiffness=3947.8, damping=2.513), **keys)


def _rattling() -> vi.System:
    return vi.load(ROOT / "examples" / "frf_impact_damper.toml")


@pytest.mark.timeout(60)
def test_results_compare_by_identity_and_hash() -> None:
    """``==`` of two solutions raised numpy's 'truth value of an array is ambiguous',
    and ``hash`` a TypeError: results are compared by identity, as the two-mass run's
    are."""
    system = _rattling()
    first, second = vi.simulate(system, t_end=0.05), vi.simulate(system, t_end=0.05)
    assert first == first and first != second
    assert first.contacts == first.contacts and first.contacts != second.contacts
    assert len({first, second, first.contacts}) == 3
    # Their values are the same: the arrays say so.
    assert np.array_equal(first.structure_displacement, second.structure_displacement)


@pytest.mark.timeout(60)
def test_a_systems_analyses_are_its_own() -> None:
    """``to_dict()`` and the dict a System was given shared the analyses' tables: a
    change to either changed the System (and ``load(to_toml())`` then failed)."""
    table = {"parameter": "structure.stiffness", "start": 1000.0, "stop": 2000.0, "count": 5}
    given = {"sweep": dict(table, derivatives=["structure.damping"])}
    system = _oscillator(analyses=given)
    given["sweep"]["derivatives"] = ["structure.mass"]
    sections = system.to_dict()
    sections["sweep"]["derivatives"].append("structure.mass")
    assert system.analyses == {"sweep": dict(table, derivatives=["structure.damping"])}
    assert vi.load(system.to_toml()) == system


def _recorded(base_dir: Path | None) -> vi.System:
    return _oscillator(excitations=[vi.Base(signal=vi.Recorded(file="acc.csv"))], base_dir=base_dir)


@pytest.mark.timeout(60)
def test_systems_reading_one_relative_record_name_in_two_folders_differ(
    tmp_path: Path,
) -> None:
    """Two Systems of the same text read from two folders compared equal (and hashed
    the same) while they ran two records."""
    here, there = tmp_path / "here", tmp_path / "there"
    for folder, scale in ((here, 1.0), (there, 2.0)):
        folder.mkdir()
        times = np.linspace(0.0, 0.2, 201)
        rows = "\n".join(f"{float(t)!r},{scale * math.sin(60.0 * t)!r}" for t in times)
        (folder / "acc.csv").write_text(f"time,acceleration\n{rows}\n", encoding="utf-8")
    system, elsewhere = _recorded(here), _recorded(there)
    a = vi.simulate(system, method="dop853", t_end=0.2)
    b = vi.simulate(elsewhere, method="dop853", t_end=0.2)
    assert not np.array_equal(a.structure_displacement, b.structure_displacement)
    assert elsewhere != system
    assert system == _recorded(here) and hash(system) == hash(_recorded(here))
    # Saved beside its record, the text reads it again: an equal System, the same run.
    (here / "shaken.toml").write_text(system.to_toml(), encoding="utf-8")
    again = vi.load(here / "shaken.toml")
    assert again == system
    c = vi.simulate(again, method="dop853", t_end=0.2)
    assert np.array_equal(a.structure_displacement, c.structure_displacement)
    # Loaded by a relative path, it reads its own record after a change of folder (it
    # read the other folder's, no error), and two spellings of the path are one System.
    with pytest.MonkeyPatch.context() as patch:
        patch.chdir(tmp_path)
        relative = vi.load(Path("here") / "shaken.toml")
        assert relative == system == vi.load(Path("there/../here/shaken.toml"))
        patch.chdir(there)
        d = vi.simulate(relative, method="dop853", t_end=0.2)
    assert np.array_equal(a.structure_displacement, d.structure_displacement)
    # Where no file is read, the folder does not matter.
    assert _oscillator(base_dir=here) == _oscillator(base_dir=there)

    class Named(vi.System):
        """A System of a user's own kind: its equal instances are equal."""

    made = {"structure": vi.Oscillator(mass=1.0, stiffness=1.0)}
    assert Named(**made) == Named(**made) and Named(**made) != vi.System(**made)


@pytest.mark.timeout(30)
def test_a_long_record_has_a_short_repr() -> None:
    """A record of 10,000 samples gave a repr of 414,347 characters."""
    times = np.linspace(0.0, 1.0, 10_000)
    signal = vi.Recorded(time=times, value=np.sin(times))
    system = _oscillator(excitations=[vi.Base(signal=signal)])
    assert len(repr(signal)) < 300 and "10000 in all" in repr(signal)
    assert len(repr(system)) < 600 and "\n" not in repr(system)
    # Short arrays are shown whole, a matrix of one row as the tuple it is.
    one_row = repr(vi.Matrices(mass=[[1.0]], stiffness=[[4.0]]))
    assert "mass=((1.0,),)" in one_row and "stiffness=((4.0,),)" in one_row
    assert repr(vi.Harmonics(amplitudes=[1.0, 2.0], frequencies=[3.0, 4.0])) == (
        "Harmonics(amplitudes=(1.0, 2.0), frequencies=(3.0, 4.0))"
    )


@pytest.mark.timeout(60)
def test_the_contact_table_states_its_units_and_keeps_its_text() -> None:
    sol = vi.simulate(_rattling(), t_end=0.2)
    frame = sol.contacts.to_pandas()
    units = frame.attrs["units"]
    assert units["onset"] == "s" and units["approach_speed"] == "m s-1"
    assert units["energy_dissipated"] == "J" and units["max_indentation"] == "m"
    assert set(units) == set(frame.columns)
    empty = vi.simulate(_oscillator(), method="dop853", t_end=0.05).contacts
    assert len(empty) == 0 and repr(empty).startswith("SystemContacts(0 contacts")
    # Text columns stay text (pandas made the empty ones float64).
    assert empty.to_pandas()["pair"].dtype == object
    one = vi.simulate(_rattling(), t_end=0.2).contacts
    first = vi.SystemContacts(**{name: getattr(one, name)[:1] for name in one.columns})
    assert repr(first).startswith("SystemContacts(1 contact,")


@pytest.mark.timeout(60)
def test_the_history_in_xarray_holds_the_runs_results() -> None:
    """``to_xarray()`` left out the contact force, the recorded peak and RMS, the
    recorded time and the strobe."""
    system = vi.load(ROOT / "examples" / "hyster_hertz.toml")
    sol = vi.simulate(system, t_end=0.3, record_from=0.1, strobe_period=0.05)
    data = sol.to_xarray()
    assert np.array_equal(data["contact_force"].to_numpy(), sol.contact_force)
    assert list(data["contact_pair"].values) == sol.contact_force_pairs
    assert data["contact_force"].attrs["units"] == "N"
    assert np.array_equal(data["peak"].to_numpy(), sol.peak)
    assert np.array_equal(data["rms"].to_numpy(), sol.rms)
    assert data.attrs["recorded_time"] == sol.recorded_time > 0
    assert np.array_equal(data["strobe"].to_numpy(), sol.strobe)
    assert np.array_equal(data["strobe_time"].to_numpy(), sol.strobe_time)
    # A strobe row is every displacement, then every velocity; the last is at t_end.
    assert list(data["state"].values) == [
        "structure_displacement_0",
        "damper_displacement_0",
        "structure_velocity_0",
        "damper_velocity_0",
    ]
    last = data["strobe"].isel(strobe_time=-1)
    assert float(data["strobe_time"][-1]) == pytest.approx(0.3)
    for name in ("structure_displacement", "damper_displacement", "damper_velocity"):
        assert float(last.sel(state=f"{name}_0")) == sol.final_state[name][0]


@pytest.mark.parametrize(
    ("value", "words"),
    [
        (None, "got None"),
        ("examples/x.toml", "vibroimpact.load(path) first"),
        ({"structure": {}}, "System.from_dict"),
        (vi.Oscillator(mass=1.0, stiffness=1.0), "one part of vibroimpact.System"),
    ],
)
@pytest.mark.timeout(30)
def test_simulate_of_something_else_says_what_a_system_is(value: object, words: str) -> None:
    """Each said "missing a required argument: 'contact'" (the two-mass run's)."""
    with pytest.raises(vi.InvalidInputError, match="system: must be a vibroimpact.System") as err:
        vi.simulate(value, t_end=1.0)  # type: ignore[call-overload]
    assert words in str(err.value)


@pytest.mark.timeout(30)
def test_wrong_keywords_are_value_errors_that_are_type_errors() -> None:
    """Each raised a bare TypeError; the standard is a ValueError naming the argument
    (Python's own TypeError kept for code that catches it)."""
    system = _oscillator()
    damper = vi.ImpactDamper(main_mass=1.0, stiffness=1.0, impact_mass=0.25, clearance=0.01)
    calls = [
        (lambda: vi.System(vi.Oscillator(mass=1.0, stiffness=1.0)), "keywords only"),  # type: ignore[misc]
        (lambda: _oscillator(foo=1), "unknown key 'foo'"),
        (lambda: vi.simulate(system, foo=1), "unexpected keyword argument 'foo'"),  # type: ignore[call-overload]
        (lambda: vi.check_solver(method="rk4", dt=1e-3, t_end=1.0, foo=1), "'foo'"),
        (lambda: vi.simulate(damper, t_end=1.0), "needs its Contact and InitialState"),  # type: ignore[call-overload]
    ]
    for call, words in calls:
        with pytest.raises(ValueError, match=words) as err:
            call()
        assert isinstance(err.value, TypeError | vi.InvalidInputError)


@pytest.mark.timeout(30)
def test_an_initial_state_of_the_wrong_length_is_refused_when_the_system_is_built() -> None:
    """Built and loaded, refused only when simulated ('must have 1 value')."""
    with pytest.raises(
        vi.InvalidInputError,
        match=r"\[initial\] structure_displacement: must have 1 value .* got 2",
    ):
        _oscillator(initial=vi.Initial(structure_displacement=[0.001, 1.0]))
    with pytest.raises(vi.InvalidInputError, match=r"damper_velocity: must have 0 values"):
        _oscillator(initial=vi.Initial(damper_velocity=[1.0]))
    text = _oscillator().to_toml() + "\n[initial]\nstructure_velocity = [0.0, 0.0]\n"
    with pytest.raises(vi.InvalidInputError, match="structure_velocity: must have 1 value"):
        vi.load(text)
    # The right lengths (or none) are taken.
    _oscillator(initial=vi.Initial(structure_displacement=[0.001], structure_velocity=[]))


@pytest.mark.timeout(60)
def test_a_text_longer_than_a_scenario_file_may_be_says_so() -> None:
    """A record of 300,000 samples gave 12 MB of text, which load() of a file refuses (a
    scenario file is at most 4 MiB) without a word when it was written: to_toml warns."""
    times = np.linspace(0.0, 10.0, 300_000)
    signal = vi.Recorded(time=times, value=np.sin(times))
    system = _oscillator(excitations=[vi.Force(at=0, signal=signal)])
    with pytest.warns(UserWarning, match=r"^System.to_toml: the scenario is 1\d\.\d MiB, more"):
        system.to_toml()
    short = _oscillator(excitations=[vi.Force(at=0, signal=vi.Recorded(time=[0, 1], value=[0, 1]))])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert vi.load(short.to_toml()) == short


def test_a_strobe_row_is_the_flat_state_as_documented() -> None:
    # The docs said "the history's columns" (structure displacements, then velocities,
    # then the dampers'); a row is the flat state: every displacement, then every velocity.
    system = vi.System(
        structure=vi.Matrices(mass=[[1.0, 0.0], [0.0, 2.0]], stiffness=[[300, -100], [-100, 200]]),
        dampers=[vi.Damper(mass=0.1, at=0, clearance=0.01, law="rigid", restitution=0.5)],
        excitations=[vi.Force(at=0, signal=vi.Harmonic(amplitude=2.0, frequency=3.0))],
    )
    sol = vi.simulate(system, method="dopri5", t_end=1.0, strobe_period=0.5)
    assert sol.strobe_time[-1] == 1.0 and sol.final_time == 1.0
    s = sol.final_state
    flat = np.concatenate(
        [s["structure_displacement"], s["damper_displacement"]]
        + [s["structure_velocity"], s["damper_velocity"]]
    )
    assert np.array_equal(sol.strobe[-1], flat)


def test_the_exact_flow_ends_at_t_end_itself() -> None:
    # Its last step ended on t_end to the grid's round-off, and the run reported that:
    # 0.9999999999999982 (the history's last time too) where every other method ends on 1.
    root = Path(__file__).resolve().parents[1] / "examples"
    for name in ("bouncing_ball_table", "ball_table_basins", "frf_impact_damper"):
        system = vi.load(root / f"{name}.toml")
        sol = vi.simulate(system, method="exact", t_end=1.0, every=1)
        assert sol.final_time == 1.0 and sol.to_xarray()["time"].values[-1] == 1.0, name


def test_masses_beyond_the_exact_flow_s_resolution_are_told_so() -> None:
    # A 1e-15 kg damper on a 1 kg structure read "the mass matrix is not positive
    # definite", naming no key, for a diagonal, positive matrix (the factor's resolution
    # is 1e-14 of its largest entry); dop853 runs the same system.
    system = vi.System(
        structure=vi.Oscillator(mass=1.0, stiffness=100.0),
        dampers=[vi.Damper(mass=1e-15, at=0, clearance=0.01, law="rigid", restitution=0.5)],
        initial=vi.Initial(structure_velocity=[0.1]),
    )
    with pytest.raises(vi.InvalidInputError) as err:
        vi.simulate(system, method="exact", t_end=0.1)
    said = str(err.value)
    assert "masses span 1.000e-15 kg to 1.000e0 kg" in said and '"dop853"' in said
    assert vi.simulate(system, method="dop853", t_end=0.1).final_time == 0.1


def _damper(law: str, **keys: object) -> list[vi.Damper]:
    return [vi.Damper(mass=0.05, at=0, clearance=0.005, law=law, **keys)]


@pytest.mark.timeout(60)
@pytest.mark.parametrize(
    ("keys", "words"),
    [
        # Analyses' and the study's tables, as vi.load checks them (the System had
        # been built, and its to_toml() refused by vi.load).
        (
            {"analyses": {"sweep": {"parameter": "excitation.0.frequency", "count": 0}}},
            "[sweep] count",
        ),
        ({"analyses": {"sweep": {"parameter": "excitation.0.frequency", "bogus": 1}}}, "bogus"),
        (
            {"analyses": {"study": {"analysis": "run", "metrics": ["bogus"], "axes": {}}}},
            "[study] metrics",
        ),
        # The output and the method's fit to the model without the run's length
        # (checked only when t_end was given).
        ({"output": vi.Output(every=0)}, "[output] every"),
        ({"output": vi.Output(points=[3])}, "[output] points[0]"),
        ({"output": vi.Output(strobe_period=-1.0)}, "[output] strobe_period"),
        ({"output": vi.Output(record_from=-1.0)}, "[output] record_from"),
        ({"output": vi.Output(moments=[0.1])}, "[output] moments"),
        (
            {"dampers": _damper("rigid", restitution=0.6), "solver": vi.Solver(method="newmark")},
            "compliant contact laws only",
        ),
        (
            {"dampers": _damper("hertz", stiffness=1e7), "solver": vi.Solver(method="exact")},
            "rigid and linear laws only",
        ),
        (
            {
                "dampers": _damper("rigid", restitution=0.6),
                "solver": vi.Solver(method="rk4", dt=1e-4, stepping="fixed"),
            },
            "compliant contact laws only",
        ),
        ({"solver": vi.Solver(method="rk4", dt=1.0)}, "[solver] dt"),
    ],
)
def test_a_system_without_its_runs_length_is_checked_as_a_run_of_it(
    keys: dict[str, object], words: str
) -> None:
    analyses = keys.pop("analyses", None)
    if analyses is not None:
        base = _rattling()
        with pytest.raises(ValueError) as refused:
            base.replace(analyses=analyses)
    else:
        with pytest.raises(ValueError) as refused:
            _oscillator(**keys)
    assert words in str(refused.value) and "\n" not in str(refused.value)


@pytest.mark.timeout(60)
@pytest.mark.parametrize("method", ["rk4", "newmark", "generalized-alpha", "dop853", "exact"])
def test_a_system_whose_runs_are_given_their_step_is_built_and_runs(method: str) -> None:
    # A fixed step left to the run is checked then, not refused when the System is
    # built; the window's start against the run's length then too.
    system = _oscillator(solver=vi.Solver(method=method), output=vi.Output(record_from=0.05))
    step = None if method in ("dop853", "exact") else 1e-4
    solution = vi.simulate(system, t_end=0.1, dt=step)
    assert solution.recorded_time == pytest.approx(0.05, abs=1e-4)
    with pytest.raises(ValueError, match="record_from"):
        vi.simulate(system, t_end=0.04, dt=step)
