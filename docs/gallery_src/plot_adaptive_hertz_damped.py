"""
Adaptive steps and an exact restitution
=======================================

``examples/adaptive_hertz_damped.toml``: the ``"hertz-damped"`` law rebounds two free bodies
at exactly ``e``, and an adaptive method (error control, every contact located to round-off)
takes few steps between contacts.
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
system = vi.load(EXAMPLES / "adaptive_hertz_damped.toml")
sol = vi.simulate(system)
relative = sol.damper_displacement[:, 0] - sol.structure_displacement[:, 0]  # m

fig, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(7, 5))
top.plot(sol.t, sol.structure_displacement[:, 0], label="main mass w")
top.plot(sol.t, sol.damper_displacement[:, 0], label="impact mass y")
top.set_ylabel("displacement (m)")
top.legend(loc="upper right")
bottom.plot(sol.t, relative)
damper = system.dampers[0]  # one clearance on each side in a two-mass file
for side in (-damper.clearance, damper.clearance):
    bottom.axhline(side, color="grey", lw=0.8, ls="--")
bottom.set_xlabel("time (s)")
bottom.set_ylabel("y - w (m)")
bottom.set_title(f"{len(sol.contacts)} contacts, method {sol.method}")
print(sol.steps, "steps,", sol.rejected_steps, "rejected, for", len(sol.contacts), "contacts")
plt.show()
