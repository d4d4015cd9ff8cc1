"""
The flip of the bouncing ball in two parameters
===============================================

``examples/ball_table_flip_curve.toml``: the period doubling of the ball's period-one
orbit is located along its branch in the table's acceleration amplitude (Newton's
method on the extended system, the Floquet multipliers from the tangent flow through
the impacts), then followed as the restitution ``e`` rises from 0.5 to 0.8: 101 points.
Beside it, Holmes's closed form ``Gamma_flip = sqrt((pi (1 - e) / (1 + e))^2 + (2 (1 +
e^2) / (1 + e)^2)^2)``; below the curve the period-one orbit is stable, above it
period-doubled.
"""

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import vibroimpact as vi
from vibroimpact.analysis import curve_of

# The clone's examples/ folder: the nearest at or above the working folder (the build runs
# this from docs/gallery_src; a downloaded copy runs from anywhere in the clone).
EXAMPLES = next(
    (p / "examples" for p in [Path.cwd(), *Path.cwd().parents] if (p / "examples").is_dir()),
    Path("examples"),
)
scenario = vi.load_scenario(EXAMPLES / "ball_table_flip_curve.toml")
found = curve_of(scenario.data, scenario.base_dir)  # as `vibroimpact curve` runs it
G = 9.81  # m/s^2, the scenario's gravity
e = np.array([p.values[found.second] for p in found.points])
gamma = np.array([p.values[found.parameter] for p in found.points]) / G
holmes = np.sqrt((np.pi * (1 - e) / (1 + e)) ** 2 + (2 * (1 + e**2) / (1 + e) ** 2) ** 2)
print(
    f"{len(found.points)} points; largest relative error {np.max(np.abs(gamma / holmes - 1)):.1e}"
)

fig, ax = plt.subplots(figsize=(7, 4))
ax.plot(e, holmes, "-", color="0.7", lw=4, label="Holmes's closed form")
ax.plot(e, gamma, "k.", ms=3, label="vibroimpact curve")
ax.text(0.62, 1.15, "period one, stable", ha="center")
ax.text(0.68, 1.5, "period doubled", ha="center")
ax.set_xlabel("restitution e")
ax.set_ylabel("Gamma at the flip (table acceleration amplitude / g)")
ax.legend()
plt.show()
