"""A checked study: its grid of runs (one dimension per axis, then the samples), split
into chunks, a chunk run by the core (rayon, the GIL released) into its metrics."""

from __future__ import annotations

import hashlib
import json
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from vibroimpact import arguments
from vibroimpact._core import InvalidInputError, __version__, run_study
from vibroimpact.analysis.limits import whole_count
from vibroimpact.analysis.parameters import forcing_period, with_parameter
from vibroimpact.analysis.runs import _prepare
from vibroimpact.model.system import System, sections_of
from vibroimpact.study.beam_axes import beam_corners, resolve_beam_axes
from vibroimpact.study.limits import StudyError, check_study_memory, check_threads
from vibroimpact.study.settings import base_metrics, study_settings
from vibroimpact.system.run import check_record_window


@dataclass
class Study:
    """A checked study of a scenario's sections (see :mod:`vibroimpact.study`)."""

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
        # The [study] table as checked, its defaults filled in: a scenario's own table
        # (the command line's) and a System's (vi.load's) had hashed apart, and a study
        # begun one way could not be resumed the other.
        data = {key: value for key, value in self.data.items() if key != "study"}
        content: dict[str, Any] = {
            "data": _plain(data),
            "study": _plain(self.settings),
            "version": __version__,
        }
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

    def prepared(self) -> Any:
        """The base scenario prepared as a run of it is (its sections but ``[study]``)."""
        return _prepare({k: v for k, v in self.data.items() if k != "study"}, self.base_dir)

    def run_chunk(self, runs: range, threads: int = 0) -> dict[str, Any]:
        """The raw metrics of the runs ``runs`` (flat indices into the grid)."""
        prepared = self.prepared()
        axes = list(self.settings["axes"].values())
        random = self.settings.get("random", {})
        index = np.unravel_index(np.arange(runs.start, runs.stop), self.shape)
        columns = [axis[i] for axis, i in zip(axes, index, strict=False)]
        if random:
            columns += [draws[index[-1]] for draws in random.values()]
        values = np.column_stack(columns) if columns else np.zeros((0, 0))
        paths = list(self.settings["axes"]) + list(random)
        if len(values):
            paths, values = resolve_beam_axes(self.data["structure"], paths, values)
        elif paths:
            # No run: the beam's axes checked at the corners of their ranges.
            every = [*axes, *random.values()]
            paths = resolve_beam_axes(self.data["structure"], paths, beam_corners(paths, every))[0]
            values = np.zeros((0, len(paths)))
        solver = prepared.solver
        s = self.settings
        raw: dict[str, Any] = run_study(
            prepared.binding_spec(),
            [list(prepared.initial[k]) for k in _INITIAL],
            paths=paths,
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
            # None: the core registry's default stepping.
            stepping=s.get("stepping"),
            orbit_periods=s.get("orbit_periods", 1),
            # The tangent flow is carried only where its exponent is kept (an orbit's
            # comes from its multipliers).
            lyapunov="largest_lyapunov" in s["metrics"] and s["analysis"] != "orbit",
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


@arguments.typed()
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
    # Always checked: axes given as arrays (from Python) were once taken as checked,
    # and a chunk size of 0 or an unknown metric failed after the runs.
    checked = study_settings(data["study"])
    output = data.get("output")
    output = output if isinstance(output, Mapping) else {}
    for name in checked["metrics"]:
        for kind in ("point", "moment"):
            if name.startswith(f"{kind}_") and not _count(output, f"{kind}s"):
                raise StudyError(
                    f"[study] metrics: {name} needs [output] {kind}s (where to follow it)"
                )
    if checked["record_from"] is None:
        # The scenario's own window where [study] gives none, as a run of it records
        # (user trial: a study and a run of one scenario disagreed on a peak).
        window = output.get("record_from")
        checked["record_from"] = 0.0 if window is None else float(window)
    study = Study(dict(data), checked, source, base_dir)
    if checked["analysis"] == "run":
        # As a single run refuses it (every run would record nothing); the study's
        # stepping, not the scenario's, says whether its steps are fixed.
        stepped = {**study.prepared().solver, "stepping": checked["stepping"]}
        try:
            check_record_window("[study] record_from: ", checked["record_from"], stepped)
        except InvalidInputError as err:
            raise StudyError(f"{source}: {err}") from None
    # The base scenario and every axis path are checked by a run of none.
    try:
        shape = study.run_chunk(range(0, 0))
    except InvalidInputError as err:
        # The core names each varied path a study axis: a drawn one is named where it is.
        text = str(err)
        for path in checked.get("random", {}):
            text = text.replace(
                f"study axis {json.dumps(str(path))}", f"[study.random] {str(path)!r}"
            )
        if text == str(err):
            raise
        raise type(err)(text) from None
    # Each structure coordinate, then each followed point and moment.
    followed = _count(output, "points") + _count(output, "moments")
    check_study_memory(study.runs, int(shape["n"]) + followed, len(shape["pairs"]), source)
    if checked["analysis"] != "run":  # whole forcing periods
        try:
            check_axis_frequencies(data, checked["axes"], base_dir)
        except InvalidInputError as err:
            raise StudyError(f"{source}: {err}") from None
    return study


def _count(output: Mapping[str, Any], key: str) -> int:
    """How many ``[output]`` ``key`` (points, moments) holds: a list, a tuple or a numpy
    array (sections built in Python), or none."""
    value = output.get(key)
    return 0 if value is None else len(value)


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
            _prepare(changed, base_dir).check_forcing_period(period)
        except InvalidInputError as err:
            if not str(err).startswith("forcing frequency"):
                continue  # the study's own check of the axis says what else is wrong
            raise InvalidInputError(f"[study.axes] {path!r}: {err}") from None


_METRIC_KEYS = (
    "peak",
    "rms",
    "impacts",
    "energy_dissipated",
    "impacts_per_period",
    "settled",
    "stable",
    "largest_multiplier",
    "largest_lyapunov",
)


def chunk_part(study: Study, start: int, stop: int, threads: int = 0) -> dict[str, Any]:
    """The metrics of runs ``start`` to ``stop`` as arrays (what a chunk file holds and
    a Dask task returns)."""
    arguments.instance("study", study, Study, "vibroimpact.study.study_of(sections)")
    # Flat indices into the grid (a stop past it was numpy's bare IndexError).
    stop = whole_count("stop", stop, 0, study.runs)
    start = whole_count("start", start, 0, stop)
    check_threads(threads, "threads:")
    raw = study.run_chunk(range(start, stop), threads)
    return {
        "n": np.int64(raw["n"]),
        "pairs": np.array(list(raw["pairs"]), dtype=str),
        "status": np.asarray(raw["status"], dtype=np.int16),
        "reason": np.array(list(raw["reason"]), dtype=str),
        **{key: np.asarray(raw[key], dtype=float) for key in _METRIC_KEYS},
    }
