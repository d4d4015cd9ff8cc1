"""Figures of the founding paper, redrawn from our own runs (matplotlib, Agg)."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from vibroimpact._core import Contact, Solution, goldsmith_max_indentation  # noqa: E402
from vibroimpact.beyond import (  # noqa: E402
    CONTACT_DAMPING,
    HERTZ_STIFFNESS,
    StudyRun,  # noqa: E402
)
from vibroimpact.paper import PAPER_LINEAR_STIFFNESS, collision  # noqa: E402


def _contact_phase(sol: Solution, clearance: float = 0.01) -> dict[str, Any]:
    """Indentation, its rate and the law's force (without c1) through the first contact."""
    relative = sol.impact_displacement - sol.main_displacement
    rate = sol.impact_velocity - sol.main_velocity
    indentation = relative - clearance
    law_force = sol.contact_force - CONTACT_DAMPING * rate
    inside = indentation > 0
    return {
        "t": sol.t,
        "relative": relative,
        "indentation": np.where(inside, indentation, np.nan),
        "law_force": np.where(inside, law_force, np.nan),
    }


def _history(method: str, dt: float, restitution: float | None) -> Solution:
    return replace(collision(method, dt, "located", restitution), every=1).run()


def fig1(path: Path) -> None:
    """(a) Hertz force against indentation for several K_hz; (b) Hyster-Hertz loops."""
    fig, (a, b) = plt.subplots(1, 2, figsize=(10, 4))
    delta = np.linspace(0.0, 4e-3, 200)
    for k in (1000.0, 3000.0, 5000.0, 10000.0):
        law = Contact("hertz", stiffness=k)
        a.plot(delta * 1e3, [law.law_force(float(d)) for d in delta], label=f"K_hz = {k:g} N/m^1.5")
    a.set(xlabel="indentation (mm)", ylabel="contact force (N)", title="(a) Hertz")
    a.legend()
    for e in (1.0, 0.9, 0.7, 0.5):
        sol = _history("rk4", 1e-5, None if e == 1.0 else e)
        p = _contact_phase(sol)
        b.plot(p["indentation"] * 1e3, p["law_force"], label=f"e = {e:g}")
    b.set(
        xlabel="indentation (mm)",
        ylabel="law force (N)",
        title="(b) Hyster-Hertz, Table 1 collision (RK4)",
    )
    b.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def fig3(path: Path, equal_duration_stiffness: float) -> None:
    """Hertz force against the paper's linear approximation and an equal-duration one."""
    fig, ax = plt.subplots(figsize=(6, 4))
    dmax = goldsmith_max_indentation(0.25, 1.0, HERTZ_STIFFNESS, 0.1)
    delta = np.linspace(0.0, 1.1 * dmax, 200)
    ax.plot(delta * 1e3, HERTZ_STIFFNESS * delta**1.5, label="Hertz, K_hz = 3000 N/m^1.5")
    ax.plot(
        delta * 1e3,
        PAPER_LINEAR_STIFFNESS * delta,
        "--",
        label=f"paper's linear, k1 = {PAPER_LINEAR_STIFFNESS} N/m",
    )
    ax.plot(
        delta * 1e3,
        equal_duration_stiffness * delta,
        ":",
        label=f"equal-duration linear, k1 = {equal_duration_stiffness:.1f} N/m",
    )
    ax.axvline(dmax * 1e3, color="grey", lw=0.8)
    ax.set(
        xlabel="indentation (mm)",
        ylabel="contact force (N)",
        title="Hertz contact and its linear approximations",
    )
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def fig4(path: Path) -> None:
    """Relative displacement y - w through one contact, elastic and e = 0.9."""
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for e, colour in ((None, "C0"), (0.9, "C3")):
        label = "elastic" if e is None else f"e = {e}"
        ref = _contact_phase(_history("rk4", 1e-5, e))
        ax.plot(
            ref["t"], ref["relative"] * 1e3, color=colour, label=f"{label}: reference (RK4, 1e-5 s)"
        )
        coarse = _contact_phase(_history("newmark", 1e-3, e))
        ax.plot(
            coarse["t"][::4],
            coarse["relative"][::4] * 1e3,
            "o",
            ms=3,
            color=colour,
            mfc="none",
            label=f"{label}: paper's Newmark, 1e-3 s",
        )
    ax.axhline(10.0, color="grey", lw=0.8)
    ax.set(
        xlabel="time (s)",
        ylabel="y - w (mm)",
        title="Relative displacement through one contact (clearance 10 mm)",
    )
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def work_precision(path: Path, study: list[StudyRun], scipy_study: list[StudyRun]) -> None:
    """Error of the contact duration against CPU time, a line per method (log-log)."""
    fig, ax = plt.subplots(figsize=(8, 5.5))
    labels = list(dict.fromkeys(r.label for r in study + scipy_study))
    floor = 1e-16  # an exact hit would have no logarithm
    for i, label in enumerate(labels):
        runs = sorted(
            (r for r in study + scipy_study if r.label == label), key=lambda r: r.cpu_time
        )
        style = "--" if label.startswith("scipy") else "-"
        ax.loglog(
            [r.cpu_time for r in runs],
            [max(r.error, floor) for r in runs],
            style,
            marker="o",
            ms=3,
            color=f"C{i % 10}",
            label=label,
        )
    ax.set(
        xlabel="CPU time per collision (s, median)",
        ylabel="relative error of the contact duration",
        title="Table 1 collision: work against precision",
    )
    ax.grid(True, which="major", alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
