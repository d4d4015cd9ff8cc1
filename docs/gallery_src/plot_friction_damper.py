"""
Den Hartog's dry-friction damper
================================

``examples/friction_damper.toml``: a one-mode structure rubbing on the ground through a
friction pad. Its frequency response at several pressing forces: with none it is the
lightly damped resonance; a moderate force slides all cycle and takes the peak down;
a large one holds the structure stuck for part of each cycle, and one whose static
force passes the forcing's amplitude holds it still. The dots are Den Hartog's (1931)
exact amplitude of the undamped structure sliding throughout (two stops a cycle), for
the 10 N pad away from resonance.
"""

import dataclasses
import math
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import vibroimpact as vi

# The clone's examples/ folder: the nearest at or above the working folder (the build runs
# this from docs/gallery_src; a downloaded copy runs from anywhere in the clone).
EXAMPLES = next(
    (p / "examples" for p in [Path.cwd(), *Path.cwd().parents] if (p / "examples").is_dir()),
    Path("examples"),
)
system = vi.load(EXAMPLES / "friction_damper.toml")
spec = system.analyses["sweep"]
frequencies = np.linspace(spec["start"], spec["stop"], spec["count"])  # Hz
pad = system.frictions[0]
force = system.excitations[0].signal.amplitude  # N
k, m = system.structure.stiffness, system.structure.mass

fig, ax = plt.subplots(figsize=(7, 4))
for normal in (0.0, 10.0, 20.0, 40.0):  # N
    model = system.replace(frictions=[dataclasses.replace(pad, normal_force=normal)])
    points = vi.sweep(
        model,
        spec["parameter"],
        frequencies,
        direction=spec["direction"],
        settle_periods=spec["settle_periods"],
        record_periods=spec["record_periods"],
    )
    (line,) = ax.plot(
        [p.value for p in points],
        [p.amplitude[0] * 1e3 for p in points],
        label=f"pressed with {normal:.0f} N",
    )
    # Den Hartog: (P / k) sqrt(V^2 - (F / P)^2 U^2), beta = f / f_n.
    slide = pad.coefficient * normal
    beta = 2 * math.pi * frequencies / math.sqrt(k / m)
    V = 1 / (1 - beta**2)
    U = np.sin(np.pi / beta) / (beta * (1 + np.cos(np.pi / beta)))
    inside = V**2 - (slide / force) ** 2 * U**2
    ok = (inside > 0) & (abs(beta - 1) > 0.05) & (normal == 10.0)
    ax.plot(frequencies[ok], force / k * np.sqrt(inside[ok]) * 1e3, ".", color=line.get_color())
ax.set_xlabel("forcing frequency (Hz)")
ax.set_ylabel("amplitude (mm)")
ax.legend()
plt.show()
