"""
Following a periodic orbit
==========================

``examples/ball_table_continuation.toml``: the ball's period-1 orbit is followed by
continuation as the table's acceleration amplitude rises, with its Floquet multipliers; the
orbit loses its stability where a multiplier leaves the unit circle.
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
system = vi.load(EXAMPLES / "ball_table_continuation.toml")
spec = system.analyses["continuation"]
branch = vi.continue_orbit(
    system, spec["parameter"], stop=spec["stop"], periods=spec["periods"], step=spec["step"]
)

values = np.array([p.value for p in branch.points])
largest = np.array([np.max(np.abs(p.floquet_multipliers)) for p in branch.points])
stable = np.array([bool(p.stable) for p in branch.points])
fig, ax = plt.subplots(figsize=(7, 4))
ax.plot(values[stable], largest[stable], "b.", label="stable")
ax.plot(values[~stable], largest[~stable], "r.", label="unstable")
ax.axhline(1.0, color="grey", ls="--")
ax.set_xlabel("table acceleration amplitude (m/s^2)")
ax.set_ylabel("largest |Floquet multiplier|")
ax.set_title(f"{len(branch.points)} orbits; stopped: {branch.stopped}")
ax.legend()
plt.show()
