"""
A frequency response with an impact damper
==========================================

``examples/frf_impact_damper.toml``: a 10 Hz one-mode structure with a rigid impact
damper, swept up and down in frequency; each point is the steady amplitude after settling,
beside the structure's response without the damper (``linear_amplitude``). Up and down
sweeps can settle on different orbits where several coexist.
"""

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
system = vi.load(EXAMPLES / "frf_impact_damper.toml")
spec = system.analyses["sweep"]
points = vi.sweep(
    system,
    spec["parameter"],
    np.linspace(spec["start"], spec["stop"], spec["count"]),  # Hz
    direction=spec["direction"],
    settle_periods=spec["settle_periods"],
    record_periods=spec["record_periods"],
)

fig, ax = plt.subplots(figsize=(7, 4))
for direction, marker in (("up", "^"), ("down", "v")):
    kept = [p for p in points if p.direction == direction]
    ax.plot([p.value for p in kept], [p.amplitude[0] * 1e3 for p in kept], marker, label=direction)
up = [p for p in points if p.direction == "up"]
ax.plot(
    [p.value for p in up],
    [p.linear_amplitude[0] * 1e3 for p in up],
    "k-",
    lw=0.8,
    label="without the damper",
)
unsettled = [p for p in points if not p.settled]
ax.plot(
    [p.value for p in unsettled],
    [p.amplitude[0] * 1e3 for p in unsettled],
    "rx",
    label="not settled",
)
ax.set_xlabel("forcing frequency (Hz)")
ax.set_ylabel("amplitude (mm)")
ax.set_yscale("log")
ax.legend()
plt.show()
