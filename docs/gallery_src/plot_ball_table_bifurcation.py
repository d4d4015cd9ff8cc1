"""
A bifurcation diagram of the bouncing ball
==========================================

``examples/ball_table_bifurcation.toml``: the ball on a vibrating table, its table
acceleration amplitude raised step by step; at each value the ball's height is sampled once
per forcing period after settling, so a period-1 orbit is one dot, period doubling two, and
chaos a cloud.
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
system = vi.load(EXAMPLES / "ball_table_bifurcation.toml")
spec = system.analyses["sweep"]
points = vi.bifurcation(
    system,
    spec["parameter"],
    np.linspace(spec["start"], spec["stop"], spec["count"]),  # m/s^2
    direction=spec["direction"],
    settle_periods=spec["settle_periods"],
    sample_periods=spec["record_periods"],
)

fig, ax = plt.subplots(figsize=(7, 4))
for p in points:
    samples = np.asarray(p.samples).ravel()
    ax.plot(np.full(samples.size, p.value), samples, "k.", ms=2)
ax.set_xlabel("table acceleration amplitude (m/s^2)")
ax.set_ylabel("sampled displacement (m)")
plt.show()
