"""
A cantilever given by its section and material
==============================================

``examples/cantilever_section.toml``: a steel flat bar (25 mm x 5 mm, 0.5 m long), given by
its section and material rather than by its second moment and mass per length, carries a tip
impact damper and is forced near its first mode. The tip deflection and the root bending
moment, ``E I w''`` (:meth:`vibroimpact.SystemSolution.moment_at`), over the run.
"""

from pathlib import Path

import matplotlib.pyplot as plt

import vibroimpact as vi

# The gallery runs from docs/gallery_src; the scenarios are in the repository's examples/.
EXAMPLES = Path.cwd().parents[1] / "examples"
system = vi.load(EXAMPLES / "cantilever_section.toml")
sol = vi.simulate(system)
length = system.structure.length  # m

fig, (top, bottom) = plt.subplots(2, 1, figsize=(7, 5), sharex=True)
top.plot(sol.t, sol.displacement_at(length) * 1e3)
top.set_ylabel("tip deflection (mm)")
top.set_title(f"steel flat bar, {len(sol.contacts)} contacts of the tip damper")
bottom.plot(sol.t, sol.moment_at(0.0))
bottom.set_xlabel("time (s)")
bottom.set_ylabel("root bending moment (N m)")
plt.show()
