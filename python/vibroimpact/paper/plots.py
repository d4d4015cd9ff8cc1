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
from vibroimpact.output import written_whole  # noqa: E402
from vibroimpact.paper.beyond import (  # noqa: E402
    APPROACH_SPEED,
    CONTACT_DAMPING,
    HERTZ_STIFFNESS,
    StudyRun,  # noqa: E402
)
from vibroimpact.paper.data import PAPER_LINEAR_STIFFNESS, collision  # noqa: E402


def _save(fig: Any, path: Path) -> None:
    """Write the figure as PNG, whole or not at all, and free it."""
    try:
        fig.tight_layout()
        with written_whole(path, binary=True) as f:
            fig.savefig(f, format="png", dpi=110)
    finally:
        plt.close(fig)


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
        (line,) = b.plot(p["indentation"] * 1e3, p["law_force"], label=f"e = {e:g}")
        loading, unloading = _loop_arrows(b, p["indentation"] * 1e3, p["law_force"], line)
    # Name the branches once, on the widest loop (the last drawn, e = 0.5).
    b.annotate("loading", xy=loading, xytext=(0.7, 0.33), arrowprops={"arrowstyle": "-"})
    b.annotate("unloading", xy=unloading, xytext=(2.7, 0.07), arrowprops={"arrowstyle": "-"})
    b.set(
        xlabel="indentation (mm)",
        ylabel="law force (N)",
        title="(b) Hyster-Hertz, Table 1 collision (RK4)",
    )
    b.legend(title="arrows: direction of travel", title_fontsize=8, loc="upper left")
    _save(fig, path)


def _loop_arrows(
    ax: Any, indentation: Any, force: Any, line: Any
) -> tuple[tuple[float, float], tuple[float, float]]:
    """Arrowheads along a loop's loading and unloading branches; the two points marked."""
    inside = np.flatnonzero(np.isfinite(indentation))
    deepest = inside[np.argmax(indentation[inside])]
    marked = []
    for branch in (inside[inside <= deepest], inside[inside >= deepest]):
        # Where the branch passes 60 % of the deepest indentation, pointing the way it runs.
        i = branch[np.argmin(np.abs(indentation[branch] - 0.6 * indentation[deepest]))]
        j = min(i + len(branch) // 50, branch[-1])
        ax.annotate(
            "",
            xy=(indentation[j], force[j]),
            xytext=(indentation[i], force[i]),
            arrowprops={"arrowstyle": "-|>", "color": line.get_color(), "mutation_scale": 14},
        )
        marked.append((float(indentation[i]), float(force[i])))
    return marked[0], marked[1]


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
    ax.axvline(
        dmax * 1e3,
        color="grey",
        lw=0.8,
        label=f"Goldsmith's maximum indentation, {dmax * 1e3:.2f} mm (v = 0.1 m/s)",
    )
    ax.set(
        xlabel="indentation (mm)",
        ylabel="contact force (N)",
        title="Hertz contact and its linear approximations",
    )
    ax.legend()
    _save(fig, path)


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
            label=f"{label}: paper's Newmark, 1e-3 s (every 4th step shown)",
        )
    ax.axhline(10.0, color="grey", lw=0.8, label="clearance: in contact above it")
    ax.set(
        xlabel="time (s)",
        ylabel="y - w (mm)",
        title="Relative displacement through one contact (clearance 10 mm)",
    )
    ax.legend(fontsize=8)
    _save(fig, path)


def _varies(runs: list[StudyRun]) -> str:
    """The setting that varies along a line of runs and its range, e.g. ``dt = 4e-3 to 1e-4 s``."""

    def short(x: float) -> str:
        return f"{x:.0e}".replace("e-0", "e-")

    steps = [r.dt for r in runs if r.dt is not None]
    if steps:
        return f"dt = {short(max(steps))} to {short(min(steps))} s"
    tolerances = [r.rtol for r in runs if r.rtol is not None]
    return f"rtol = {short(max(tolerances))} to {short(min(tolerances))}"


#: The lines' styles where the colour alone would not tell them apart:
#: newmark-implicit and generalized-alpha (spectral radius 0.9) err alike to a few
#: per cent, and one had hidden the other. The rest take a marker each, in turn.
_WORK_PRECISION_STYLES: dict[str, dict[str, Any]] = {
    "generalized-alpha": {"ls": "--", "lw": 3.0, "marker": "o", "ms": 7, "mfc": "none"},
    "newmark-implicit": {"ls": "-", "lw": 1.0, "marker": "x", "ms": 5, "zorder": 3},
}
_MARKERS = "os^vD<>ph*P"
#: Why RK4 with the paper's stepping is first order (measured: its error halves with dt
#: below 1e-3 s, and with the contact damper c1 = 0 it converges as RK4 with events).
_RK4_FIXED = "rk4 (paper stepping)"


def _rk4_fixed_note() -> str:
    jump = CONTACT_DAMPING * APPROACH_SPEED
    return (
        f"{_RK4_FIXED}: level near 1e-6, then\n"
        "falling only as dt (order 1). Its fixed\n"
        "steps straddle the contact's onset, where\n"
        "the contact damper's force c1 v jumps\n"
        f"from 0 to {jump:.0e} N: RK4's stages\n"
        "integrate a jump to O(dt), and where in\n"
        "its step the onset falls sets the error\n"
        "at the largest steps. rk4 (events) cuts\n"
        "the step there and keeps its order."
    ).replace("e-0", "e-")


def work_precision(path: Path, study: list[StudyRun], scipy_study: list[StudyRun]) -> None:
    """Error of the contact duration against CPU time, a line per method (log-log),
    through its runs from the largest step or tolerance to the smallest; lines that
    would coincide drawn apart, and why RK4 with the paper's stepping is first order
    said on the figure."""
    fig, ax = plt.subplots(figsize=(8, 7))
    labels = list(dict.fromkeys(r.label for r in study + scipy_study))
    floor = 1e-16  # an exact hit would have no logarithm
    for i, label in enumerate(labels):
        runs = sorted(
            (r for r in study + scipy_study if r.label == label),
            key=lambda r: -(r.dt if r.dt is not None else r.rtol or 0.0),
        )
        style = {
            "ls": "--" if label.startswith("scipy") else "-",
            "marker": _MARKERS[i % len(_MARKERS)],
            "ms": 4,
            **_WORK_PRECISION_STYLES.get(label, {}),
        }
        errors = [max(r.error, floor) for r in runs]
        name = f"{label}: {_varies(runs)}" + (", order 1 (see note)" if label == _RK4_FIXED else "")
        ax.loglog([r.cpu_time for r in runs], errors, color=f"C{i % 10}", label=name, **style)
        if label == _RK4_FIXED and runs:
            ax.annotate(
                _rk4_fixed_note(),
                xy=(runs[-1].cpu_time, errors[-1]),
                # Bottom middle: right of the adaptive methods' lines, left of scipy's.
                xytext=(0.74, 0.03),
                textcoords="axes fraction",
                ha="right",
                va="bottom",
                multialignment="left",
                fontsize=7,
                color=f"C{i % 10}",
                bbox={"boxstyle": "round", "fc": "white", "ec": f"C{i % 10}", "alpha": 0.9},
                arrowprops={"arrowstyle": "->", "color": f"C{i % 10}", "lw": 0.8},
            )
    ax.set(
        xlabel="CPU time per collision (s, median)",
        ylabel="relative error of the contact duration",
        title="Table 1 collision: work against precision",
    )
    ax.grid(True, which="major", alpha=0.3)
    ax.legend(
        fontsize=7,
        ncol=2,
        title="method: its step dt or tolerance rtol along the line, from largest to smallest",
        title_fontsize=7,
        loc="upper center",
        bbox_to_anchor=(0.5, -0.1),
    )
    _save(fig, path)
