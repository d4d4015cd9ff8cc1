"""A study's xarray Dataset assembled from its chunks' metrics: a dimension per axis,
the metrics as variables with their units, ``status`` and the reasons of failed runs."""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from vibroimpact._core import __version__
from vibroimpact.study.axes import _is_seed
from vibroimpact.study.grid import Study, _plain
from vibroimpact.study.settings import PER_COORDINATE, base_metrics
from vibroimpact.system import split_observed
from vibroimpact.units import parameter_units

# The metrics that are yes or no: booleans in the Dataset.
_FLAGS = ("settled", "stable")
# What each metric means and its unit (attrs of the Dataset's variables).
_DESCRIPTIONS = {
    "peak": ("largest |displacement| of each structure coordinate, recorded", "m"),
    "rms": ("RMS displacement of each structure coordinate, recorded", "m"),
    "impacts": ("impacts and compliant contacts recorded (sticking not counted)", "1"),
    "energy_dissipated": (
        "energy taken by each pair's contacts and impacts (a friction element's: its "
        "sliding), recorded",
        "J",
    ),
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
    "largest_lyapunov": (
        "largest Lyapunov exponent, by the tangent flow through the impacts over the "
        "recorded time (an orbit's: ln |largest multiplier| / its period; > 0: chaos)",
        "1/s",
    ),
}


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
        # A cantilever's point is a position along it; another structure's, a coordinate.
        point_units = {"units": "m"} if study.data["structure"].get("kind") == "cantilever" else {}
        coords["at"] = (
            "at",
            at,
            {"long_name": "point of the structure ([output] points)", **point_units},
        )
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
            "scenario": json.dumps(
                _finite(_plain(study.data)), sort_keys=True, default=str, allow_nan=False
            ),
            "input_hash": study.fingerprint(),
            "analysis": study.settings["analysis"],
            "reasons": json.dumps(reasons),
        },
    )


def _finite(value: Any) -> Any:
    """``value`` with each non-finite number written as TOML writes it (``"inf"``,
    ``"-inf"``, ``"nan"``): strict JSON has none (an infinite clearance had been written
    ``Infinity``, which strict readers refuse)."""
    if isinstance(value, float) and not math.isfinite(value):
        return "nan" if math.isnan(value) else ("inf" if value > 0 else "-inf")
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_finite(v) for v in value]
    return value
