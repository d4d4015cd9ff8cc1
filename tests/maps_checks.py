"""The closed forms and example files that the tests of the forced-response maps
(test_maps.py, on the API; test_maps_cli.py, on the commands) share: the ball on the
vibrating table (Holmes 1982) as :class:`Table`, and the examples' paths.
"""

from __future__ import annotations

import math
import subprocess
import tomllib
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import brentq, minimize_scalar

Array = NDArray[np.float64]
RunCli = Callable[..., subprocess.CompletedProcess[str]]
ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
CONTINUATION = EXAMPLES / "ball_table_continuation.toml"
BIFURCATION = EXAMPLES / "ball_table_bifurcation.toml"
BASINS = EXAMPLES / "ball_table_basins.toml"
BALL_TABLE = EXAMPLES / "bouncing_ball_table.toml"
AMPLITUDE = "excitation.0.amplitude"
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
PNG_END = b"IEND\xaeB`\x82"


def load(path: Path) -> dict[str, Any]:
    with path.open("rb") as f:
        return tomllib.load(f)


def angle_between(a: Array, b: float) -> Array:
    """|a - b| as angles, in [0, pi]."""
    out: Array = np.abs(np.angle(np.exp(1j * (np.asarray(a) - b))))
    return out


def bounded_max(f: Callable[[float], float], low: float, high: float) -> float:
    """The largest value of a smooth ``f`` over [low, high]: sampled, then refined."""
    grid = np.linspace(low, high, 20001)
    values = np.array([f(float(t)) for t in grid])
    i = int(np.argmax(values))
    a, b = grid[max(i - 1, 0)], grid[min(i + 1, len(grid) - 1)]
    found = minimize_scalar(lambda t: -f(t), bounds=(a, b), method="bounded")
    return max(float(values[i]), -float(found.fun))


class Table:
    """The ball-on-table scenario of an example: restitution, gravity, frequency and
    the base acceleration's amplitude A and phase p."""

    def __init__(self, data: dict[str, Any]) -> None:
        (stop,) = data["stop"]
        (exc,) = data["excitation"]
        assert stop["law"] == "rigid" and stop["side"] == "lower" and stop["gap"] == 0.0
        assert exc["kind"] == "base" and exc["signal"] == "harmonic"
        assert data["structure"]["stiffness"] == 0.0
        self.e = float(stop["restitution"])
        self.g = float(data["gravity"]["acceleration"])
        self.f = float(exc["frequency"])
        self.w = 2 * math.pi * self.f
        self.period = 1 / self.f
        self.big_a = float(exc["amplitude"])
        self.p = float(exc["phase"])
        self.tm = (self.p - math.pi / 2) / self.w  # the table is a sin(w (t + tm))

    def gamma(self, big_a: float | None = None) -> float:
        return (self.big_a if big_a is None else big_a) / self.g

    def flip(self) -> float:
        """Gamma_flip: the period-one orbit's multiplier reaches -1."""
        e = self.e
        return math.hypot(math.pi * (1 - e) / (1 + e), 2 * (1 + e**2) / (1 + e) ** 2)

    def phi(self, gamma: float) -> float:
        """The impact phase of w (t + tm) on the stable branch, sin(phi) > 0."""
        return math.acos(math.pi * (1 - self.e) / ((1 + self.e) * gamma))

    def closing(self) -> float:
        return 2 * math.pi * self.g / (self.w * (1 + self.e))

    def _flight(self, gamma: float) -> tuple[float, float, float]:
        """Impact time t0 (absolute clock, table a sin(w t)), table amplitude a, and
        the ball's absolute speed just after the impact."""
        a = gamma * self.g / self.w**2
        t0 = self.phi(gamma) / self.w
        up = a * self.w * math.cos(self.w * t0) + self.e * self.closing()
        return t0, a, up

    def relative(self, gamma: float, delta: float) -> tuple[float, float]:
        """Ball minus table, ``delta`` after the impact on the period-one orbit."""
        t0, a, up = self._flight(gamma)
        w, g = self.w, self.g
        x = a * math.sin(w * t0) + up * delta - g * delta**2 / 2 - a * math.sin(w * (t0 + delta))
        v = up - g * delta - a * w * math.cos(w * (t0 + delta))
        return x, v

    def orbit_state(self, gamma: float) -> Array:
        """The period-one orbit's relative state at the scenario's t = 0."""
        t0 = self.phi(gamma) / self.w
        return np.array(self.relative(gamma, (self.tm - t0) % self.period), dtype=float)

    def amplitude(self, gamma: float) -> float:
        """The largest height of the ball above the table over the orbit: at a zero of
        the relative velocity, to round-off (the sampled maximum refined by a bounded
        search had ~1e-9 of it, too coarse for a difference of two amplitudes)."""
        grid = np.linspace(0.0, self.period, 2001)
        v = np.array([self.relative(gamma, float(d))[1] for d in grid])
        tops = [
            brentq(lambda d: self.relative(gamma, d)[1], grid[i], grid[i + 1], xtol=1e-16)
            for i in np.flatnonzero((v[:-1] > 0) & (v[1:] <= 0))
        ]
        return max(self.relative(gamma, float(t))[0] for t in tops)

    def jacobian(self, gamma: float) -> Array:
        e = self.e
        s = gamma * math.sin(self.phi(gamma))
        return np.array([[1.0, 1 + e], [-(1 + e) * s, e**2 - (1 + e) ** 2 * s]])

    def impact_phase(self, gamma: float) -> float:
        """The impacts' phase in the forcing period of the scenario's clock."""
        return (self.phi(gamma) - self.w * self.tm) % (2 * math.pi)


def release_flight_amplitude(table: Table) -> float:
    """A ball resting on the table leaves it when the table's downward acceleration
    first exceeds g; the height it reaches before landing again."""
    big_a, w, p, g = table.big_a, table.w, table.p, table.g
    # Free, the relative acceleration is -g - A cos(w t + p): it turns positive at
    # w t + p = acos(-g / A) (mod 2 pi).
    ts = ((math.acos(-g / big_a) - p) % (2 * math.pi)) / w

    def x(t: float) -> float:
        tau = t - ts
        return (
            -g * tau**2 / 2
            + big_a / w**2 * (math.cos(w * t + p) - math.cos(w * ts + p))
            + big_a / w * math.sin(w * ts + p) * tau
        )

    grid = np.linspace(ts, ts + table.period, 20001)[1:]
    heights = np.array([x(float(t)) for t in grid])
    landing = float(grid[int(np.argmax(heights < 0))])
    assert heights[0] > 0 and landing < ts + table.period
    return bounded_max(x, ts, landing)


def edited(source: Path, *changes: tuple[str, str]) -> str:
    text = source.read_text(encoding="utf-8")
    for old, new in changes:
        assert old in text, old
        text = text.replace(old, new, 1)
    return text


def write(folder: Path, name: str, text: str) -> Path:
    path = folder / name
    path.write_text(text, encoding="utf-8")
    return path


def assert_png(path: Path) -> None:
    data = path.read_bytes()
    assert data.startswith(PNG_SIGNATURE) and data.endswith(PNG_END)


def assert_one_line_error(done: subprocess.CompletedProcess[str], *fragments: str) -> None:
    assert done.returncode == 2, (done.returncode, done.stdout, done.stderr)
    assert "Traceback" not in done.stderr, done.stderr
    assert done.stderr.startswith("vibroimpact: error: "), done.stderr
    assert done.stderr.count("\n") == 1 and done.stderr.endswith("\n"), done.stderr
    for fragment in fragments:
        assert fragment in done.stderr, (fragment, done.stderr)
    assert done.stdout == ""


STATE_KEYS = {
    "structure_displacement",
    "structure_velocity",
    "damper_displacement",
    "damper_velocity",
}
