"""Plots of the analyses (PNG, SI units on every axis), each written whole or not at
all: frequency response, time history with phase portrait and impact markers,
Poincare section, bifurcation diagram, basins of attraction and continued branches."""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

from vibroimpact._core import InvalidInputError
from vibroimpact.analysis.continuation import Branch
from vibroimpact.analysis.curves import Curve
from vibroimpact.analysis.lyapunov import Lyapunov
from vibroimpact.analysis.maps import Basins, BifurcationPoint, Section
from vibroimpact.analysis.parameters import with_parameter
from vibroimpact.analysis.runs import Runner
from vibroimpact.analysis.settings import BIFURCATION_SAMPLES
from vibroimpact.analysis.steady import linear_response
from vibroimpact.analysis.sweeps import (
    SweepPoint,
    shown_amplitudes,
    shown_derivative,
    shown_label,
    shown_values,
)
from vibroimpact.output import written_whole
from vibroimpact.system import SystemSolution, split_observed
from vibroimpact.units import derivative_units, parameter_units


@contextmanager
def _figure(
    path: Path,
    rows: int = 1,
    cols: int = 1,
    size: tuple[float, float] = (7, 4.5),
    mosaic: list[list[str]] | None = None,
) -> Iterator[Any]:
    """A figure of ``rows`` x ``cols`` axes (or of the named axes of ``mosaic``, a
    dict), written to ``path`` whole when the block ends."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    if mosaic is None:
        fig, axes = plt.subplots(rows, cols, figsize=size)
    else:
        fig, axes = plt.subplot_mosaic(mosaic, figsize=size)  # type: ignore[arg-type]  # stub: HashableList
    try:
        yield fig, axes
        fig.tight_layout()
        _save(fig, path)
    finally:
        plt.close(fig)


def _save(fig: Any, path: Path) -> None:
    with written_whole(path, binary=True) as f:
        fig.savefig(f, format="png", dpi=120)


#: The least half-width of an axis, relative to the size of the motion: points that
#: coincide to round-off (a periodic orbit's) are drawn as the points they are, not
#: spread over an axis of 1e-13 with an offset label.
_LEAST_HALF_SPAN = 0.05


def _span_at_least(ax: Any, axis: str, values: np.ndarray, size: float) -> None:
    """Widen ``axis`` ("x" or "y") of ``ax`` about the middle of ``values`` to at
    least ``_LEAST_HALF_SPAN * size`` either side, and show plain tick labels
    (no offset text)."""
    values = values[np.isfinite(values)]
    (ax.xaxis if axis == "x" else ax.yaxis).get_major_formatter().set_useOffset(False)
    if not values.size or not size > 0:
        return
    low, high = float(values.min()), float(values.max())
    half = _LEAST_HALF_SPAN * size
    if high - low < 2 * half:
        middle = 0.5 * (low + high)
        (ax.set_xlim if axis == "x" else ax.set_ylim)(middle - half, middle + half)


def _unit(parameter: str, data: Any = None) -> str:
    """`` (unit)`` of a scenario parameter for an axis label, as the datasets give it
    (resolved with the scenario's sections ``data`` where it depends on them: an
    amplitude is N for a force, m s-2 for a base acceleration); empty where unknown."""
    units = parameter_units(parameter, data)
    return f" ({units})" if units else ""


#: How many values of the parameter the linear curve of a sweep's plot is drawn at: its
#: closed form costs about 0.1 ms a value, and a resonance of damping ratio 0.01 is
#: 2 % of its frequency wide, missed between the sweep's own values (a 1 Hz grid showed
#: 0.065 m at 20 Hz for a linear peak of 0.126 m at 20.4 Hz).
LINEAR_CURVE_VALUES = 1000


def _linear_curve(
    parameter: str, points: list[SweepPoint], data: Any, shown: str
) -> tuple[np.ndarray, np.ndarray]:
    """The linear structure's amplitude of kind ``shown`` across the sweep's range, on a
    fine grid (with the sweep's own values) from the closed form; at the sweep's values
    only where the scenario's sections ``data`` are not given."""
    values = np.array([p.value for p in points])
    at_points = np.array([shown_values(p, shown)[1][0] for p in points])
    order = np.argsort(values, kind="stable")
    if data is None or not np.all(np.isfinite(values)):
        return values[order], at_points[order]
    grid = np.union1d(np.linspace(values.min(), values.max(), LINEAR_CURVE_VALUES), values)
    kind = {"coordinate": 0, "point": 1, "moment": 2}[shown]
    try:
        linear = [linear_response(with_parameter(data, parameter, float(v)))[kind][0] for v in grid]
    except InvalidInputError:
        # A value the closed form cannot take (the sweep marked its run failed).
        return values[order], at_points[order]
    return grid, np.array(linear)


def plot_sweep(
    path: Path,
    parameter: str,
    points: list[SweepPoint],
    data: Any = None,
    *,
    derivatives: list[str] | tuple[str, ...] = (),
) -> None:
    """Amplitude of structure coordinate 0 (of the structure at the first of
    ``[output] points``, or else of the first bending moment of ``[output] moments``,
    where there are: see :func:`shown_amplitudes`) against the parameter, each
    direction, with the linear structure's beside it. Points whose response did not
    settle (no period of at most 8 forcing periods: chaos, or a slow transient) are
    marked, with the spread of their periods' peaks (smallest to largest); points
    whose run failed are marked on the parameter axis. The legend sits beside the
    axes, off the curves. With ``derivatives`` (paths the sweep's points hold, see
    :attr:`SweepPoint.derivatives`), beside it one axes per path: the amplitude's
    derivative in it, against the same parameter axis."""
    if not derivatives:
        with _figure(path, size=(8, 5.5)) as (fig, ax):
            _frequency_response(ax, parameter, points, data)
        return
    mosaic = [["response", f"d {p}"] for p in derivatives]
    size = (14.0, max(5.5, 3.0 * len(derivatives)))
    with _figure(path, size=size, mosaic=mosaic) as (fig, axes):
        _frequency_response(axes["response"], parameter, points, data)
        _sensitivities(axes, parameter, points, data, derivatives)


def _sensitivities(
    axes: dict[str, Any],
    parameter: str,
    points: list[SweepPoint],
    data: Any,
    derivatives: list[str] | tuple[str, ...],
) -> None:
    """The shown amplitude's derivative in each path of ``derivatives`` against the
    parameter, each direction, on ``axes["d PATH"]`` (sharing the response's axis)."""
    shown, unit = shown_amplitudes(points[0])
    for index, d_path in enumerate(derivatives):
        ax = axes[f"d {d_path}"]
        ax.sharex(axes["response"])
        for direction, marker in (("up", "^"), ("down", "v")):
            chosen = [p for p in points if p.direction == direction]
            if chosen:
                ax.plot(
                    [p.value for p in chosen],
                    [shown_derivative(p, shown, d_path) for p in chosen],
                    marker=marker,
                    ms=3,
                    lw=1,
                    label=f"sweep {direction}",
                )
        ax.axhline(0.0, color="k", lw=0.5)
        ax.set_ylabel(
            f"d amplitude / d {d_path}\n({derivative_units(unit, d_path, data)})", fontsize=8
        )
        ax.grid(alpha=0.3)
        if index == 0:
            ax.set_title("the orbit's sensitivity (none where no orbit is found)", fontsize=9)
            ax.legend(fontsize=8)
        if index == len(derivatives) - 1:
            ax.set_xlabel(f"{parameter}{_unit(parameter, data)}")


def _frequency_response(ax: Any, parameter: str, points: list[SweepPoint], data: Any) -> None:
    """The frequency response panel of :func:`plot_sweep` on ``ax``."""
    shown, unit = shown_amplitudes(points[0])

    def amplitude(p: SweepPoint) -> float:
        return float(shown_values(p, shown)[0][0])

    grid, linear = _linear_curve(parameter, points, data, shown)
    ax.plot(grid, linear, "k--", lw=1, label="without dampers, stops and friction (linear)")
    for direction, marker in (("up", "^"), ("down", "v")):
        chosen = [p for p in points if p.direction == direction]
        if chosen:
            ax.plot(
                [p.value for p in chosen],
                [amplitude(p) for p in chosen],
                marker=marker,
                ms=3,
                lw=1,
                label=f"with them, sweep {direction}",
            )
    unsettled = [p for p in points if not p.settled and not p.error]
    if unsettled:
        least = [_least_shown(p, shown) for p in unsettled]
        ax.vlines(
            [p.value for p in unsettled],
            least,
            [amplitude(p) for p in unsettled],
            colors="tab:red",
            lw=2.5,
            alpha=0.6,
            label="not settled: spread of the periods' peaks",
        )
        ax.plot(
            [p.value for p in unsettled],
            [amplitude(p) for p in unsettled],
            "o",
            ms=6,
            mfc="none",
            mec="tab:red",
            label="not settled (no period of at most 8 forcing periods)",
        )
    failed = [p.value for p in points if p.error]
    if failed:
        ax.plot(
            failed,
            [0.0] * len(failed),
            "kx",
            ms=7,
            transform=ax.get_xaxis_transform(),
            clip_on=False,
            label="run failed (see the table or --json)",
        )
    ax.set_xlabel(f"{parameter}{_unit(parameter, data)}")
    ax.set_ylabel(f"{shown_label(points[0], shown)} ({unit})")
    # Below the axes: inside, it had covered the peak.
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=2, fontsize=8)
    ax.grid(alpha=0.3)


def _least_shown(point: SweepPoint, shown: str) -> float:
    """The smallest of a not settled point's periods' peaks, of the quantity
    ``shown`` (see :func:`shown_amplitudes`); its amplitude where unknown."""
    coordinates, at_points, moments = split_observed(
        point.least_period_peak, len(point.amplitude), len(point.points)
    )
    least = {"coordinate": coordinates, "point": at_points, "moment": moments}[shown]
    return float(least[0]) if len(least) else float(shown_values(point, shown)[0][0])


def plot_history(path: Path, sol: SystemSolution) -> None:
    """Time history of structure coordinate 0, or of the structure at the first of
    ``[output] points`` (and each damper's displacement), its phase portrait, and the
    impacts marked on both."""
    with _figure(path, 1, 2, (11, 4.5)) as (fig, (left, right)):
        if len(sol.points):
            # A cantilever's coordinate 0 is a mode, not a deflection beside the dampers'.
            x, v = sol.displacement_at(sol.points[0]), sol.velocity_at(sol.points[0])
            name = f"structure at point {sol.points[0]:g}"
        else:
            x = sol.structure_displacement[:, 0]
            v = sol.structure_velocity[:, 0]
            name = "structure coordinate 0"
        left.plot(sol.t, x, lw=1, label=name)
        for j in range(sol.damper_displacement.shape[1]):
            left.plot(sol.t, sol.damper_displacement[:, j], lw=0.8, label=f"damper {j}")
        right.plot(x, v, lw=1)
        onsets = np.asarray(sol.contacts.onset)
        kinds = list(sol.contacts.kind)
        hits = np.array([k != "sticking" for k in kinds], dtype=bool)
        if len(onsets) and hits.any() and len(sol.t) > 1:
            times = onsets[hits]
            xs = np.interp(times, sol.t, x)
            left.plot(times, xs, "rx", ms=5, label="impacts")
            right.plot(xs, np.interp(times, sol.t, v), "rx", ms=5, label="impacts")
            right.legend()
        left.set_xlabel("t (s)")
        left.set_ylabel("displacement (m, relative to the base)")
        left.legend(fontsize=8)
        right.set_xlabel(f"{name}: displacement (m)")
        right.set_ylabel(f"{name}: velocity (m/s)")
        for ax in (left, right):
            ax.grid(alpha=0.3)


def orbit_history(run: Runner, state: np.ndarray, periods: int) -> SystemSolution:
    """The history of a run of ``periods`` forcing periods from ``state``."""
    prepared = run.prepared
    n, k = run.n, run.k
    d = n + k
    initial = {
        "structure_displacement": list(state[:n]),
        "structure_velocity": list(state[d : d + n]),
        "damper_displacement": list(state[n:d]),
        "damper_velocity": list(state[d + n :]),
    }
    solver = {**prepared.solver, "t_end": periods * run.period}
    if solver["method"] == "exact" and solver["dt"] is None:
        # Smooth curves: about 200 rows a period.
        solver["dt"] = run.period / 200
    output = {**prepared.output, "history": True, "every": 1}
    return dataclasses.replace(prepared, initial=initial, solver=solver, output=output).run()


def plot_section(path: Path, section: Section, period: float) -> None:
    """The stroboscopic section (structure coordinate 0) and the impact section
    (impact phase against impact speed)."""
    with _figure(path, 1, 2, (11, 4.5)) as (fig, (left, right)):
        dim = section.strobe.shape[1] // 2
        x, v = section.strobe[:, 0], section.strobe[:, dim]
        left.plot(x, v, ".", ms=3)
        # The size of the motion from the sampled states: the amplitude of a harmonic
        # motion through each, sqrt(x^2 + (v / w)^2), and its speed w times that.
        w = 2 * np.pi / period
        amplitude = float(np.max(np.hypot(x, v / w), initial=0.0))
        _span_at_least(left, "x", x, amplitude)
        _span_at_least(left, "y", v, w * amplitude)
        left.set_xlabel("structure displacement 0 (m)")
        left.set_ylabel("structure velocity 0 (m/s)")
        left.set_title(f"stroboscopic, every {period:.6g} s")
        for pair in sorted(set(section.impact_pair)):
            chosen = np.array([p == pair for p in section.impact_pair], dtype=bool)
            right.plot(
                section.impact_phase[chosen], section.impact_speed[chosen], ".", ms=3, label=pair
            )
        right.set_xlabel("impact phase in the forcing period (rad)")
        right.set_ylabel("impact speed (m/s)")
        right.set_xlim(0, 2 * np.pi)
        speeds = section.impact_speed
        _span_at_least(right, "y", speeds, float(np.max(np.abs(speeds), initial=0.0)))
        if section.impact_pair:
            right.legend()
        for ax in (left, right):
            ax.grid(alpha=0.3)


def plot_bifurcation(
    path: Path,
    parameter: str,
    points: list[BifurcationPoint],
    data: Any = None,
    *,
    sample: str = "displacement",
    pair: str | None = None,
) -> None:
    """The samples of each point (see :func:`~vibroimpact.analysis.bifurcation`: the
    stroboscopic displacement of structure coordinate 0, or each impact's approach
    speed or phase) against the parameter, each direction."""
    with _figure(path) as (fig, ax):
        for direction, colour in (("up", "tab:blue"), ("down", "tab:orange")):
            xs: list[float] = []
            ys: list[float] = []
            for p in points:
                if p.direction == direction and p.samples.size:
                    xs += [p.value] * len(p.samples)
                    ys += list(p.samples)
            if xs:
                ax.plot(xs, ys, ".", ms=1.5, color=colour, label=f"sweep {direction}")
        impacts = f"each impact of {pair}" if pair else "each impact"
        label = {
            "displacement": "stroboscopic structure displacement 0",
            "impact-velocity": f"impact velocity: approach speed at {impacts}",
            "impact-phase": f"impact phase $\\omega t$ mod $2\\pi$ at {impacts}",
        }[sample]
        ax.set_xlabel(f"{parameter}{_unit(parameter, data)}")
        ax.set_ylabel(f"{label} ({BIFURCATION_SAMPLES[sample]})")
        if sample == "impact-phase":
            ax.set_ylim(0, 2 * np.pi)
        if ax.lines:
            ax.legend(markerscale=6)
        ax.grid(alpha=0.3)


def plot_basins(path: Path, result: Basins, x_name: str, y_name: str) -> None:
    """The attractor reached from each start (colours), not settled (white),
    failed (grey) and not admissible (black)."""
    import matplotlib.colors as colors

    with _figure(path) as (fig, ax):
        count = len(result.attractors)
        palette = ["#000000", "#dddddd", "#ffffff"] + [
            colors.to_hex(c)
            for c in __import__("matplotlib").colormaps["tab10"](np.arange(count) % 10)
        ]
        cmap = colors.ListedColormap(palette)
        mesh = ax.pcolormesh(
            result.first,
            result.second,
            (result.labels + 3).T,
            cmap=cmap,
            vmin=-0.5,
            vmax=len(palette) - 0.5,
            shading="nearest",
        )
        ticks = list(range(len(palette)))
        labels = ["not admissible", "failed", "not settled"] + [
            f"{a['period']}-periodic, {a['impacts_per_period']:g} impacts/period"
            for a in result.attractors
        ]
        bar = fig.colorbar(mesh, ax=ax, ticks=ticks)
        bar.ax.set_yticklabels(labels, fontsize=7)
        unit = " (m/s)" if "velocity" in x_name else " (m)"
        ax.set_xlabel(f"initial {x_name}{unit}")
        unit = " (m/s)" if "velocity" in y_name else " (m)"
        ax.set_ylabel(f"initial {y_name}{unit}")


def plot_branch(path: Path, branch: Branch, data: Any = None) -> None:
    """Amplitude of structure coordinate 0 along the branch (and the period-doubled
    one it switched to, in a lighter shade): stable solid, unstable dashed,
    bifurcations marked."""
    with _figure(path) as (fig, ax):
        shades = (("tab:blue", "tab:red"), ("tab:cyan", "tab:orange"))
        shown = [branch] + ([branch.switched] if branch.switched is not None else [])
        for (steady, unsteady), part in zip(shades, shown, strict=False):
            _draw_branch(ax, part, (steady, unsteady))
            ax.plot([], [], "-", color=steady, label=f"{part.periods}-period, stable")
            ax.plot([], [], "--", color=unsteady, label=f"{part.periods}-period, unstable")
        ax.set_xlabel(f"{branch.parameter}{_unit(branch.parameter, data)}")
        ax.set_ylabel("amplitude of structure coordinate 0 (m)")
        located = ", ".join(f"{b.kind} at {b.value:.10g}" for b in branch.bifurcations)
        ax.set_title(f"{branch.periods}-period orbits" + (f"; {located}" if located else ""))
        ax.legend()
        ax.grid(alpha=0.3)


def _draw_branch(ax: Any, branch: Branch, colors: tuple[str, str]) -> None:
    """One branch's amplitude, stable solid in ``colors[0]``, unstable dashed in
    ``colors[1]``, each bifurcation marked where it lies (located exactly, else where
    its multiplier crossed) and the line split there where the stability changed: the
    whole segment had been drawn dashed and the flag put on the point after it."""
    points = branch.points
    marked = []
    for before, after in zip(points, points[1:], strict=False):
        flags = _flag_values(branch, before, after)
        marked += [(kind, value, before, after) for kind, value in flags]
        cuts, styles = [before.value, after.value], [before.stable and after.stable]
        if flags and before.stable != after.stable:
            cuts = [before.value, flags[0][1], after.value]
            styles = [before.stable, after.stable]
        for low, high, stable in zip(cuts, cuts[1:], styles, strict=False):
            ax.plot(
                [low, high],
                [_amplitude_at(before, after, v) for v in (low, high)],
                "-" if stable else "--",
                color=colors[0] if stable else colors[1],
                lw=1.2,
            )
    for found in branch.bifurcations:
        near = _bracketing(points, found.value)
        if near is not None and (found.kind, found.value) not in [m[:2] for m in marked]:
            marked.append((found.kind, found.value, *near))
    for kind, value, before, after in marked:
        y = _amplitude_at(before, after, value)
        ax.annotate(kind, (value, y), fontsize=7)
        ax.plot([value], [y], "ko", ms=3)


def _flag_values(branch: Branch, before: Any, point: Any) -> list[tuple[str, float]]:
    """Each bifurcation ``point`` is flagged with since ``before``, and its parameter:
    the located one between them, else where its multiplier crossed, else the point's."""
    out = []
    for flag in point.flags:
        located = (
            found.value
            for found in branch.bifurcations
            if found.kind == flag and _within(found.value, before.value, point.value)
        )
        out.append((flag, next(located, point.crossings.get(flag, point.value))))
    return out


def _within(value: float, a: float, b: float) -> bool:
    """Whether ``value`` lies between ``a`` and ``b`` (either order), ends included."""
    return min(a, b) <= value <= max(a, b)


def _bracketing(points: list[Any], value: float) -> tuple[Any, Any] | None:
    """The first two neighbouring points of a branch whose parameters bracket ``value``."""
    for before, after in zip(points, points[1:], strict=False):
        if _within(value, before.value, after.value):
            return before, after
    return None


def _amplitude_at(before: Any, after: Any, value: float) -> float:
    """Coordinate 0's amplitude between two branch points at parameter ``value``,
    interpolated linearly (the located bifurcation's own orbit is not run again)."""
    span = after.value - before.value
    weight = 0.0 if span == 0 else (value - before.value) / span
    return float(before.amplitude[0] + weight * (after.amplitude[0] - before.amplitude[0]))


def plot_study(path: Path, dataset: Any, metric: str, x: str, y: str) -> None:
    """A heat map of ``metric`` over the axes ``x`` and ``y`` of a study's Dataset:
    the other axes (and structure coordinates, points or pairs beyond the first)
    reduced to their worst case, the largest value; the optimum, the smallest, marked."""
    values = dataset[metric]
    if values.dtype == bool:
        # A yes-or-no metric (settled, stable) as 1 / 0, a failed run's blank.
        values = values.astype(float).where(dataset["status"] == 0)
    where = ""
    for dim in ("coordinate", "pair", "at", "moment_at"):
        if dim in values.dims:
            if dim in ("at", "moment_at"):
                where = f" at {float(values[dim][0]):g}" + (" m" if dim == "moment_at" else "")
            values = values.isel({dim: 0})
    others = [d for d in values.dims if d not in (x, y)]
    if others:
        values = values.max(others)
    grid = values.transpose(y, x)
    with _figure(path) as (fig, ax):
        mesh = ax.pcolormesh(
            dataset[x].values, dataset[y].values, grid.values, shading="nearest", cmap="viridis"
        )
        units = dataset[metric].attrs.get("units", "")
        label = metric + where + (f" ({units})" if units and units != "1" else "")
        if others:
            label += ", worst over " + ", ".join(others)
        fig.colorbar(mesh, ax=ax, label=label)
        if np.isnan(grid.values).all():
            # Every run failed: the map is empty, and says so (the reasons are in
            # the Dataset's attributes).
            ax.set_title("every run failed")
        else:
            flat = np.nanargmin(grid.values)
            iy, ix = np.unravel_index(flat, grid.shape)
            ax.plot(dataset[x].values[ix], dataset[y].values[iy], "r*", ms=14, label="optimum")
            ax.legend(loc="upper right")
        for axis, name in ((ax.xaxis, x), (ax.yaxis, y)):
            values = np.asarray(dataset[name].values, dtype=float)
            # An axis spaced logarithmically is drawn so.
            if len(values) > 2 and np.all(values > 0):
                steps = np.diff(np.log(values))
                if np.allclose(steps, steps[0]) and not np.allclose(
                    np.diff(values), values[1] - values[0]
                ):
                    (ax.set_xscale if axis is ax.xaxis else ax.set_yscale)("log")
        for set_label, name in ((ax.set_xlabel, x), (ax.set_ylabel, y)):
            units = dataset[name].attrs.get("units")
            set_label(f"{name} ({units})" if units else name)


def plot_lyapunov(path: Path, found: Lyapunov) -> None:
    """Each Lyapunov exponent's estimate against the time averaged over (its
    convergence), the final values with their standard errors at the right."""
    with _figure(path) as (fig, ax):
        finite = np.isfinite(found.exponents)
        for j in np.flatnonzero(finite):
            line = ax.plot(found.running_time, found.running[:, j], ".-", label=f"λ{j + 1}")
            error = found.standard_error[j]
            if np.isfinite(error):
                ax.errorbar(
                    found.running_time[-1],
                    found.exponents[j],
                    yerr=error,
                    color=line[0].get_color(),
                    capsize=4,
                )
        ax.axhline(0.0, color="0.5", lw=0.8)
        ax.set_xlabel("time averaged over (s)")
        ax.set_ylabel("Lyapunov exponent (1/s)")
        lost = int(np.count_nonzero(~finite))
        ax.set_title(
            f"{found.impacts} impacts" + (f"; {lost} direction(s) lost to sticking" if lost else "")
        )
        ax.legend()
        ax.grid(alpha=0.3)


def plot_curve(
    path: Path, found: Curve, regions: list[tuple[str, float, float]], data: Any = None
) -> None:
    """A curve of bifurcations in the plane of its two parameters (the second along x),
    with the regions it bounds labelled where they were read."""
    with _figure(path) as (fig, ax):
        x = [p.values[found.second] for p in found.points]
        y = [p.values[found.parameter] for p in found.points]
        ax.plot(x, y, "-", color="tab:purple", lw=1.5, label=f"{found.kind}")
        ax.plot(x[:1], y[:1], "ko", ms=4, label="located first")
        for label, at_x, at_y in regions:
            ax.annotate(label, (at_x, at_y), fontsize=8, ha="center", va="center")
            ax.plot([at_x], [at_y], ".", color="0.4", ms=3)
        ax.set_xlabel(f"{found.second}{_unit(found.second, data)}")
        ax.set_ylabel(f"{found.parameter}{_unit(found.parameter, data)}")
        ax.set_title(f"{found.kind} of {found.periods}-period orbits: {len(found.points)} points")
        ax.legend()
        ax.grid(alpha=0.3)
