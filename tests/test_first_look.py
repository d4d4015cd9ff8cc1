"""What a new user sees first (issue 23): the repr of every result the public API
returns, the Poincare and frequency-response plots, and the bifurcation diagram's
impact samples against Holmes's closed form."""

from __future__ import annotations

import json
import tomllib
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import vibroimpact as vi
from vibroimpact import analysis
from vibroimpact.analysis import continuation, maps
from vibroimpact.analysis import plots as analysis_plots
from vibroimpact.paper import beyond, plots
from vibroimpact.scenario.two_mass import load_scenario

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
#: A repr longer than this is no summary.
SHORT = 600


def _sections(name: str) -> dict[str, Any]:
    with open(EXAMPLES / name, "rb") as f:
        return tomllib.load(f)


# ---------------------------------------------------------------------- repr


def test_a_system_runs_repr_is_a_short_summary() -> None:
    # 300+ contacts of two dampers, 1872 rows: printed whole it had been tens of kB.
    sol = load_scenario(EXAMPLES / "beam_two_dampers.toml").run()
    text = repr(sol)
    assert len(text) < SHORT, text
    assert "\n" not in text
    for said in (
        "cantilever",
        "method='dopri5'",
        f"steps={sol.steps}",
        f"contacts={len(sol.contacts)}",
        f"rows={len(sol.t)}",
        "t_end=1 s",
        "structure_displacement",
        "energy",
        "damper 0, damper 1",
    ):
        assert said in text, said
    assert text.count("damper 0") == 1
    contacts = repr(sol.contacts)
    assert len(contacts) < SHORT and f"{len(sol.contacts)} contacts" in contacts
    assert "approach_speed" in contacts and contacts.count("damper 0") == 1


def test_a_two_body_runs_repr_gives_the_time_reached_and_fields(
    table1_system: vi.ImpactDamper, hertz_contact: vi.Contact, onset_state: vi.InitialState
) -> None:
    sol = vi.simulate(table1_system, hertz_contact, onset_state, method="rk4", dt=1e-4, t_end=0.2)
    text = repr(sol)
    assert len(text) < SHORT, text
    for said in ('method="rk4"', "t_end=0.2 s", f"steps={sol.steps}", "rows=", "main_velocity"):
        assert said in text, said


def test_every_analysis_result_has_a_short_repr() -> None:
    data = _sections("ball_table_bifurcation.toml")
    run = analysis.runner(data)
    results: list[Any] = [
        analysis.steady_state(run, settle_periods=20, record_periods=5),
        analysis.orbit(run, run.initial_state()),
        *analysis.sweep(data, "excitation.0.amplitude", [12.0], settle_periods=20),
        # 500 periods of strobe rows and impacts: thousands of numbers.
        maps.poincare(run, settle_periods=10, periods=500),
        *maps.bifurcation(data, "excitation.0.amplitude", [12.0], sample_periods=400),
        maps.basins(
            run, (0, np.linspace(0.0, 0.03, 12)), (1, np.linspace(-0.4, 0.4, 12)), settle_periods=20
        ),
        continuation.continue_orbit(data, "excitation.0.amplitude", stop=13.0, step=0.1),
    ]
    for result in results:
        text = repr(result)
        assert len(text) < SHORT, (type(result).__name__, len(text), text[:200])
        assert text.startswith(type(result).__name__ + "(")
    branch = results[-1]
    assert f"<{len(branch.points)} items>" in repr(branch)
    assert len(repr(branch.points[0])) < SHORT


# ------------------------------------------------------------------- plots


@pytest.fixture
def figures(monkeypatch: pytest.MonkeyPatch) -> dict[str, Any]:
    """Figures drawn by analysis_plots, kept (and drawn) instead of written."""
    kept: dict[str, Any] = {}

    def keep(fig: Any, path: Path) -> None:
        fig.canvas.draw()
        kept[path.name] = fig

    monkeypatch.setattr(analysis_plots, "_save", keep)
    return kept


def test_the_poincare_plot_of_a_period_one_orbit_shows_a_point_not_round_off(
    figures: dict[str, Any],
) -> None:
    # Holmes's period-one orbit of the ball on the table: every strobe and impact the
    # same to 1e-13, which the axes had spread over their whole width.
    run = analysis.runner(_sections("bouncing_ball_table.toml"))
    section = maps.poincare(run, settle_periods=200, periods=200)
    assert np.ptp(section.strobe[:, 0]) < 1e-10
    analysis_plots.plot_section(Path("section.png"), section, run.period)
    left, right = figures["section.png"].axes
    height = float(np.max(section.strobe[:, 0]))
    for axis, value in (
        (left.xaxis, section.strobe[0, 0]),
        (left.yaxis, section.strobe[0, 1]),
        (right.yaxis, section.impact_speed[0]),
    ):
        low, high = axis.get_view_interval()
        # A range on the scale of the motion (the orbit is 16 mm high, 0.65 m/s at
        # impact), with the point inside it, and no offset text.
        assert low < value < high
        assert high - low > 0.01 * max(abs(value), height)
        assert axis.get_offset_text().get_text() == ""
        for label in axis.get_ticklabels():
            assert "e-" not in label.get_text() and "+" not in label.get_text()


def _overlaps(box: Any, x: float, y: float) -> bool:
    return bool(box.x0 <= x <= box.x1 and box.y0 <= y <= box.y1)


def test_the_frf_plot_marks_unsettled_points_with_their_spread_and_keeps_the_legend_off_the_peaks(
    figures: dict[str, Any],
) -> None:
    data = _sections("frf_impact_damper.toml")
    points = analysis.sweep(
        data, "excitation.0.frequency", np.linspace(7.0, 13.0, 61), direction="both"
    )
    unsettled = [p for p in points if not p.settled]
    assert len(unsettled) >= 5  # around the resonance, impacts never settle
    analysis_plots.plot_sweep(Path("frf.png"), "excitation.0.frequency", points, data)
    fig = figures["frf.png"]
    (ax,) = fig.axes
    marked = [line for line in ax.lines if "not settled" in line.get_label()]
    assert len(marked) == 1
    np.testing.assert_array_equal(marked[0].get_xdata(), [p.value for p in unsettled])
    (spread,) = [c for c in ax.collections if "spread" in c.get_label()]
    segments = spread.get_segments()
    assert len(segments) == len(unsettled)
    for segment, p in zip(segments, unsettled, strict=True):
        (x0, y0), (x1, y1) = segment
        assert x0 == x1 == p.value
        assert (y0, y1) == (p.least_period_peak[0], p.amplitude[0])
        assert y0 <= y1
    # Neither the linear peak nor the swept one under the legend.
    legend = ax.get_legend().get_window_extent()
    linear = max(points, key=lambda p: p.linear_amplitude[0])
    swept = max(points, key=lambda p: p.amplitude[0])
    for x, y in ((linear.value, linear.linear_amplitude[0]), (swept.value, swept.amplitude[0])):
        assert not _overlaps(legend, *ax.transData.transform((x, y)))


def test_the_spread_of_an_unsettled_response_is_its_periods_smallest_and_largest_peak() -> None:
    # The ball on the table at Gamma 1.8: no period of at most 8. Independent values:
    # each period's highest row of a dense history (200 rows a period) of the same run.
    data = _sections("ball_table_bifurcation.toml")
    data["excitation"][0]["amplitude"] = 18.0
    run = analysis.runner(data)
    start = run.map(run.initial_state(), 200)
    result = analysis.steady_state(run, start, settle_periods=0, record_periods=30)
    assert not result.settled
    history = analysis_plots.orbit_history(run, start, 30)
    t, x = history.t, history.structure_displacement[:, 0]
    heights = [np.max(x[(t >= i * run.period) & (t <= (i + 1) * run.period)]) for i in range(30)]
    assert result.amplitude[0] == pytest.approx(max(heights), rel=1e-3)
    assert result.least_period_peak[0] == pytest.approx(min(heights), rel=1e-3)
    assert min(heights) < 0.5 * max(heights)  # a real spread, not round-off


# ----------------------------------------------------- bifurcation samples


def _holmes(data: dict[str, Any], big_a: float) -> tuple[float, float]:
    """Holmes's period-one orbit of the ball on the table (forced-oracles.md): the
    impact phase on the scenario's clock and the closing speed (m/s). The scenario's
    base acceleration is ``A cos(w t + p)``: the table's displacement is ``a sin(w (t +
    tm))`` with ``w tm = p - pi / 2``, so Holmes's phase ``phi`` is ``phi - w tm`` here."""
    (stop,) = data["stop"]
    (forcing,) = data["excitation"]
    e, g = stop["restitution"], data["gravity"]["acceleration"]
    w = 2 * np.pi * forcing["frequency"]
    gamma = big_a / g
    phi = float(np.arccos(np.pi * (1 - e) / ((1 + e) * gamma)))  # the branch sin > 0
    phase = (phi - (forcing["phase"] - np.pi / 2)) % (2 * np.pi)
    return phase, 2 * np.pi * g / (w * (1 + e))


def test_bifurcation_samples_impact_velocity_and_phase_of_holmes_orbit() -> None:
    data = _sections("ball_table_bifurcation.toml")
    values = [11.772, 12.5, 13.5, 14.5]  # Gamma 1.2 to 1.48, below the flip at 1.5268
    for sample in ("impact-velocity", "impact-phase"):
        points = maps.bifurcation(
            data,
            "excitation.0.amplitude",
            values,
            settle_periods=300,
            sample_periods=20,
            sample=sample,
            pair="stop 0",
        )
        for p in points:
            phase, closing = _holmes(data, p.value)
            assert p.error is None and len(p.samples) == 20  # one impact a period
            if sample == "impact-velocity":
                np.testing.assert_allclose(p.samples, closing, rtol=1e-7)
            else:
                gap = np.angle(np.exp(1j * (p.samples - phase)))
                assert np.max(np.abs(gap)) < 1e-7, (p.value, p.samples[:3], phase)
                assert np.all((p.samples >= 0) & (p.samples < 2 * np.pi))


def test_bifurcation_sample_and_pair_are_checked() -> None:
    data = _sections("ball_table_bifurcation.toml")
    with pytest.raises(vi.InvalidInputError, match="^sample: must be one of"):
        maps.bifurcation(data, "excitation.0.amplitude", [12.0], sample="speed")
    with pytest.raises(vi.InvalidInputError, match=r"^pair: .*\(stop 0\), got 'stop 3'"):
        maps.bifurcation(
            data, "excitation.0.amplitude", [12.0], sample="impact-phase", pair="stop 3"
        )
    data["sweep"]["sample"] = "velocity"
    with pytest.raises(vi.InvalidInputError, match=r"\[sweep\] sample"):
        analysis.sweep_settings(data["sweep"])


def test_the_bifurcation_command_samples_impacts_with_units(run_cli: Any, tmp_path: Path) -> None:
    scenario = (EXAMPLES / "ball_table_bifurcation.toml").read_text(encoding="utf-8")
    scenario = scenario.replace("count = 50", "count = 3").replace(
        "record_periods = 32", 'record_periods = 10\nsample = "impact-phase"'
    )
    path = tmp_path / "phase.toml"
    path.write_text(scenario, encoding="utf-8")
    plot = tmp_path / "phase.png"
    done = run_cli("bifurcation", str(path), "--json", "--plot", str(plot))
    assert done.returncode == 0, done.stderr
    out = json.loads(done.stdout)
    assert (out["sample"], out["sample_units"], out["pair"]) == ("impact-phase", "rad", None)
    data = _sections("ball_table_bifurcation.toml")
    phase, closing = _holmes(data, out["points"][0]["value"])
    assert (
        np.abs(np.angle(np.exp(1j * (np.array(out["points"][0]["samples"]) - phase)))).max() < 1e-7
    )
    # --sample overrides the section's, and the text names what it counted.
    done = run_cli("bifurcation", str(path), "--sample", "impact-velocity", "--json")
    first = json.loads(done.stdout)["points"][0]["samples"]
    np.testing.assert_allclose(first, closing, rtol=1e-7)
    done = run_cli("bifurcation", str(path), "--pair", "damper 0")
    assert done.returncode == 2 and "--pair: must name one of" in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1


# ------------------------------------------------------------ work precision


def _study_run(label: str, dt: float, error: float, cpu: float) -> beyond.StudyRun:
    return beyond.StudyRun(label, f"dt={dt:g}", dt, None, 0.109, error, cpu, 0)


def test_work_precision_draws_coinciding_lines_apart_and_says_why_rk4_fixed_is_order_one(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    kept: dict[str, Any] = {}
    monkeypatch.setattr(plots, "_save", lambda fig, path: kept.__setitem__(path.name, fig))
    steps = (4e-3, 1e-3, 1e-4)
    # newmark-implicit and generalized-alpha err alike to a few per cent: one line.
    study = [_study_run("generalized-alpha", dt, 1e-3 * dt / 4e-3, 1e-5 / dt) for dt in steps]
    study += [_study_run("newmark-implicit", dt, 0.97e-3 * dt / 4e-3, 1e-5 / dt) for dt in steps]
    study += [_study_run("rk4 (paper stepping)", dt, 4e-4 * dt, 1e-8 / dt) for dt in steps]
    plots.work_precision(Path("wp.png"), study, [])
    (ax,) = kept["wp.png"].axes
    lines = {line.get_label().split(":")[0]: line for line in ax.lines}
    alpha, newmark = lines["generalized-alpha"], lines["newmark-implicit"]
    assert alpha.get_marker() != newmark.get_marker()
    assert alpha.get_linestyle() != newmark.get_linestyle()
    # The one drawn over the other is the thinner, and the one beneath shows round it.
    assert newmark.get_zorder() > alpha.get_zorder() and newmark.get_lw() < alpha.get_lw()
    assert alpha.get_markerfacecolor() == "none"
    # Why RK4 with the paper's stepping is first order, on the figure, pointing at it.
    rk4 = lines["rk4 (paper stepping)"]
    assert "order 1" in rk4.get_label()
    (note,) = [t for t in ax.texts if "rk4 (paper stepping)" in t.get_text()]
    text = " ".join(note.get_text().split())
    assert "order 1" in text and "jumps from 0 to 1e-3 N" in text and "onset" in text
    assert note.xy in list(zip(rk4.get_xdata(), rk4.get_ydata(), strict=True))


def test_rk4_with_the_papers_stepping_is_first_order_because_of_the_contact_dampers_jump() -> None:
    # What the note says, measured: with the contact damper (c1 v = 1e-3 N at onset) the
    # error halves with dt; without it (c1 = 0) it falls as RK4 with located events does.
    system, _, start = beyond.table1()
    ratios = {}
    for c1 in (beyond.CONTACT_DAMPING, 0.0):
        contact = vi.Contact(law="hertz", stiffness=beyond.HERTZ_STIFFNESS, damping=c1)
        exact = vi.simulate(
            system, contact, start, method="dop853", rtol=1e-13, atol=1e-16, t_end=0.15
        ).contacts.duration[0]
        errors = [
            abs(
                vi.simulate(
                    system, contact, start, method="rk4", dt=dt, stepping="fixed", t_end=0.11
                ).contacts.duration[0]
                / exact
                - 1
            )
            for dt in (2e-4, 1e-4)
        ]
        ratios[c1] = errors[0] / errors[1]
    assert ratios[beyond.CONTACT_DAMPING] == pytest.approx(2.0, rel=0.05)
    assert ratios[0.0] > 5.0
