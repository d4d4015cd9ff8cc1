"""Comparisons the orbit tests share: states relative to their own scale, and
eigenvalue sets paired at best."""

from __future__ import annotations

import itertools
from typing import Any

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]


def spectrum_distance(actual: NDArray[Any], expected: NDArray[Any]) -> float:
    """The largest distance between two sets of eigenvalues, best paired."""
    a = np.asarray(actual, dtype=complex)
    b = np.asarray(expected, dtype=complex)
    assert a.shape == b.shape
    return min(
        float(np.max(np.abs(a[list(p)] - b), initial=0.0))
        for p in itertools.permutations(range(len(a)))
    )


def state_error(actual: Array, expected: Array) -> float:
    """max |actual - expected|, displacements and velocities each relative to the
    largest |value| of ``expected`` of their kind."""
    d = len(expected) // 2
    x_scale = float(np.max(np.abs(expected[:d])))
    v_scale = float(np.max(np.abs(expected[d:])))
    return max(
        float(np.max(np.abs(actual[:d] - expected[:d]))) / x_scale,
        float(np.max(np.abs(actual[d:] - expected[d:]))) / v_scale,
    )
