"""``vibroimpact paper``: reproduce the founding paper's tables and figures.

A. Afsharfard, A. Farshidianfar, "An efficient method to solve the strongly
coupled nonlinear differential equations of impact dampers", Arch. Appl. Mech.
82 (2012) 977-984. Writes tables 2 and 3 (CSV), the figures (PNG) and
``report.md``, which lists every file written, and prints the tables. Each
file is written whole or not at all.
"""

from __future__ import annotations

import csv
import math
import os
import platform
import shutil
import tempfile
import time
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import vibroimpact.paper.beyond as beyond
from vibroimpact._core import (
    Contact,
    ImpactDamper,
    InitialState,
    RestitutionWarning,
    Solution,
    adequacy,
    cantilever_mode,
    goldsmith_contact_duration,
    goldsmith_max_indentation,
    linear_contact_duration,
    simulate,
)
from vibroimpact.output import UsageError, written_whole
from vibroimpact.paper.beyond import (
    APPROACH_SPEED,
    CLEARANCE,
    CONTACT_DAMPING,
    HERTZ_STIFFNESS,
    IMPACT_MASS,
    MAIN_MASS,
    first_duration,
    median_time,
)
from vibroimpact.paper.data import (
    PAPER_LINEAR_STIFFNESS,
    RUN_TIME,
    STEP_SIZES,
    WEIGHTS,
    collision,
)
from vibroimpact.paper.report import write_report

# Rows of table 3: method, dt (None for adaptive runs), adequacy per WF1.
Block = list[tuple[str, float | None, list[float]]]


@dataclass(frozen=True)
class Row:
    """One row of table 2. ``dt`` and ``cpu_time`` are None for closed forms."""

    method: str
    dt: float | None
    contact_duration: float
    cpu_time: float | None
    error_percent: float
    error_vs_exact_percent: float


def rebound_over_approach(sol: Solution) -> float:
    return float(sol.contacts.restitution[0])


def exact_duration(restitution: float | None = None) -> float:
    """The model's own contact duration (DOP853 at rtol 1e-13, events located)."""
    return beyond.exact_duration(restitution)


def exact_duration_rk4() -> float:
    """The same by RK4 at dt = 1e-5 s with events: a second, independent method."""
    system, contact, start = beyond.table1()
    sol = simulate(system, contact, start, method="rk4", stepping="events", dt=1e-5, t_end=RUN_TIME)
    return first_duration(sol)


def pct(value: float, reference: float) -> float:
    return abs(value / reference - 1.0) * 100.0


def equal_duration_stiffness(duration: float) -> float:
    """The linear stiffness k1 (N/m) whose damped contact lasts ``duration`` (s)."""
    m, big, c1 = IMPACT_MASS, MAIN_MASS, CONTACT_DAMPING
    root = 2.0 * math.pi * m * big / (duration * math.sqrt(m + big))
    return (root * root + c1 * c1 * (m + big)) / (4.0 * m * big)


def hyster_hertz(restitution: float) -> Contact:
    """The paper's law, without the warning that its rebound is not ``e``:
    showing that is the point here."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RestitutionWarning)
        return Contact("hyster-hertz", stiffness=HERTZ_STIFFNESS, restitution=restitution)


def rebound_ratio_exact(restitution: float) -> float:
    """e* from alpha (1 + e*) = ln((1 + alpha)/(1 - alpha e*)), alpha = 3/4 (1 - e^2)."""
    return hyster_hertz(restitution).effective_restitution


def rebound_ratio_simulated(restitution: float) -> float:
    """Rebound/approach speed of two free bodies under the Hyster-Hertz law."""
    system = ImpactDamper(
        main_mass=MAIN_MASS, stiffness=0.0, impact_mass=IMPACT_MASS, clearance=CLEARANCE
    )
    start = InitialState(impact_displacement=CLEARANCE, impact_velocity=APPROACH_SPEED)
    contact = hyster_hertz(restitution)
    sol = simulate(system, contact, start, method="rk4", dt=1e-5, t_end=0.3, every=1_000_000)
    return rebound_over_approach(sol)


def table2(goldsmith: float, exact: float) -> list[Row]:
    linear = linear_contact_duration(
        IMPACT_MASS, MAIN_MASS, PAPER_LINEAR_STIFFNESS, CONTACT_DAMPING
    )
    rows = [
        Row("goldsmith (theoretical)", None, goldsmith, None, 0.0, pct(goldsmith, exact)),
        Row(
            f"linear model k1={PAPER_LINEAR_STIFFNESS}",
            None,
            linear,
            None,
            pct(linear, goldsmith),
            pct(linear, exact),
        ),
    ]
    for timing in ("step-count", "located"):
        for method in ("newmark", "rk4"):
            for dt in STEP_SIZES:
                scenario = collision(method, dt, timing)
                sol, cpu = median_time(scenario.run, min_repeats=7, budget=0.05)
                tc = first_duration(sol)
                rows.append(
                    Row(f"{method} ({timing})", dt, tc, cpu, pct(tc, goldsmith), pct(tc, exact))
                )
    return rows


def table3(rows: list[Row], basis: str) -> list[tuple[str, float | None, list[float]]]:
    """Eq. 15 over the numerical rows, with maxima taken over those rows."""
    numerical = [r for r in rows if r.cpu_time is not None]

    def err(r: Row) -> float:
        return r.error_vs_exact_percent if basis == "exact" else r.error_percent

    max_err = max(err(r) for r in numerical)
    max_cpu = max(r.cpu_time for r in numerical if r.cpu_time is not None)
    out = []
    for r in numerical:
        assert r.cpu_time is not None
        out.append(
            (r.method, r.dt, [adequacy(err(r), max_err, r.cpu_time, max_cpu, w) for w in WEIGHTS])
        )
    return out


def fmt(x: float | None, spec: str) -> str:
    return "" if x is None else format(x, spec)


def write_table2(path: Path, rows: list[Row]) -> None:
    with written_whole(path) as f:
        w = csv.writer(f)
        w.writerow(
            [
                "method",
                "dt",
                "contact_duration",
                "cpu_time",
                "error_percent",
                "error_vs_exact_percent",
            ]
        )
        for r in rows:
            w.writerow(
                [
                    r.method,
                    fmt(r.dt, "g"),
                    repr(r.contact_duration),
                    fmt(r.cpu_time, ".6e"),
                    f"{r.error_percent:.6f}",
                    f"{r.error_vs_exact_percent:.6f}",
                ]
            )


def write_table3(path: Path, blocks: dict[str, Block]) -> None:
    with written_whole(path) as f:
        w = csv.writer(f)
        w.writerow(["method", "dt", "error_basis"] + [f"wf1_{x:.1f}" for x in WEIGHTS])
        for basis, rows in blocks.items():
            for method, dt, values in rows:
                w.writerow([method, fmt(dt, "g"), basis] + [f"{v:.2f}" for v in values])


def print_tables(rows: list[Row], blocks: dict[str, Block]) -> None:
    print("Table 2: contact duration of the Table 1 collision (v = 0.1 m/s)")
    print(
        f"{'method':<28}{'dt (s)':>9}{'Tc (s)':>12}{'CPU (s)':>12}{'err %':>10}{'vs exact %':>12}"
    )
    for r in rows:
        print(
            f"{r.method:<28}{fmt(r.dt, 'g'):>9}{r.contact_duration:>12.7f}"
            f"{fmt(r.cpu_time, '.3e'):>12}{r.error_percent:>10.4f}{r.error_vs_exact_percent:>12.5f}"
        )
    for basis, block in blocks.items():
        print(
            f"\nTable 3: adequacy (%), errors against {basis}; columns WF1 = "
            + ", ".join(f"{x:.1f}" for x in WEIGHTS)
        )
        for method, dt, values in block:
            print(f"{method:<28}{fmt(dt, 'g'):>9}" + "".join(f"{v:>8.2f}" for v in values))


@dataclass(frozen=True)
class Findings:
    goldsmith: float
    goldsmith_exact_constant: float
    max_indentation: float
    exact: float
    exact_hyster: float
    hyster_rows: list[tuple[str, str, float]]
    restitution_rows: list[tuple[float, float, float]]
    linear: float
    equal_k1: float
    beam_modal: float
    beam_tip: float
    rebound_rows: list[tuple[str, float, float]]
    exact_rk4: float
    adequacy_all: Block
    study: list[beyond.StudyRun]
    scipy_study: list[beyond.StudyRun]


def findings(
    rows: list[Row],
    study: list[beyond.StudyRun],
    scipy_study: list[beyond.StudyRun],
    adequacy_all: Block,
) -> Findings:
    hyster = []
    for method in ("rk4", "newmark"):
        for timing in ("step-count", "located"):
            hyster.append(
                (method, timing, first_duration(collision(method, 1e-4, timing, 0.9).run()))
            )
    restitution = [
        (e, rebound_ratio_exact(e), rebound_ratio_simulated(e)) for e in (0.9, 0.7, 0.5, 0.01)
    ]
    goldsmith = rows[0].contact_duration
    beam = cantilever_mode(length=1.0, youngs_modulus=1.0, second_moment=1.0, density=1.0, area=1.0)
    return Findings(
        goldsmith=goldsmith,
        goldsmith_exact_constant=goldsmith_contact_duration(
            IMPACT_MASS, MAIN_MASS, HERTZ_STIFFNESS, APPROACH_SPEED, exact_constant=True
        ),
        max_indentation=goldsmith_max_indentation(
            IMPACT_MASS, MAIN_MASS, HERTZ_STIFFNESS, APPROACH_SPEED
        ),
        exact=exact_duration(),
        exact_hyster=exact_duration(0.9),
        hyster_rows=hyster,
        restitution_rows=restitution,
        linear=rows[1].contact_duration,
        equal_k1=equal_duration_stiffness(goldsmith),
        beam_modal=beam.modal_stiffness,
        beam_tip=beam.stiffness_at_position,
        rebound_rows=[
            (method, dt, rebound_over_approach(collision(method, dt, "located").run()))
            for method in ("newmark", "rk4")
            for dt in STEP_SIZES
        ],
        exact_rk4=exact_duration_rk4(),
        adequacy_all=adequacy_all,
        study=study,
        scipy_study=scipy_study,
    )


def run_paper(out: Path) -> int:
    """Compute everything, write the files into ``out`` and print the tables. The
    files are made in a folder of their own inside ``out`` and moved into it together
    at the end: an interrupted or failed run leaves the last run's set as it was (its
    report agreeing with its tables), not new tables beside an old report."""
    if out.exists() and not out.is_dir():
        raise UsageError(f"--out {out}: is a file; --out is the folder the results go into")
    try:
        out.mkdir(parents=True, exist_ok=True)
        staging = Path(tempfile.mkdtemp(prefix=".paper-", dir=out))
    except OSError as err:
        raise UsageError(f"cannot write to {str(out)!r}: {err.strerror or err}") from None
    try:
        written = _paper_files(staging)
        for name in written:
            os.replace(staging / name, out / name)
    except UsageError as err:
        # Named where the user asked for it, not in the folder of the making.
        raise UsageError(str(err).replace(str(staging), str(out))) from None
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    return 0


def _paper_files(out: Path) -> list[str]:
    """:func:`run_paper`'s work: every file written into ``out`` (their names, in
    order), the tables printed."""
    # Here, not at the top: matplotlib loads for this job only, not for every command.
    from vibroimpact.paper.plots import fig1, fig3, fig4, work_precision

    started = time.perf_counter()
    goldsmith = goldsmith_contact_duration(IMPACT_MASS, MAIN_MASS, HERTZ_STIFFNESS, APPROACH_SPEED)
    exact = exact_duration()
    rows = table2(goldsmith, exact)
    study = beyond.ours(exact)
    scipy_study = beyond.scipy_runs(exact)
    # The paper's two methods are in table 2 already; the study adds the others.
    all_rows = rows + [
        Row(
            f"{r.label} ({r.setting})" if r.rtol is not None else r.label,
            r.dt,
            r.contact_duration,
            r.cpu_time,
            pct(r.contact_duration, goldsmith),
            r.error * 100.0,
        )
        for r in study
        if "paper" not in r.label
    ]
    blocks = {
        "exact": table3(rows, "exact"),
        "goldsmith": table3(rows, "goldsmith"),
        "exact, all methods": table3(all_rows, "exact"),
    }
    # The names of the files written, in order, so that the report lists exactly them.
    written: list[str] = []

    def write(name: str, writer: Callable[[Path], None]) -> None:
        writer(out / name)
        written.append(name)

    write("table2.csv", lambda path: write_table2(path, all_rows))
    write("table3.csv", lambda path: write_table3(path, blocks))
    print_tables(all_rows, blocks)
    found = findings(rows, study, scipy_study, blocks["exact, all methods"])
    write("fig1.png", fig1)
    write("fig3.png", lambda path: fig3(path, found.equal_k1))
    write("fig4.png", fig4)
    write("work_precision.png", lambda path: work_precision(path, study, scipy_study))
    elapsed = time.perf_counter() - started
    write(
        "report.md",
        lambda path: write_report(
            path, rows, blocks, found, elapsed, platform.platform(), [*written, path.name]
        ),
    )
    print(f"\nwrote {', '.join(written)} to {out.parent}/ in {elapsed:.1f} s")
    missing = beyond.scipy_missing()
    if missing is not None:
        print(f"note: {missing}")
    return written
