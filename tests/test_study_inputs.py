"""A study's inputs at their edges (a new user's trial): axes given from Python as numpy
arrays are checked as a file's are, an index spelled with a leading zero is refused (it
made a second axis of one parameter), a recorded window past the run's end is refused
as a single run refuses it, a ``[study]`` that is not a table says so, and Ctrl-C during
a chunk stops the study even where the chunk's last run ends before it is seen."""

from __future__ import annotations

import dataclasses
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

import vibroimpact as vi
from conftest import shell_signals
from study_checks import FORCED_DAMPER, load_study
from vibroimpact import study as st

SYSTEM = vi.System(
    structure=vi.Oscillator(mass=1.0, stiffness=3947.8, damping=2.513),
    dampers=[vi.Damper(mass=0.05, at=0, clearance=0.005, law="rigid", restitution=0.6)],
    excitations=[vi.Force(at=0, signal=vi.Harmonic(amplitude=5.0, frequency=10.0))],
    solver=vi.Solver(method="exact", t_end=0.2),
)


def with_study(settings: object) -> vi.System:
    return dataclasses.replace(SYSTEM, analyses={"study": settings})


def test_axes_given_as_arrays_are_checked_as_lists_are(tmp_path: Path) -> None:
    axis = np.linspace(0.004, 0.006, 3)
    # Without the other keys: their defaults (it raised KeyError: 'metrics').
    study = st.study_of(with_study({"axes": {"damper.0.clearance": axis}}))
    assert study.settings["metrics"] == ["peak", "rms", "impacts"]
    listed = st.study_of(with_study({"axes": {"damper.0.clearance": list(axis)}}))
    out = st.chunk_part(study, 0, 3, threads=1)
    assert np.array_equal(out["peak"], st.chunk_part(listed, 0, 3, threads=1)["peak"])
    for settings, words in (
        ({"chunk_size": 0}, r"^\[study\] chunk_size: must be a whole number in \[1, 2\^63 - 1\]"),
        ({"metrics": ["bogus"]}, r'^\[study\] metrics must be one of .*, got "bogus"'),
    ):
        with pytest.raises(ValueError, match=words):
            st.study_of(with_study({"axes": {"damper.0.clearance": axis}, **settings}))
    with pytest.raises(st.StudyError, match=r"'damper.0.clearance': must be a list of numbers"):
        st.study_of(with_study({"axes": {"damper.0.clearance": np.array([])}}))


@pytest.mark.parametrize("settings", [None, 5, "study"])
def test_a_study_that_is_not_a_table_says_so(settings: object) -> None:
    with pytest.raises(st.StudyError, match=r"^\[study\]: must be a table"):
        st.study_of(with_study(settings))


def test_an_index_with_a_leading_zero_is_refused(tmp_path: Path) -> None:
    # "damper.00.clearance" beside "damper.0.clearance" was a second axis of the same
    # parameter: the runs took its value, and the first axis's coordinates were wrong.
    text = FORCED_DAMPER + (
        '[study]\n[study.axes]\n"damper.0.clearance" = [0.002, 0.011]\n'
        '"damper.00.clearance" = [0.005]\n'
    )
    with pytest.raises(ValueError, match=r"'00': an index is a whole number from 0, without"):
        load_study(tmp_path / "study.toml", text)
    random = FORCED_DAMPER + (
        '[study]\nsamples = 2\n[study.axes]\n"damper.0.mass" = [0.05, 0.06]\n'
        '[study.random]\n"damper.00.mass" = { uniform = [0.01, 0.02] }\n'
    )
    with pytest.raises(ValueError, match=r"'00': an index is a whole number"):
        load_study(tmp_path / "random.toml", random)


@pytest.mark.parametrize("record_from", [0.5, 1.0])
def test_a_window_from_the_end_of_the_run_on_is_refused(tmp_path: Path, record_from: float) -> None:
    # Each run recorded nothing and was reported done: peak 0 (events), NaN (fixed).
    def text(start: float) -> str:
        return FORCED_DAMPER + (
            f'[study]\nrecord_from = {start}\n[study.axes]\n"damper.0.clearance" = [0.005]\n'
        )

    with pytest.raises(
        st.StudyError, match=r"\[study\] record_from: must be before \[solver\] t_end \(0.5 s\)"
    ):
        load_study(tmp_path / "study.toml", text(record_from))
    # Just before the end, a window of one instant, is a study.
    load_study(tmp_path / "ok.toml", text(0.49))


# Sixty chunks of one short run each, and SIGINT part way: the chunks' watcher checks
# for signals every 20 ms, and a signal it saw after the chunk's run had ended was lost
# (the study went on to its end, and wrote over an earlier output).
RACE = textwrap.dedent(
    """
    import dataclasses, os, signal, sys, threading, time
    import vibroimpact as vi
    sys.path.insert(0, {tests!r})
    from test_study_inputs import with_study
    study = vi.study_of(with_study(
        {{"chunk_size": 1, "axes": {{"damper.0.clearance": [0.005] * 60}}}}
    ))
    vi.study.chunk_part(study, 0, 1, threads=1)
    start = time.perf_counter()
    vi.study.chunk_part(study, 0, 1, threads=1)
    each = time.perf_counter() - start
    delay = {fraction} * 60 * each
    threading.Timer(delay, lambda: os.kill(os.getpid(), signal.SIGINT)).start()
    # Chunks run on until well after the signal (not a count of them, which a loaded
    # machine's slower chunks can outlast): a signal that was lost ends the loop here.
    until = time.perf_counter() + delay + 3.0
    try:
        while time.perf_counter() < until:
            for i in range(60):
                vi.study.chunk_part(study, i, i + 1, threads=1)
        print("the chunks ran on, 3 s past the signal")
    except KeyboardInterrupt:
        print("interrupted")
    """
)


@pytest.mark.timeout(120)
@pytest.mark.skipif(sys.platform == "win32", reason="SIGINT semantics")
@pytest.mark.parametrize("fraction", [0.2, 0.4, 0.6])
def test_ctrl_c_between_a_chunks_last_step_and_its_end_stops_the_study(fraction: float) -> None:
    script = RACE.format(tests=str(Path(__file__).parent), fraction=fraction)
    done = subprocess.run(
        [sys.executable, "-c", script],
        capture_output=True,
        text=True,
        timeout=100,
        preexec_fn=shell_signals,
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "interrupted"


def test_a_study_whose_results_would_not_fit_in_memory_is_refused(tmp_path: Path) -> None:
    # 9 million runs, each following 1,000 points: about 290 GB of results. The count of
    # runs was the only bound, and such a study started, holding 24 GB within minutes.
    from test_study_beam_axes import BEAM, RECTANGLE

    points = ", ".join(f"{0.5 * i / 999:.6f}" for i in range(1000))
    text = (
        BEAM.format(section=RECTANGLE)
        + f"points = [{points}]\n"
        + (
            '[study]\nmetrics = ["peak", "point_peak"]\n[study.axes]\n'
            '"damper.0.clearance" = { start = 1e-4, stop = 1e-3, count = 3000 }\n'
            '"excitation.0.frequency" = { start = 10.0, stop = 20.0, count = 3000 }\n'
        )
    )
    with pytest.raises(st.StudyError) as err:
        load_study(tmp_path / "big.toml", text)
    said = str(err.value)
    assert "the study's results would take about 291 GB of memory (9,000,000 runs" in said
    assert "1002 observed quantities and 1 pair(s)" in said and "split the study" in said
    # A tenth of the points in a ten-thousandth of the runs is a study.
    few = ", ".join(f"{0.5 * i / 99:.6f}" for i in range(100))
    small = text.replace(f"[{points}]", f"[{few}]").replace("count = 3000", "count = 30")
    assert load_study(tmp_path / "small.toml", small).runs == 900


def test_points_given_as_an_array_count_in_the_memory_bound(tmp_path: Path) -> None:
    # Sections built in Python may hold [output] points as a numpy array, which the
    # bound's count took for a truth value (numpy's 'ambiguous' error).
    from test_study_beam_axes import BEAM, RECTANGLE

    data = vi.load(write_text(tmp_path, BEAM.format(section=RECTANGLE))).to_dict()
    data["output"] = {"points": np.array([0.25, 0.5]), "record_from": 0.0}
    data["study"] = {"axes": {"damper.0.clearance": [4e-4, 5e-4]}, "metrics": ["point_peak"]}
    study = st.study_of(data)
    assert study.runs == 2
    assert st.chunk_part(study, 0, 2, threads=1)["peak"].shape == (2 * (2 + 2),)


def write_text(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "beam.toml"
    path.write_text(text)
    return path


def test_python_callers_are_told_their_own_argument_names(tmp_path: Path) -> None:
    # A Python call was told "--out x.csv: ...", a flag it has not got; a chunk past the
    # grid raised numpy's bare "index 5 is out of bounds", and NumPy scalars in an axis's
    # list were refused as not numbers.
    study = st.study_of(with_study({"axes": {"damper.0.clearance": [np.float32(0.005), 0.006]}}))
    single = float(np.float32(0.005))
    assert study.settings["axes"]["damper.0.clearance"].tolist() == [single, 0.006]
    with pytest.raises(ValueError, match=r"^out: \S*x\.csv: must end in \.nc"):
        st.run(study, tmp_path / "x.csv")
    with pytest.raises(ValueError, match=r"^stop: must be a whole number in \[0, 2\], got 9"):
        st.chunk_part(study, 5, 9)
    with pytest.raises(ValueError, match=r"^start: must be a whole number in \[0, 1\], got 2"):
        st.chunk_part(study, 2, 1)
    assert (
        st.chunk_part(study, 1, 2, threads=1)["peak"].shape
        == st.chunk_part(study, 0, 1, threads=1)["peak"].shape
    )


@pytest.mark.timeout(60)
def test_a_study_plans_on_the_memory_its_process_may_use(tmp_path: Path) -> None:
    # Under `ulimit -v` the plan read the machine's memory alone: a study that fitted it
    # but not the process's limit failed with a MemoryError traceback in the assembly.
    script = (
        "import resource\n"
        "resource.setrlimit(resource.RLIMIT_AS, (3 << 30, 3 << 30))\n"
        "from vibroimpact.study.limits import check_study_memory, machine_memory\n"
        "assert machine_memory() <= 3 << 30, machine_memory()\n"
        "try:\n"
        "    check_study_memory(9_000_000, 2, 2, '[study]')\n"
        "except ValueError as err:\n"
        "    print(err)\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, timeout=50, check=False
    )
    assert done.returncode == 0, done.stderr
    assert "the study's results would take about 3.17 GB" in done.stdout
    assert "more than half of the 3.22 GB this process may use" in done.stdout
