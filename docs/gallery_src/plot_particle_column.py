"""
A column of particles in a forced cavity
========================================

``examples/particle_column.toml``: five 10 g particles stacked in a cavity on a forced
15 Hz structure, under gravity (a particle-column damper). Each particle strikes its
neighbours (``[[collision]]``, Hertzian with restitution 0.6); only the lowest reaches the
floor and only the highest the ceiling. Shaken at about 2 g, the column leaves the floor
and its particles collide with each other as it lands: a wave runs up the column at
each landing. Below, each particle's lift: its height above its place in the column
resting on the floor (the particles are points, 2 mm apart at rest, so a resting column
is at zero throughout), and where the energy the force puts in goes.
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
system = vi.load(EXAMPLES / "particle_column.toml")
sol = vi.simulate(system)
pairs = list(sol.contacts.pair)
print({name: pairs.count(name) for name in sorted(set(pairs))})
print({key: round(value, 4) for key, value in sol.energy.items()})

# Resting on the floor, particle j is (j + 1) gaps below its rest position.
spacing = system.collisions[0].gap
fig, (top, bottom) = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
for j in range(len(system.dampers)):
    relative = sol.damper_displacement[:, j] - sol.structure_displacement[:, 0]
    top.plot(sol.t, (relative + (j + 1) * spacing) * 1e3, lw=0.8, label=f"particle {j}")
top.axhline(0.0, color="k", lw=1)
top.set_ylabel("lift (mm)")
top.legend(loc="upper right", fontsize=8, ncol=5)
top.set_title(f"{len(pairs)} contacts in {sol.t[-1]:.0f} s")
bottom.plot(sol.t, sol.structure_displacement[:, 0] * 1e3, color="0.3")
bottom.set_xlabel("time (s)")
bottom.set_ylabel("cavity (mm)")
fig.tight_layout()
plt.show()

fig, ax = plt.subplots(figsize=(7, 3))
energy = sol.energy
shares = {
    "structure's damping": energy["viscous"],
    "particles' contacts": energy["contact"],
    "stored at the end": energy["stored_end"],
}
ax.barh(list(shares), np.array(list(shares.values())) * 1e3, color="0.5")
ax.set_xlabel(f"energy (mJ) of the force's work, {energy['input_work'] * 1e3:.0f} mJ")
fig.tight_layout()
plt.show()
