"""The ``[study]`` section checked, with its defaults: the analysis, the metrics it
keeps, the periods, the chunks, the samples and the stepping; its axes and draws made
(:mod:`vibroimpact.study.axes`)."""

from __future__ import annotations

import difflib
import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from vibroimpact import arguments
from vibroimpact.analysis.limits import MAX_PERIODS, AnalysisError, check_total
from vibroimpact.model.system import ANALYSIS_CHECKS
from vibroimpact.study.axes import (
    _axis_count,
    _axis_values,
    _check_path,
    _check_seeds,
    _distribution,
    _draws,
    _is_seed,
)
from vibroimpact.study.limits import MAX_STUDY_RUNS, StudyError
from vibroimpact.system import (
    _NUMBER,
    _TEXT,
    _WHOLE,
    SYSTEM_SOLVER_DEFAULTS,
    _choice,
    _table,
)

# A chunk holds at least one run (its range stated by the whole-number check itself).
arguments.WHOLE_RANGES["[study] chunk_size"] = (1, arguments.LARGEST_WHOLE)

# What each analysis keeps; every metric.
_RUN_METRICS = ("peak", "rms", "impacts", "energy_dissipated", "largest_lyapunov")
_STEADY_METRICS = (*_RUN_METRICS, "amplitude", "impacts_per_period", "settled")
#: What an orbit study keeps by default.
_ORBIT_DEFAULT = ("amplitude", "impacts_per_period", "stable", "largest_multiplier")
_ANALYSIS_METRICS = {
    "run": _RUN_METRICS,
    "steady-state": _STEADY_METRICS,
    "orbit": (*_ORBIT_DEFAULT, "largest_lyapunov"),
}
#: Every metric a study can keep (each analysis keeps some of them).
METRICS = (*_STEADY_METRICS, "stable", "largest_multiplier")
_ANALYSES = tuple(_ANALYSIS_METRICS)
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
    # A study's runs step as any system's do unless [study] stepping = "fixed" (the core
    # registry's default, RUN_DEFAULTS["system"]).
    "stepping": (_TEXT, SYSTEM_SOLVER_DEFAULTS["stepping"]),
}
_STEPPINGS = ("events", "fixed")
# What a lockstep ensemble of fixed steps keeps.
_FIXED_METRICS = ("peak", "rms", "impacts")


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
    default = _ORBIT_DEFAULT if out["analysis"] == "orbit" else _FIXED_METRICS
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
    # Their lower bounds are the whole-number check's (WHOLE_RANGES, the analyses'
    # settings'); its upper bound is each key's own.
    for key in ("settle_periods", "record_periods", "orbit_periods"):
        if out[key] > MAX_PERIODS:
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
    _check_clearances([*counts, *map(str, random)])
    runs = math.prod(counts.values()) * max(out["samples"], 1)
    if runs > MAX_STUDY_RUNS:
        sizes = " x ".join(f"{path} {count}" for path, count in counts.items())
        keys = "[study.axes] count"
        if out["samples"]:
            sizes += f" x samples {out['samples']}"
            keys = "[study] samples, [study.axes] count"
        raise StudyError(
            # Whole: 1e+07 of 10,010,001 had read as the limit itself.
            f"{keys}: the study would make {runs:,} runs ({sizes}), more than "
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


ANALYSIS_CHECKS["study"] = checked_study_settings


def _check_clearances(paths: list[str]) -> None:
    """Refuse a damper's ``clearance`` varied beside its ``lower_clearance`` or
    ``upper_clearance``, as a scenario is refused for giving both: the runs took one
    and the coordinates said the other."""
    for path in paths:
        parts = path.split(".")
        if len(parts) == 3 and parts[0] == "damper" and parts[2] == "clearance":
            for side in ("lower_clearance", "upper_clearance"):
                other = f"damper.{parts[1]}.{side}"
                if other in paths:
                    raise StudyError(
                        f"[study] {path!r} and {other!r}: vary clearance (each side) or "
                        f"{side}, not both"
                    )
