"""
A cantilever from its section and material
===========================================

``examples/cantilever_section.toml``: a steel flat bar, 25 mm by 5 mm, given by its section
and its material instead of its second moment of area and mass per length (which
:meth:`vibroimpact.Cantilever.resolved` shows); a tip impact damper and a tip force near the
first mode. The figure shows the tip deflection and the root bending moment ``E I w''``.
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
system = vi.load(EXAMPLES / "cantilever_section.toml")
beam = system.structure.resolved()
print(f"I = {beam['second_moment']:.4e} m^4, mass per length = {beam['mass_per_length']:.4f} kg/m")
sol = vi.simulate(system)

fig, (top, bottom) = plt.subplots(2, 1, figsize=(7, 5), sharex=True)
top.plot(sol.t, sol.displacement_at(system.structure.length) * 1e3)
top.set_ylabel("tip deflection (mm)")
top.set_title(f"{len(sol.contacts)} contacts of the tip damper")
bottom.plot(sol.t, sol.moment_at(0.0))
bottom.set_xlabel("time (s)")
bottom.set_ylabel("root moment (N m)")
plt.show()
