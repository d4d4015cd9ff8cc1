"""
A cantilever with two impact dampers
====================================

``examples/beam_two_dampers.toml``: a cantilever in modal coordinates carries two loose
masses along its length; the deflection at any point is the sum of the mode shapes times the
modal amplitudes (:meth:`vibroimpact.SystemSolution.displacement_at`).
"""

from pathlib import Path

import matplotlib.pyplot as plt

import vibroimpact as vi

# The clone's examples/ folder: the nearest at or above the working folder (the build runs
# this from docs/gallery_src; a downloaded copy runs from anywhere in the clone).
EXAMPLES = next(
    (p / "examples" for p in [Path.cwd(), *Path.cwd().parents] if (p / "examples").is_dir()),
    Path("examples"),
)
system = vi.load(EXAMPLES / "beam_two_dampers.toml")
sol = vi.simulate(system)
length = system.structure.length  # m

fig, ax = plt.subplots(figsize=(7, 3.5))
ax.plot(sol.t, sol.displacement_at(length) * 1e3, label="tip")
for j, damper in enumerate(system.dampers):
    ax.plot(sol.t, sol.displacement_at(damper.at) * 1e3, lw=0.8, label=f"damper {j}'s point")
ax.set_xlabel("time (s)")
ax.set_ylabel("deflection (mm)")
ax.set_title(f"{len(sol.contacts)} contacts of the two dampers")
ax.legend()
plt.show()
