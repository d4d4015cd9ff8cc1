"""A prepared system shared: given twice to one call, run from two threads at once
(an adversarial pass found both hung, Ctrl-C unheard), and a lockstep study of a damper
with friction (it ran the damper without its friction)."""

from __future__ import annotations

import threading
import tomllib

import numpy as np
import pytest

import vibroimpact as vi
from model_checks import ROOT
from vibroimpact import analysis as an
from vibroimpact import study as st


def _sections() -> dict[str, object]:
    with open(ROOT / "examples" / "frf_impact_damper.toml", "rb") as f:
        sections = tomllib.load(f)
    sections.pop("sweep")
    return sections


@pytest.mark.timeout(30)
def test_one_system_given_as_both_sides_of_a_parameter_is_the_two_systems_result() -> None:
    # The same prepared system as p + delta and p - delta (a zero derivative), and as
    # the run's own: each had locked one lock twice, a hang.
    run, other = an.runner(_sections()), an.runner(_sections())
    z = np.zeros(4)
    twice = run.tangent(z, 0.1, parameters=[(other, other, 1e-4)])
    apart = run.tangent(z, 0.1, parameters=[(other, an.runner(_sections()), 1e-4)])
    own = run.tangent(z, 0.1, parameters=[(run, run, 1e-4)])
    assert np.array_equal(twice["parameters"], apart["parameters"])
    assert np.array_equal(own["parameters"], apart["parameters"])
    assert np.all(np.asarray(apart["parameters"]) == 0.0)


@pytest.mark.timeout(60)
def test_two_threads_running_one_system_each_get_the_runs_result() -> None:
    # The second thread waited on the first's lock holding the GIL, which the first
    # needed to return: both hung.
    prepared = an.runner(_sections()).system()
    alone = prepared.run([0.0] * 4, 4000.0)
    results: list[dict[str, object]] = []

    def work() -> None:
        results.append(prepared.run([0.0] * 4, 4000.0))

    threads = [threading.Thread(target=work) for _ in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=40)
    assert len(results) == 2
    for r in results:
        assert np.array_equal(r["final_state"], alone["final_state"])


@pytest.mark.timeout(60)
@pytest.mark.parametrize("axis", ["initial.damper_velocity.0", "damper.0.friction"])
def test_a_lockstep_study_of_a_damper_with_friction_is_refused(axis: str) -> None:
    # The two-mass lanes ran it without its friction: the frictionless damper's
    # peaks and impacts (11 and 21 for the event-driven runs' 1 and 1).
    data = {
        "structure": {"kind": "oscillator", "mass": 1.0, "stiffness": 1.0, "damping": 0.01},
        "damper": [
            {
                "mass": 0.25,
                "at": 0,
                "clearance": 0.01,
                "law": "hertz-damped",
                "stiffness": 3000.0,
                "restitution": 0.9,
                "friction": 0.5,
                "normal_force": 2.0,
            }
        ],
        "initial": {"damper_displacement": [0.01]},
        "solver": {"method": "rk4", "dt": 1e-3, "t_end": 1.0},
        "study": {
            "analysis": "run",
            "stepping": "fixed",
            "metrics": ["peak", "impacts"],
            "axes": {axis: [0.1, 0.5]},
        },
    }
    with pytest.raises(ValueError, match="friction") as refused:
        st.study_of(data).run_chunk(range(2), threads=1)
    assert "stepping" in str(refused.value) and "\n" not in str(refused.value)
    # Without friction the same study runs.
    data["damper"][0] = {  # type: ignore[index]
        k: v
        for k, v in data["damper"][0].items()
        if k not in ("friction", "normal_force")  # type: ignore[index]
    }
    if axis == "initial.damper_velocity.0":
        points = st.study_of(data).run_chunk(range(2), threads=1)
        assert np.all(np.asarray(points["status"]) == 0)
    assert vi is not None
