"""
Basins of attraction of the bouncing ball
=========================================

``examples/ball_table_basins.toml``: every initial height and velocity of a grid is run
until it settles, and labelled by the attractor it reaches (-1 where a run did not settle,
-3 where the start is inside the table).
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
system = vi.load(EXAMPLES / "ball_table_basins.toml")
spec = system.analyses["basins"]
state = ["structure_displacement.0", "structure_velocity.0"]  # the flat state (x, v)


def axis(table):
    return state.index(table["state"]), np.linspace(table["start"], table["stop"], table["count"])


found = vi.basins(
    system,
    axis(spec["x"]),
    axis(spec["y"]),
    settle_periods=spec["settle_periods"],
    record_periods=spec["record_periods"],
)

fig, ax = plt.subplots(figsize=(6, 4.5))
mesh = ax.pcolormesh(
    found.first, found.second, np.asarray(found.labels).T, shading="nearest", cmap="tab10"
)
ax.set_xlabel("initial height (m)")
ax.set_ylabel("initial velocity (m/s)")
ax.set_title(f"{len(found.attractors)} attractors")
fig.colorbar(mesh, label="attractor")
plt.show()
