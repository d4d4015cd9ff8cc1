"""
Two buildings pounding
======================

``examples/pounding_buildings.toml``: two structures side by side under the same ground
motion; a stop carried by one (``against``) makes them pound on each other when their
relative displacement closes the gap.
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
system = vi.load(EXAMPLES / "pounding_buildings.toml")
sol = vi.simulate(system)
stop = system.stops[0]
x = sol.structure_displacement
relative = x[:, int(stop.at)] - x[:, int(stop.against)]  # m
wall = stop.gap if stop.side == "upper" else -stop.gap

fig, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(7, 5))
for i in range(x.shape[1]):
    top.plot(sol.t, x[:, i], label=f"coordinate {i}")
top.set_ylabel("displacement (m)")
top.legend()
bottom.plot(sol.t, relative)
bottom.axhline(wall, color="grey", ls="--")
bottom.plot(sol.contacts.onset, np.full(len(sol.contacts), wall), "o")
bottom.set_xlabel("time (s)")
bottom.set_ylabel("relative displacement (m)")
bottom.set_title(f"{len(sol.contacts)} poundings")
plt.show()
