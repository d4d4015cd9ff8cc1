"""Stress the event kernel with random forced systems: an oscillator (10 Hz, 2 %
damping), two storeys or a cantilever, with one to three dampers (rigid or Hertz),
maybe a stop (or pounding between the storeys) and gravity, forced or shaken at the
base by a harmonic, a sweep, white noise or a record with quiet stretches, every method,
sometimes recording peak and RMS from a random instant, each run with and without a
stroboscopic sample every forcing period. Prints
how many runs stopped, by method and error, and the first few scenarios that did.

Not a test (no fixed expectation yet: some stops are legitimate, such as Newton's
method failing on a stiff Hertz contact at a coarse step); a tool for finding event
handling bugs, which show as "chattering" stops or as strobes changing the outcome.

    python tests/fuzz_events.py [SEED] [SECONDS]
"""

from __future__ import annotations

import collections
import json
import sys
import time
from typing import Any

import numpy as np

import vibroimpact as vi

STRUCTURE = {"kind": "oscillator", "mass": 1.0, "stiffness": 3947.8, "damping": 2.513}
TWO_STOREYS = {
    "kind": "matrices",
    "mass": [[1.0, 0.0], [0.0, 0.5]],
    "stiffness": [[6000.0, -2000.0], [-2000.0, 2000.0]],
    "damping": [[3.0, -1.0], [-1.0, 1.0]],
}
BEAM = {
    "kind": "cantilever",
    "length": 0.5,
    "youngs_modulus": 7e10,
    "second_moment": 1e-10,
    "mass_per_length": 0.27,
    "modes": 3,
    "damping_ratio": 0.01,
}


def law(rng: np.random.Generator, method: str) -> dict[str, Any]:
    """A random law: rigid (any restitution) or, except for exact, Hertz."""
    if rng.random() < 0.4 and method != "exact":
        return {"law": "hertz", "stiffness": float(10 ** rng.uniform(5, 8))}
    return {"law": "rigid", "restitution": float(rng.choice([0, 0.3, 0.6, 1]))}


def signal(
    rng: np.random.Generator, kind: str, amplitude: float, frequency: float, t_end: float
) -> dict[str, Any]:
    """A signal of about ``amplitude`` near ``frequency`` (Hz): harmonic, a sweep through
    it, white noise up to four times it, or a record of random samples that begins and
    ends with quiet stretches."""
    if kind == "harmonic":
        return {"signal": "harmonic", "amplitude": amplitude, "frequency": frequency}
    if kind == "sweep":
        return {
            "signal": "sweep",
            "amplitude": amplitude,
            "start_frequency": 0.5 * frequency,
            "end_frequency": 2.0 * frequency,
            "sweep": str(rng.choice(["linear", "logarithmic"])),
            "duration": 0.5 * t_end,
        }
    if kind == "noise":
        cutoff = 4.0 * frequency
        return {
            "signal": "white-noise",
            "intensity": amplitude**2 / (2 * np.pi * cutoff),
            "cutoff_frequency": cutoff,
            "seed": int(rng.integers(2**32)),
        }
    quiet = float(rng.uniform(0, 0.5 * t_end))
    steps = quiet + np.cumsum(rng.uniform(0.02, 0.1, size=int(rng.integers(5, 60))) / frequency)
    values = amplitude * rng.normal(size=steps.size)
    values[-1] = 0.0
    return {
        "signal": "recorded",
        "time": [0.0, *steps.tolist()],
        "value": [0.0, *values.tolist()],
    }


def scenario(rng: np.random.Generator) -> dict[str, Any]:
    """One random system and method, as keyword arguments of simulate_system: an
    oscillator (most often), two storeys (pounding between them) or a cantilever;
    one to three dampers, maybe a stop, gravity, a force or base excitation."""
    method = str(rng.choice(["exact", "dop853", "dopri5", "rk4", "newmark-implicit"]))
    kind = str(rng.choice(["oscillator"] * 3 + ["matrices", "cantilever"]))
    structure = {"oscillator": STRUCTURE, "matrices": TWO_STOREYS, "cantilever": BEAM}[kind]
    points = {"oscillator": [0], "matrices": [0, 1], "cantilever": [0.25, 0.5]}[kind]
    scale = 0.1 if kind == "cantilever" else 1.0
    dampers = []
    for _ in range(int(rng.choice([1, 2, 2, 3]))):
        clearance = scale * float(rng.choice([0.0005, 0.003, 0.01]))
        dampers.append(
            {
                "mass": scale * float(rng.uniform(0.01, 0.2)),
                "at": rng.choice(points).item(),
                "clearance": clearance,
                **law(rng, method),
            }
        )
    stops = []
    if rng.random() < 0.3:
        gap = scale * float(rng.uniform(0.001, 0.02))
        side = str(rng.choice(["upper", "lower"]))
        stop = {"at": points[0], "side": side, "gap": gap, **law(rng, method)}
        if kind == "matrices" and rng.random() < 0.5:
            stop["against"] = 1  # pounding
        stops.append(stop)
    if rng.random() < 0.7:
        excitation = {"kind": "force", "at": points[-1]}
        amplitude = scale * float(rng.uniform(1, 30))
    else:
        excitation = {"kind": "base"}
        amplitude = float(rng.uniform(1, 30))
    frequency = float(rng.uniform(5, 15))
    t_end = 10.0 if kind != "cantilever" else 2.0
    # The exact flow takes harmonics only.
    signals = ["harmonic"] if method == "exact" else ["harmonic"] * 3 + ["sweep", "noise", "record"]
    excitation |= signal(rng, str(rng.choice(signals)), amplitude, frequency, t_end)
    return {
        "structure": structure,
        "damper": dampers,
        "stop": stops,
        "gravity": {"acceleration": 9.81} if rng.random() < 0.3 else None,
        "excitation": [excitation],
        "method": method,
        "t_end": t_end,
        **({"record_from": float(rng.uniform(0, t_end))} if rng.random() < 0.3 else {}),
        "history": False,
        **(
            {"dt": 1e-4 if kind != "cantilever" else 2e-5}
            if method in ("rk4", "newmark-implicit")
            else {}
        ),
    }


def outcome(kw: dict[str, Any], strobe: float | None) -> str:
    """ "ok", or the error's class and first words."""
    try:
        vi.simulate_system(**kw, **({} if strobe is None else {"strobe_period": strobe}))
    except Exception as err:  # every stop is what is counted
        return f"{type(err).__name__}: {' '.join(str(err).split()[:3])}"
    return "ok"


def main(seed: int, seconds: float) -> None:
    rng = np.random.default_rng(seed)
    stops: list[tuple[dict[str, Any], tuple[str, str]]] = []
    start, cases = time.perf_counter(), 0
    while time.perf_counter() - start < seconds:
        cases += 1
        kw = scenario(rng)
        period = 1.0 / kw["excitation"][0].get("frequency", 10.0)
        results = (outcome(kw, None), outcome(kw, period))
        if results != ("ok", "ok"):
            stops.append((kw, results))
    print(f"{cases} cases in {time.perf_counter() - start:.0f} s, {len(stops)} with a stop")
    counts = collections.Counter((kw["method"], results) for kw, results in stops)
    for (method, results), count in counts.most_common():
        print(f"{count:5d} {method:17s} plain: {results[0]} | strobed: {results[1]}")
    for kw, results in stops[:5]:
        print(json.dumps(kw), results)


if __name__ == "__main__":
    main(
        int(sys.argv[1]) if len(sys.argv) > 1 else 0,
        float(sys.argv[2]) if len(sys.argv) > 2 else 60,
    )
