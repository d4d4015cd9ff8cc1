"""
A ball bouncing on the floor
============================

``examples/bouncing_ball.toml``: a ball dropped onto a rigid floor rebounds with Newton's
restitution ``e``; its bounces come ever faster and sum to a finite accumulation time
``t1 (1 + e) / (1 - e)``, ``t1 = sqrt(2 h / g)``, after which it rests (sticking).
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
system = vi.load(EXAMPLES / "bouncing_ball.toml")
sol = vi.simulate(system)

fig, ax = plt.subplots(figsize=(7, 3.5))
ax.plot(sol.t, sol.structure_displacement[:, 0])
ax.set_xlabel("time (s)")
ax.set_ylabel("height (m)")
ax.set_title(f"{len(sol.contacts)} impacts, then at rest")
plt.show()
