"""Studies: a grid of runs of one 0.2 scenario with some of its parameters varied,
run on every core by the Rust core (rayon, the GIL released), each reduced to
metrics; the result an xarray Dataset written as a NetCDF file (``RESULT.nc``) or a Zarr
store (``RESULT.zarr``, with the optional zarr package), chunk by chunk so that an
interrupted study resumes where it stopped and gives the same file or store.

The ``[study]`` section::

    [study]
    analysis = "steady-state"      # or "run" (to [solver] t_end; record_from, s), "orbit"
    settle_periods = 200           # steady-state, orbit: forcing periods to settle
    record_periods = 50            # steady-state: periods to record (at least 8 run)
    orbit_periods = 1              # orbit: its period, in forcing periods
    metrics = ["peak", "rms", "impacts", "energy_dissipated",
               "amplitude", "impacts_per_period", "settled"]
               # orbit: "amplitude", "impacts_per_period", "stable", "largest_multiplier"
               # default: "peak", "rms", "impacts"; for an orbit, its four
    chunk_size = 1024              # runs a chunk (what a resume can lose at most)

    samples = 100                  # Monte Carlo: runs of random draws at each grid point
    seed = 7                       #   of the generator of [study.random]
    stepping = "events"            # or "fixed": see below

    [study.axes]
    "damper.0.clearance" = { start = 0.001, stop = 0.01, count = 10 }
    "damper.0.mass" = [0.01, 0.02, 0.05]
    "excitation.0.frequency" = { start = 5.0, stop = 50.0, count = 20, spacing = "log" }

    [study.random]
    "damper.0.restitution" = { uniform = [0.4, 0.8] }
    "excitation.0.phase" = { normal = [0.0, 0.5] }

Axes vary the paths :data:`vibroimpact._core` lists in its error for another one
(dampers, stops, gravity, harmonic excitations, entries of ``[initial]``; the structure's
``mass``, ``stiffness``, ``damping`` for ``kind = "oscillator"`` and ``length``,
``youngs_modulus``, ``second_moment``, ``mass_per_length``, ``damping_ratio`` for
``kind = "cantilever"``, the structure made again for each run, its points staying where
they are; random signals' ``seed``, ``intensity``, ``cutoff_frequency``, ``duration``, and
``ground_frequency``, ``ground_damping`` for ``"kanai-tajimi"``, the signal generated again
for each run that varies it). A bad value fails its run alone, with its reason naming the
key. A seed axis holds whole numbers in [0, 2^53]::

    [study.axes]
    "excitation.0.seed" = { start = 0, stop = 99, count = 100 }   # 100 realisations

Each run's signal is the one a scenario written with that seed has, bit for bit, whatever
the threads, chunks or Dask workers. With ``samples``, ``"excitation.0.seed" = { from = N }``
in ``[study.random]`` gives sample ``k`` the seed ``N + k`` (no draw taken). In the
Dataset each axis is a dimension named by its path, the metrics are data
variables (with a ``coordinate`` dimension for per-structure-coordinate metrics and
``pair`` for per-pair ones; with ``[output] points``, ``peak``, ``rms`` and ``amplitude``
of the structure at each point as ``point_peak``... over a dimension ``at``), and
``status`` is 0 for a run that completed, else ``k``, the ``k``-th reason of the
attribute ``reasons`` (a failed run's metrics are NaN; its ``settled`` and ``stable``,
booleans, false). With ``samples``, a ``sample`` dimension follows the axes, and each
random parameter is a variable over it: the same draws (numpy's PCG64 from ``seed``, in
the order of ``[study.random]``) at every grid point. SI units.

``analysis = "orbit"`` settles each point for ``settle_periods`` forcing periods, then
shoots for an orbit of ``orbit_periods`` periods from there (Newton's method with the
central-difference monodromy, as :func:`vibroimpact.analyses.orbit`, in the core): ``stable``
is true when it converged and every Floquet multiplier is inside the unit circle,
``largest_multiplier`` the largest multiplier's modulus, ``amplitude`` and
``impacts_per_period`` those of the orbit. A point whose shooting fails (no orbit near its
settled state) is recorded with its reason. Both periodic analyses use the common period
of the excitations (see :func:`vibroimpact.analyses.forcing_period`): other forcing is
refused, and a point an axis makes aperiodic fails with its reason.

``stepping = "fixed"`` runs a study of the two-mass impact damper (one mass on a spring,
one ``[[damper]]`` with equal clearances and a compliant law, no stops, gravity or
excitation; ``[solver] method = "rk4"`` with its ``dt``; ``analysis = "run"``) as a
lockstep ensemble: sixteen runs advanced together in vector instructions, each the same bit
for bit as the fixed-step run ``vibroimpact.simulate(..., method="rk4",
stepping="fixed")`` makes of it (steps are not cut at contacts; contact onsets are located
inside the step). It keeps ``peak`` (step ends and extrema located on the cubic Hermite
interpolant), ``rms`` (trapezoidal rule over the step ends) and ``impacts`` (contacts whose
located onset is at or after ``record_from``). A run whose state stops being finite, or
whose mechanical energy grows past its start by more than ``energy_tolerance``, fails with
its reason; these are its only checks, looser than a single run's energy ledger.
"""

from __future__ import annotations

import difflib
import hashlib
import importlib
import json
import logging
import math
import os
import shutil
import sys
import time
import zipfile
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from vibroimpact import arguments
from vibroimpact._core import InvalidInputError, __version__, run_study
from vibroimpact.analyses import (
    MAX_PERIODS,
    AnalysisError,
    _prepare,
    check_total,
    forcing_period,
    whole_count,
    with_parameter,
)
from vibroimpact.forcing_limits import check_forcing_period
from vibroimpact.model.system import System, sections_of
from vibroimpact.output import UsageError, claim_beside, remove_stale, swap_in, written_whole
from vibroimpact.system import _NUMBER, _REQ, _TEXT, _WHOLE, _choice, _table, split_observed

# What each analysis keeps; every metric.
_RUN_METRICS = ("peak", "rms", "impacts", "energy_dissipated")
_STEADY_METRICS = (*_RUN_METRICS, "amplitude", "impacts_per_period", "settled")
_ANALYSIS_METRICS = {
    "run": _RUN_METRICS,
    "steady-state": _STEADY_METRICS,
    "orbit": ("amplitude", "impacts_per_period", "stable", "largest_multiplier"),
}
METRICS = (*_STEADY_METRICS, "stable", "largest_multiplier")
# The metrics that are yes or no: booleans in the Dataset.
_FLAGS = ("settled", "stable")
_ANALYSES = tuple(_ANALYSIS_METRICS)
_SPACINGS = ("linear", "log")
_STUDY = {
    "analysis": (_TEXT, "run"),
    "settle_periods": (_WHOLE, 200),
    "record_periods": (_WHOLE, 50),
    "orbit_periods": (_WHOLE, 1),
    # None: [output] record_from, else 0 (see study()).
    "record_from": (_NUMBER, None),
    "tolerance": (_NUMBER, 1e-6),
    "chunk_size": (_WHOLE, 1024),
    "samples": (_WHOLE, 0),
    "seed": (_WHOLE, 0),
    "stepping": (_TEXT, "events"),
}
_STEPPINGS = ("events", "fixed")
# What a lockstep ensemble of fixed steps keeps.
_FIXED_METRICS = ("peak", "rms", "impacts")
_AXIS = {
    "start": (_NUMBER, _REQ),
    "stop": (_NUMBER, _REQ),
    "count": (_WHOLE, _REQ),
    "spacing": (_TEXT, "linear"),
}
# What each metric means and its unit (attrs of the Dataset's variables).
_DESCRIPTIONS = {
    "peak": ("largest |displacement| of each structure coordinate, recorded", "m"),
    "rms": ("RMS displacement of each structure coordinate, recorded", "m"),
    "impacts": ("impacts and compliant contacts recorded (sticking not counted)", "1"),
    "energy_dissipated": ("energy taken by each pair's contacts and impacts, recorded", "J"),
    "amplitude": (
        "largest |displacement| of each structure coordinate over the recorded periods",
        "m",
    ),
    "impacts_per_period": (
        "impacts and compliant contacts per forcing period (sticking not counted)",
        "1",
    ),
    "settled": (
        "whether the stroboscopic state repeats within tolerance (false where the run "
        "failed: see status)",
        "1",
    ),
    "stable": (
        "whether the orbit converged and every Floquet multiplier is inside the unit "
        "circle (false where the run failed: see status)",
        "1",
    ),
    "largest_multiplier": ("modulus of the orbit's largest Floquet multiplier", "1"),
}


class StudyError(AnalysisError):
    """A study that cannot be set up as asked (a ValueError)."""


#: The most threads (or Dask processes) a study may ask for: more than any machine's
#: cores, far fewer than would exhaust its threads.
MAX_WORKERS = 1024


def check_threads(threads: Any, name: str) -> None:
    """Refuse ``threads`` (given as ``name``: ``"threads:"``, ``"--workers"``) that is
    not a whole number in [0, MAX_WORKERS] (0: all cores)."""
    if isinstance(threads, bool) or not isinstance(threads, int):
        raise StudyError(f"{name} must be a whole number, got {threads!r}")
    if not 0 <= threads <= MAX_WORKERS:
        raise StudyError(
            f"{name} must be in [0, {MAX_WORKERS}] (0: all cores, {os.cpu_count() or 1} "
            f"here), got {threads}"
        )


#: The most runs a study may hold (the product of its axes' counts, times ``samples``):
#: its metrics and their reasons are gathered in memory at the end (about 100 bytes a
#: run and metric), and ten million runs are hours of computing already.
MAX_STUDY_RUNS = 10_000_000


#: Metrics kept at each of [output] points and moments as well as per coordinate.
PER_COORDINATE = ("peak", "rms", "amplitude")
_FOLLOWED = tuple(f"{kind}_{m}" for kind in ("point", "moment") for m in PER_COORDINATE)


def base_metrics(names: Sequence[str]) -> list[str]:
    """The metrics the runs keep for ``names``: ``point_peak``, ``moment_rms``... are
    the per-coordinate ``peak``, ``rms``... (kept at each of ``[output] points`` and
    ``moments`` too, in the Dataset's ``point_*``, ``moment_*``); each once, in order."""
    out = []
    for name in names:
        for kind in ("point_", "moment_"):
            if name.startswith(kind) and name[len(kind) :] in PER_COORDINATE:
                name = name[len(kind) :]
        out.append(name)
    return list(dict.fromkeys(out))


def checked_study_settings(table: Any) -> dict[str, Any]:
    """The ``[study]`` section checked as :func:`study_settings` checks it, without
    making its axes' values or its random draws: ``axes`` and ``random`` are left as
    given. What reading a scenario does, so that a command other than ``study`` never
    allocates them."""
    return study_settings(table, build=False)


def study_settings(table: Any, build: bool = True) -> dict[str, Any]:
    """The ``[study]`` section checked, with its defaults; each axis as its list of
    values (``axes``: a dict, path to array). Every count is checked, and the runs
    bounded by :data:`MAX_STUDY_RUNS`, before any array is made; ``build=False``
    makes none (see :func:`checked_study_settings`)."""
    if not isinstance(table, Mapping):
        raise StudyError(f"[study]: must be a table, got {table!r:.60}")
    sections = ("metrics", "axes", "random")
    allowed = [*_STUDY, *sections]
    for key in table:
        if key not in allowed:
            close = difflib.get_close_matches(str(key), allowed, n=1)
            hint = f"; did you mean {close[0]!r}?" if close else ""
            raise StudyError(f"[study] unknown key {key!r} (allowed: {', '.join(allowed)}){hint}")
    # A None is a default left to fill (TOML has none): settings checked before.
    plain = {k: v for k, v in table.items() if k not in sections and v is not None}
    out = _table("[study] ", plain, _STUDY)
    _choice("[study] ", "analysis", out["analysis"], _ANALYSES)
    _choice("[study] ", "stepping", out["stepping"], _STEPPINGS)
    # By default what the analysis keeps (an orbit's own metrics, none of a run's).
    default = _ANALYSIS_METRICS["orbit"] if out["analysis"] == "orbit" else _FIXED_METRICS
    metrics = table.get("metrics", list(default))
    if isinstance(metrics, str) or not isinstance(metrics, Sequence) or not metrics:
        raise StudyError(f"[study] metrics: must be a list of names, got {metrics!r:.60}")
    for name in metrics:
        _choice("[study] ", "metrics", name, METRICS + _FOLLOWED)
    asked, metrics = metrics, base_metrics(metrics)
    if out["stepping"] == "fixed":
        if out["analysis"] != "run":
            raise StudyError(
                '[study] stepping = "fixed": runs each member to [solver] t_end; '
                'use analysis = "run"'
            )
        other = [m for m in metrics if m not in _FIXED_METRICS]
        if other:
            raise StudyError(
                f'[study] metrics: {", ".join(other)} not kept by stepping = "fixed" '
                f'(allowed: {", ".join(_FIXED_METRICS)}; or stepping = "events")'
            )
    kept = _ANALYSIS_METRICS[out["analysis"]]
    other = [name for name in metrics if name not in kept]
    if other:
        keeping = [a for a, names in _ANALYSIS_METRICS.items() if set(other) <= set(names)]
        hint = f"; use analysis = {' or '.join(repr(a) for a in keeping)}" if keeping else ""
        raise StudyError(
            f"[study] metrics: {', '.join(other)} not kept by analysis = "
            f'"{out["analysis"]}" (it keeps {", ".join(kept)}){hint}'
        )
    # As asked (point_peak... among them: see base_metrics).
    out["metrics"] = list(dict.fromkeys(asked))
    for key, low in (
        ("settle_periods", 0),
        ("record_periods", 1),
        ("orbit_periods", 1),
        ("chunk_size", 1),
    ):
        if out[key] < low:
            raise StudyError(f"[study] {key}: must be >= {low}, got {out[key]}")
        if key != "chunk_size" and out[key] > MAX_PERIODS:
            # As the analyses' own settings: 1e11 periods ran for half a minute into
            # gigabytes of contacts before failing (user trial).
            raise StudyError(
                f"[study] {key}: must be at most {MAX_PERIODS} forcing periods, got {out[key]}"
            )
    try:
        check_total(
            ("[study] settle_periods", out["settle_periods"]),
            ("record_periods", out["record_periods"]),
        )
    except AnalysisError as err:
        raise StudyError(str(err)) from None
    if out["record_from"] is not None and not out["record_from"] >= 0:
        raise StudyError(f"[study] record_from: must be >= 0 s, got {out['record_from']}")
    if not out["tolerance"] > 0:
        raise StudyError(f"[study] tolerance: must be > 0, got {out['tolerance']}")
    axes = table.get("axes")
    if not isinstance(axes, Mapping) or not axes:
        raise StudyError(
            "[study.axes]: required, a table of dotted paths to a list of values or "
            "{start, stop, count}"
        )
    counts = {}
    for path, spec in axes.items():
        _check_path(f"[study.axes] {str(path)!r}: ", str(path))
        counts[str(path)] = _axis_count(str(path), spec)
    random = table.get("random", {})
    if not isinstance(random, Mapping):
        raise StudyError("[study.random]: must be a table of dotted paths to distributions")
    if random and out["samples"] < 1:
        raise StudyError("[study] samples: must be >= 1 with [study.random]")
    if out["samples"] and not random:
        raise StudyError(
            "[study] samples: needs [study.random] (the parameters drawn for each sample)"
        )
    for path, spec in random.items():
        path = str(path)
        _check_path(f"[study.random] {path!r}: ", path)
        if path in counts:
            raise StudyError(f"[study.random] {path!r}: is also an axis")
        _distribution(path, spec, out["samples"])
    runs = math.prod(counts.values()) * max(out["samples"], 1)
    if runs > MAX_STUDY_RUNS:
        sizes = " x ".join(f"{path} {count}" for path, count in counts.items())
        keys = "[study.axes] count"
        if out["samples"]:
            sizes += f" x samples {out['samples']}"
            keys = "[study] samples, [study.axes] count"
        raise StudyError(
            f"{keys}: the study would make {runs:.3g} runs ({sizes}), more than "
            f"{MAX_STUDY_RUNS:,}; lower the counts or samples, or split the study"
        )
    if not build:
        return {**out, "axes": dict(axes), "random": dict(random)}
    out["axes"] = {str(path): _axis_values(str(path), spec) for path, spec in axes.items()}
    for path, values in out["axes"].items():
        if _is_seed(path):
            _check_seeds(f"[study.axes] {path!r}: ", values)
    # Every distribution from one generator seeded by `seed`, in the order given:
    # the same draws on every platform (numpy's PCG64), the same for every grid point.
    generator = np.random.default_rng(out["seed"])
    out["random"] = {}
    for path, spec in random.items():
        out["random"][str(path)] = _draws(str(path), spec, out["samples"], generator)
    return out


def _check_path(where: str, path: str) -> None:
    """Refuse a dotted path whose index is not a whole number from 0 (``-1``, ``+1``):
    Python would read a negative one from the end."""
    for part in path.split(".")[1:]:
        if part.lstrip("+-").isdigit() and not (part.isascii() and part.isdigit()):
            raise StudyError(f"{where}{part!r}: an index is a whole number from 0")


def _axis_count(path: str, spec: Any) -> int:
    """The number of values of an axis, checked (and a seed axis's values) without
    making them."""
    where = f"[study.axes] {path!r}: "
    if not isinstance(spec, Mapping):
        return len(_axis_values(path, spec))
    axis = _table(where, spec, _AXIS)
    _choice(where, "spacing", axis["spacing"], _SPACINGS)
    count: int = axis["count"]
    if count < 1:
        raise StudyError(f"{where}count: must be >= 1, got {count}")
    if count > MAX_STUDY_RUNS:
        raise StudyError(f"{where}count: must be at most {MAX_STUDY_RUNS:,}, got {count}")
    if axis["spacing"] == "log" and not (axis["start"] > 0 and axis["stop"] > 0):
        raise StudyError(f'{where}start, stop: must be > 0 for spacing = "log"')
    if _is_seed(path):
        # The ends, and the step between them: all whole when these are.
        step = (axis["stop"] - axis["start"]) / (count - 1) if count > 1 else 0.0
        _check_seeds(where, np.array([axis["start"], axis["stop"]]))
        if not float(step).is_integer():
            raise StudyError(
                f"{where}a seed must be a whole number in [0, 2^53]: start, stop and count "
                f"give a step of {step!r}"
            )
    return count


def _is_seed(path: str) -> bool:
    """Whether ``path`` is a random signal's seed (``excitation.N.seed``)."""
    parts = path.split(".")
    return len(parts) == 3 and parts[0] == "excitation" and parts[2] == "seed"


#: Seeds travel among the study's values as floats: whole numbers up to 2^53.
_MAX_SEED = 2**53


def _check_seeds(where: str, values: np.ndarray) -> None:
    bad = [v for v in values if not (0 <= v <= _MAX_SEED and float(v).is_integer())]
    if bad:
        raise StudyError(f"{where}a seed must be a whole number in [0, 2^53], got {float(bad[0])}")


def _distribution(path: str, spec: Any, samples: int) -> tuple[str, float, float]:
    """A ``[study.random]`` entry checked: its law and two numbers (``"from"``, the
    first seed and the last, for a seed)."""
    where = f"[study.random] {path!r}: "
    if _is_seed(path):
        # A seed of its own for each sample: from, from + 1, ... (no draw taken).
        first = spec.get("from") if isinstance(spec, Mapping) and len(spec) == 1 else None
        if isinstance(first, bool) or not isinstance(first, int):
            raise StudyError(
                f"{where}a seed is given as {{from = N}}: seed N + k for sample k, got {spec!r:.40}"
            )
        _check_seeds(where, np.array([first, first + max(samples - 1, 0)], dtype=float))
        return "from", float(first), float(first + max(samples - 1, 0))
    if (
        not isinstance(spec, Mapping)
        or len(spec) != 1
        or not isinstance(next(iter(spec)), str)
        or next(iter(spec)) not in _LAWS
    ):
        raise StudyError(
            f"{where}must be one of {{uniform = [low, high]}}, {{normal = [mean, std]}} "
            "(or {from = N} for a seed)"
        )
    law, bounds = next(iter(spec.items()))
    if (
        isinstance(bounds, str)
        or not isinstance(bounds, Sequence)
        or len(bounds) != 2
        or any(isinstance(b, bool) or not isinstance(b, int | float) for b in bounds)
        or not all(math.isfinite(b) for b in bounds)
    ):
        raise StudyError(f"{where}{law} must be two finite numbers, got {bounds!r:.40}")
    a, b = float(bounds[0]), float(bounds[1])
    if law == "uniform" and not a < b:
        raise StudyError(f"{where}uniform needs low < high, got [{a}, {b}]")
    if law == "normal" and not b >= 0:
        raise StudyError(f"{where}normal needs std >= 0, got {b}")
    return law, a, b


def _draws(path: str, spec: Any, samples: int, generator: np.random.Generator) -> np.ndarray:
    """A ``[study.random]`` entry's values for the samples (seeds: no draw taken)."""
    law, a, b = _distribution(path, spec, samples)
    if law == "from":
        return np.arange(samples, dtype=float) + a
    if law == "uniform":
        return generator.uniform(a, b, samples)
    return generator.normal(a, b, samples)


_LAWS = ("uniform", "normal")


def _tidy(values: np.ndarray) -> np.ndarray:
    """Each of ``values`` that is a few units in the last place from a decimal of 12
    significant digits replaced by it (0.005, not linspace's 0.004999999999999999, so
    that ``.sel(0.005)`` finds it: the runs use these values); the others (2/3 of
    something) as they are."""
    short = np.array([float(f"{v:.12g}") for v in values])
    close = np.abs(short - values) <= 4 * np.spacing(np.abs(values))
    return np.where(close, short, values)


def _axis_values(path: str, spec: Any) -> np.ndarray:
    where = f"[study.axes] {path!r}: "
    if isinstance(spec, Mapping):
        _axis_count(path, spec)
        axis = _table(where, spec, _AXIS)
        if axis["spacing"] == "log":
            return _tidy(np.geomspace(axis["start"], axis["stop"], axis["count"]))
        return _tidy(np.linspace(axis["start"], axis["stop"], axis["count"]))
    if isinstance(spec, str) or not isinstance(spec, Sequence) or not spec:
        raise StudyError(f"{where}must be a list of numbers or {{start, stop, count}}")
    values = []
    for v in spec:
        if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
            raise StudyError(f"{where}must hold finite numbers, got {v!r:.40}")
        values.append(float(v))
    return np.asarray(values)


@dataclass
class Study:
    """A checked study of a scenario's sections (see the module docstring)."""

    data: dict[str, Any]
    settings: dict[str, Any]
    source: str = "<study>"
    base_dir: Path | None = None

    @property
    def shape(self) -> tuple[int, ...]:
        """The grid: one dimension per axis, then the samples if any."""
        grid = tuple(len(v) for v in self.settings["axes"].values())
        samples = self.settings.get("samples", 0)
        return (*grid, samples) if samples else grid

    @property
    def dims(self) -> list[str]:
        return list(self.settings["axes"]) + (["sample"] if self.settings.get("samples") else [])

    @property
    def runs(self) -> int:
        return int(np.prod(self.shape))

    def fingerprint(self) -> str:
        """A hash of everything that decides the results: the scenario, the version,
        and the contents of the files it reads (a recorded signal changed between an
        interrupted run and its resumption would otherwise mix two inputs)."""
        content: dict[str, Any] = {"data": _plain(self.data), "version": __version__}
        files: list[str | None] = []
        for e in self.data.get("excitation", None) or ():
            name = e.get("file") if isinstance(e, Mapping) else None
            if isinstance(name, str):
                path = Path(name)
                if self.base_dir is not None and not path.is_absolute():
                    path = self.base_dir / path
                try:
                    files.append(hashlib.sha256(path.read_bytes()).hexdigest())
                except OSError:
                    files.append(None)
        if files:
            content["files"] = files
        canonical = json.dumps(content, sort_keys=True, default=str)
        return hashlib.sha256(canonical.encode()).hexdigest()

    def chunks(self) -> list[range]:
        size = self.settings["chunk_size"]
        return [range(i, min(i + size, self.runs)) for i in range(0, self.runs, size)]

    def run_chunk(self, runs: range, threads: int = 0) -> dict[str, Any]:
        """The raw metrics of the runs ``runs`` (flat indices into the grid)."""
        prepared = _prepare({k: v for k, v in self.data.items() if k != "study"}, self.base_dir)
        axes = list(self.settings["axes"].values())
        random = self.settings.get("random", {})
        index = np.unravel_index(np.arange(runs.start, runs.stop), self.shape)
        columns = [axis[i] for axis, i in zip(axes, index, strict=False)]
        if random:
            columns += [draws[index[-1]] for draws in random.values()]
        values = np.column_stack(columns) if columns else np.zeros((0, 0))
        solver = prepared.solver
        s = self.settings
        raw: dict[str, Any] = run_study(
            prepared.binding_spec(),
            [list(prepared.initial[k]) for k in _INITIAL],
            paths=list(self.settings["axes"]) + list(random),
            values=np.ascontiguousarray(values.ravel(), dtype=float),
            method=solver["method"],
            dt=solver["dt"],
            rtol=solver["rtol"],
            atol=solver["atol"],
            beta=solver["beta"],
            gamma=solver["gamma"],
            spectral_radius=solver["spectral_radius"],
            max_steps=solver["max_steps"],
            energy_tolerance=solver["energy_tolerance"],
            analysis=s["analysis"],
            t_end=solver["t_end"],
            record_from=s["record_from"],
            settle_periods=s["settle_periods"],
            record_periods=s["record_periods"],
            tolerance=s["tolerance"],
            threads=threads,
            mean_square="rms" in base_metrics(s["metrics"]),
            stepping=s.get("stepping", "events"),
            orbit_periods=s.get("orbit_periods", 1),
        )
        return raw


_INITIAL = (
    "structure_displacement",
    "structure_velocity",
    "damper_displacement",
    "damper_velocity",
)


def _plain(value: Any) -> Any:
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, Mapping):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_plain(v) for v in value]
    return value


def study_of(
    data: Mapping[str, Any] | System, source: str = "<study>", base_dir: Path | None = None
) -> Study:
    """A :class:`Study` of a :class:`~vibroimpact.System` (its ``analyses["study"]``)
    or of a scenario's sections with a ``[study]`` section."""
    data, base_dir = sections_of(data, base_dir)
    arguments.text("source", source)
    base_dir = arguments.directory("base_dir", base_dir)
    if "study" not in data:
        raise StudyError(f"{source}: a study needs a [study] section with [study.axes]")
    settings = data["study"]
    if (
        "axes" in settings
        and isinstance(settings["axes"], Mapping)
        and all(isinstance(v, np.ndarray) for v in settings["axes"].values())
    ):
        checked = dict(settings)
    else:
        checked = study_settings(settings)
    output = data.get("output")
    output = output if isinstance(output, Mapping) else {}
    for name in checked["metrics"]:
        for kind in ("point", "moment"):
            if name.startswith(f"{kind}_") and not output.get(f"{kind}s"):
                raise StudyError(
                    f"[study] metrics: {name} needs [output] {kind}s (where to follow it)"
                )
    if checked["record_from"] is None:
        # The scenario's own window where [study] gives none, as a run of it records
        # (user trial: a study and a run of one scenario disagreed on a peak).
        window = output.get("record_from")
        checked["record_from"] = 0.0 if window is None else float(window)
    study = Study(dict(data), checked, source, base_dir)
    # The base scenario and every axis path are checked by a run of none.
    study.run_chunk(range(0, 0))
    if checked["analysis"] != "run":  # whole forcing periods
        try:
            check_axis_frequencies(data, checked["axes"], base_dir)
        except InvalidInputError as err:
            raise StudyError(f"{source}: {err}") from None
    return study


def check_axis_frequencies(
    data: Mapping[str, Any], axes: Mapping[str, Any], base_dir: Path | None = None
) -> None:
    """A study's axes of excitation frequencies (``"excitation.0.frequency"``): the
    lowest value of each, in the study's base scenario, checked as an analysis's forcing
    period is (the error names the axis)."""
    for path, values in axes.items():
        parts = str(path).split(".")
        if len(parts) != 3 or parts[0] != "excitation" or parts[2] != "frequency":
            continue
        lowest = float(np.min(np.asarray(values, dtype=float)))
        changed = with_parameter(data, str(path), lowest)
        try:
            period = forcing_period(changed)
            check_forcing_period(changed, period, _prepare(changed, base_dir).solver["max_steps"])
        except InvalidInputError as err:
            if not str(err).startswith("forcing frequency"):
                continue  # the study's own check of the axis says what else is wrong
            raise InvalidInputError(f"[study.axes] {path!r}: {err}") from None


def assemble(study: Study, parts: list[dict[str, Any]]) -> Any:
    """The study's xarray Dataset from its chunks' raw metrics, in order."""
    import xarray as xr

    n = parts[0]["n"] if parts else 0
    pairs = list(parts[0]["pairs"]) if parts else []
    output = study.data.get("output", {})
    output = output if isinstance(output, Mapping) else {}
    at = np.asarray(output.get("points", ()), dtype=float)
    moment_at = np.asarray(output.get("moments", ()), dtype=float)
    shape = study.shape
    dims = study.dims
    # Each distinct reason once, numbered in order of first failure (a dict: a study
    # of millions of failures, each quoting its own value, is linear, not quadratic).
    numbers: dict[str, int] = {}
    status = np.concatenate([np.asarray(p["status"], dtype=np.int16) for p in parts])
    codes = np.zeros(len(status), dtype=np.int32)
    flat_reasons = [r for p in parts for r in p["reason"]]
    for i, (s, reason) in enumerate(zip(status, flat_reasons, strict=True)):
        if s:
            codes[i] = numbers.setdefault(reason, len(numbers) + 1)
    reasons = list(numbers)
    data_vars: dict[str, Any] = {
        "status": (
            dims,
            codes.reshape(shape),
            {"long_name": "0: run completed; k: failed for the k-th of attrs reasons"},
        )
    }
    for name in base_metrics(study.settings["metrics"]):
        key = "peak" if name == "amplitude" else name
        values = np.concatenate([np.asarray(p[key], dtype=float) for p in parts])
        description, unit = _DESCRIPTIONS[name]
        attrs = {"long_name": description, "units": unit}
        if name in _FLAGS:
            # Kept as 1 / 0 in the chunks (NaN for a failed run, which status marks).
            values = values == 1.0
            attrs = {"long_name": description}
        if name in PER_COORDINATE:
            values = values.reshape(*shape, n + len(at) + len(moment_at))
            coordinates, at_points, at_moments = split_observed(values, n, len(at))
            data_vars[name] = ([*dims, "coordinate"], coordinates, attrs)
            for kind, dim, part, units, long_name in (
                (
                    "point",
                    "at",
                    at_points,
                    unit,
                    description.replace(
                        "each structure coordinate", "the structure at each [output] point"
                    ),
                ),
                (
                    "moment",
                    "moment_at",
                    at_moments,
                    "N m",
                    description.replace("displacement", "bending moment").replace(
                        "each structure coordinate", "each of [output] moments"
                    ),
                ),
            ):
                if part.shape[-1]:
                    data_vars[f"{kind}_{name}"] = (
                        [*dims, dim],
                        part,
                        {"long_name": long_name, "units": units},
                    )
        elif name == "energy_dissipated":
            data_vars[name] = ([*dims, "pair"], values.reshape(*shape, len(pairs)), attrs)
        else:
            data_vars[name] = (dims, values.reshape(shape), attrs)
    from vibroimpact.datasets import parameter_units

    coords: dict[str, Any] = {}
    for path, values in study.settings["axes"].items():
        axis_unit = parameter_units(path, study.data)
        coords[path] = (path, values, {"units": axis_unit} if axis_unit else {})
    if study.settings.get("samples"):
        coords["sample"] = ("sample", np.arange(study.settings["samples"]))
        for path, draws in study.settings["random"].items():
            axis_unit = parameter_units(path, study.data)
            long_name = (
                f"{path}, the seed of each sample's signal"
                if _is_seed(path)
                else f"{path}, drawn for each sample (seed {study.settings['seed']})"
            )
            data_vars[path] = (
                ["sample"],
                draws,
                {
                    "long_name": long_name,
                    **({"units": axis_unit} if axis_unit else {}),
                },
            )
    coords["coordinate"] = ("coordinate", np.arange(n))
    if len(at):
        coords["at"] = ("at", at, {"long_name": "point of the structure ([output] points)"})
    if len(moment_at):
        coords["moment_at"] = (
            "moment_at",
            moment_at,
            {"long_name": "position of a bending moment ([output] moments)", "units": "m"},
        )
    coords["pair"] = ("pair", np.array(pairs, dtype=str))
    return xr.Dataset(
        data_vars,
        coords=coords,
        attrs={
            "title": f"vibroimpact study of {study.source}",
            "vibroimpact_version": __version__,
            "scenario": json.dumps(_plain(study.data), sort_keys=True, default=str),
            "input_hash": study.fingerprint(),
            "analysis": study.settings["analysis"],
            "reasons": json.dumps(reasons),
        },
    )


_METRIC_KEYS = (
    "peak",
    "rms",
    "impacts",
    "energy_dissipated",
    "impacts_per_period",
    "settled",
    "stable",
    "largest_multiplier",
)


def chunk_part(study: Study, start: int, stop: int, threads: int = 0) -> dict[str, Any]:
    """The metrics of runs ``start`` to ``stop`` as arrays (what a chunk file holds and
    a Dask task returns)."""
    arguments.instance("study", study, Study, "vibroimpact.study.study_of(sections)")
    start, stop = whole_count("start", start, 0), whole_count("stop", stop, 0)
    check_threads(threads, "threads:")
    raw = study.run_chunk(range(start, stop), threads)
    return {
        "n": np.int64(raw["n"]),
        "pairs": np.array(list(raw["pairs"]), dtype=str),
        "status": np.asarray(raw["status"], dtype=np.int16),
        "reason": np.array(list(raw["reason"]), dtype=str),
        **{key: np.asarray(raw[key], dtype=float) for key in _METRIC_KEYS},
    }


def _save(path: Path, part: dict[str, Any]) -> None:
    import io

    buffer = io.BytesIO()
    np.savez(buffer, **part)
    with written_whole(path, binary=True) as f:
        f.write(buffer.getvalue())


def _load(path: Path) -> dict[str, Any]:
    # The file opened here, closed here: np.load leaves a damaged one open.
    with path.open("rb") as f, np.load(f, allow_pickle=False) as data:
        part = {key: data[key] for key in data.files}
    part["n"] = int(part["n"])
    part["pairs"] = [str(p) for p in part["pairs"]]
    part["reason"] = [str(r) for r in part["reason"]]
    return part


def run(
    study: Study,
    out: Path,
    *,
    threads: int = 0,
    progress: Callable[[int, int, float], None] | None = None,
    dask: str | None = None,
    notice: Callable[[str], None] | None = None,
    resume: str = "run the same study into the same output again",
) -> Any:
    """Run ``study`` into ``out``, by its suffix the NetCDF file ``RESULT.nc`` or the
    Zarr store ``RESULT.zarr`` (needs zarr; see :func:`output_kind`), chunk by chunk:
    each finished chunk is kept in ``OUT.parts/`` (written whole), so a study
    interrupted or killed loses at most the chunks in flight and, run again, goes on
    where it stopped; the output is written whole at the end (the same file or store as
    an uninterrupted run) and the parts removed. ``dask``: the address of a Dask
    scheduler, or ``"local"`` for a LocalCluster of ``threads`` processes (all cores for
    0), the chunks its tasks; the results are the same. A run that resumes says so to
    ``notice`` (one line: the chunks kept before); a run that stops (interrupted, or
    failed) with chunks kept gets a note (:meth:`BaseException.add_note`) saying how
    many and how to resume (``resume``). Returns the Dataset."""
    arguments.instance("study", study, Study, "vibroimpact.study.study_of(sections)")
    out = arguments.path("out", out)
    for name, function in (("progress", progress), ("notice", notice)):
        arguments.callback(name, function)
    if dask is not None:
        arguments.text("dask", dask)
    arguments.text("resume", resume)
    check_threads(threads, "threads:")
    kind = output_kind(out)
    # What a killed write left: an earlier store moved aside is back before any run.
    remove_stale(out.resolve() if out.is_symlink() else out)
    parts_dir = out.with_name(out.name + ".parts")
    fingerprint = study.fingerprint()
    manifest = parts_dir / "manifest.json"
    if parts_dir.exists():
        try:
            known = json.loads(manifest.read_text())
        except (OSError, ValueError):
            known = {}
        if known.get("input_hash") != fingerprint:
            raise UsageError(
                f"{parts_dir} holds the chunks of another study (or is damaged): remove it "
                "to start this one"
            )
    else:
        try:
            parts_dir.mkdir()
        except OSError as err:
            raise UsageError(f"cannot write {str(parts_dir)!r}: {err.strerror or err}") from None
        with written_whole(manifest) as f:
            f.write(json.dumps({"input_hash": fingerprint, "runs": study.runs}))
    chunks = study.chunks()
    path_of = [parts_dir / f"chunk-{number:06d}.npz" for number in range(len(chunks))]
    parts: dict[int, dict[str, Any]] = {}
    for number, path in enumerate(path_of):
        if path.exists():
            try:
                parts[number] = _load(path)
            except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile):
                # Written whole, so damaged since (a disk, a hand): run it again.
                pass
    pending = [number for number in range(len(path_of)) if number not in parts]
    if parts and notice is not None:
        notice(
            f"resuming from {parts_dir}: {_kept(study, chunks, path_of)} by an earlier run, "
            f"{len(pending)} chunks to run"
        )
    start = time.perf_counter()
    state = {"computed": 0, "done": study.runs - sum(len(chunks[i]) for i in pending)}

    def finished(number: int, part: dict[str, Any]) -> None:
        _save(path_of[number], part)
        # As a resumed study reads it (the same types).
        parts[number] = _load(path_of[number])
        state["computed"] += len(chunks[number])
        state["done"] += len(chunks[number])
        if progress is not None:
            rate = state["computed"] / max(time.perf_counter() - start, 1e-9)
            progress(state["done"], study.runs, rate)

    try:
        if dask is None:
            for number in pending:
                runs = chunks[number]
                finished(number, chunk_part(study, runs.start, runs.stop, threads))
        else:
            _run_on_dask(study, chunks, pending, dask, threads, finished)
        dataset = assemble(study, [parts[number] for number in range(len(path_of))])
        if kind == ".zarr":
            _write_zarr(dataset, out)
        else:
            with written_whole(out, binary=True) as f:
                f.write(dataset.to_netcdf(engine="scipy"))
    except BaseException as stop:
        if any(path.exists() for path in path_of):
            stop.add_note(
                f"{_kept(study, chunks, path_of)}, kept in {parts_dir}; to resume, {resume}"
            )
        else:
            # Nothing finished: leave nothing behind (a resume has nothing to go on).
            shutil.rmtree(parts_dir, ignore_errors=True)
            if not isinstance(stop, Exception):  # interrupted, not an error's one line
                stop.add_note(
                    f"{_kept(study, chunks, path_of)}: nothing kept, run again it starts afresh"
                )
        raise
    shutil.rmtree(parts_dir, ignore_errors=True)
    return dataset


def _kept(study: Study, chunks: list[range], path_of: list[Path]) -> str:
    """How much of the study its kept chunks hold (``2 of 4 chunks (8 of 16 runs)
    done``)."""
    kept = [runs for runs, path in zip(chunks, path_of, strict=True) if path.exists()]
    done = sum(len(runs) for runs in kept)
    return f"{len(kept)} of {len(chunks)} chunks ({done} of {study.runs} runs) done"


# What a study's output may end in, and what each suffix writes.
OUTPUTS = {".nc": "a NetCDF file", ".zarr": "a Zarr store"}


def output_kind(out: Path) -> str:
    """The suffix of ``out`` that decides its format (``.nc`` or ``.zarr``), checked
    before a study runs: another suffix, a Zarr store without the zarr package, or a
    ``.zarr`` path that holds something other than a Zarr store (which the store
    would replace) raise :class:`UsageError`."""
    out = arguments.path("out", out)
    kind = out.suffix.lower()
    if kind not in OUTPUTS:
        allowed = " or ".join(f"{suffix} ({what})" for suffix, what in OUTPUTS.items())
        raise UsageError(f"--out {out}: must end in {allowed}")
    if kind == ".zarr":
        try:
            importlib.import_module("zarr")
        except ImportError:
            raise UsageError(
                f'--out {out}: a Zarr store needs zarr: pip install "vibroimpact[zarr]"'
            ) from None
        _replaceable_store(out)
    return kind


def _replaceable_store(out: Path) -> None:
    """Refuse a ``.zarr`` path that holds a file, or a folder that is neither empty nor
    a Zarr store: writing the study there would replace what is not a result."""
    if out.is_symlink():
        out = out.resolve()
    if not out.exists():
        return
    if out.is_dir() and (
        not any(out.iterdir()) or any((out / name).is_file() for name in _STORE_MARKS)
    ):
        return
    raise UsageError(
        f"--out {out}: exists and is not a Zarr store; remove it or choose another name"
    )


# What marks a folder as a Zarr store: format 2's group or consolidated metadata, or 3's.
_STORE_MARKS = (".zgroup", ".zmetadata", "zarr.json")


def _write_zarr(dataset: Any, out: Path) -> None:
    """Write ``dataset`` as the Zarr store ``out`` whole or not at all: built in a hidden
    folder beside ``out`` (so that the rename cannot cross file systems), its files on
    disk, then swapped in (:func:`vibroimpact.output.swap_in`: on Linux one atomic
    exchange, ``out`` never missing), the earlier store removed once the new one stands
    in its place. A write that fails or is interrupted removes the folder and leaves
    ``out`` as it was; what a killed one leaves (the folder, or elsewhere an earlier
    store moved aside) the next write removes (or puts back, where ``out`` is missing).

    Zarr format 2 with consolidated metadata: its specification covers every dtype of
    the Dataset (format 3 has none yet for fixed-width strings, and zarr warns), and
    ``xr.open_zarr`` reads it in one request, with no warning."""
    if out.is_symlink():
        # Replace the store the link points to, and keep the link.
        out = out.resolve()
    remove_stale(out)
    _replaceable_store(out)
    # The new store's folder until it is swapped in, then the earlier store's.
    held: list[Path] = []
    lock: int | None = None
    try:
        lock = claim_beside(out, held, folder=True)
        # Into the empty folder made (and locked) above: "w" would make it again.
        dataset.to_zarr(held[0], mode="w-", zarr_format=2, consolidated=True)
        _sync(held[0])
        earlier = swap_in(held[0], out)
        held[:] = [] if earlier is None else [earlier]
        _sync_folder(out.parent)
    except OSError as err:
        raise UsageError(f"cannot write {str(out)!r}: {err.strerror or err}") from None
    finally:
        if lock is not None:
            os.close(lock)
        for folder in held:
            shutil.rmtree(folder, ignore_errors=True)


def _sync(folder: Path) -> None:
    """The files below ``folder`` and the folders themselves on disk."""
    for root, _, files in os.walk(folder):
        for name in files:
            with open(os.path.join(root, name), "rb") as f:
                os.fsync(f.fileno())
        _sync_folder(Path(root))


def _sync_folder(folder: Path) -> None:
    # A folder's entries on disk, where the system can (not on Windows).
    try:
        descriptor = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(descriptor)
    except OSError:
        pass
    finally:
        os.close(descriptor)


def _run_on_dask(
    study: Study,
    chunks: list[range],
    pending: list[int],
    address: str,
    workers: int,
    finished: Callable[[int, dict[str, Any]], None],
) -> None:
    """The pending chunks as tasks of a Dask cluster, each kept as it completes."""
    try:
        # Untyped: taken as Any.
        distributed: Any = importlib.import_module("dask.distributed")
    except ImportError:
        raise UsageError(
            '--dask needs dask and distributed: pip install "vibroimpact[dask]"'
        ) from None
    cluster = None
    try:
        if address == "local":
            cluster = distributed.LocalCluster(
                n_workers=workers or os.cpu_count() or 1,
                threads_per_worker=1,
                processes=True,
                dashboard_address=None,
                # Its workers' own messages (an interrupt stops them too) are noise.
                silence_logs=logging.CRITICAL,
            )
            client = distributed.Client(cluster)
        else:
            client = distributed.Client(address, timeout="10s")
    except (OSError, ValueError, TypeError) as err:
        raise UsageError(
            f"--dask {address}: cannot reach the scheduler ({err}); give 'local' or an "
            "address such as tcp://HOST:8786"
        ) from None
    try:
        shared = client.scatter(study, broadcast=True)
        futures = {
            client.submit(chunk_part, shared, chunks[n].start, chunks[n].stop, 1, pure=False): n
            for n in pending
        }
        for future in distributed.as_completed(futures):
            finished(futures[future], future.result())
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def terminal_progress(stream: Any = sys.stderr) -> Callable[[int, int, float], None]:
    """A progress line with the rate and the time left, on a terminal only."""
    show = hasattr(stream, "isatty") and stream.isatty()

    def progress(done: int, total: int, rate: float) -> None:
        if not show:
            return
        left = (total - done) / rate if rate > 0 else math.inf
        eta = f"{left:.0f} s left" if math.isfinite(left) else ""
        stream.write(f"\r{done}/{total} runs, {rate:,.0f} runs/s, {eta}   ")
        stream.flush()
        if done == total:
            stream.write("\n")

    return progress
