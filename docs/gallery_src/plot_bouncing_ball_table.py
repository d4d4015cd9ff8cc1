"""
A ball on a vibrating table
===========================

``examples/bouncing_ball_table.toml``: a ball under gravity bounces on a table driven
harmonically (a stop that moves with the base). Coordinates are relative to the table, so a
height of 0 is a contact.
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
system = vi.load(EXAMPLES / "bouncing_ball_table.toml")
sol = vi.simulate(system)

fig, ax = plt.subplots(figsize=(7, 3.5))
ax.plot(sol.t, sol.structure_displacement[:, 0], label="ball above the table")
ax.plot(sol.contacts.onset, np.zeros(len(sol.contacts)), "o", label="impacts")
ax.set_xlabel("time (s)")
ax.set_ylabel("height (m)")
ax.legend()
plt.show()
