"""
The largest Lyapunov exponent of the bouncing ball
==================================================

``examples/bouncing_ball_table.toml`` with ``e = 0.8``: at each table acceleration
amplitude ``Gamma g`` the ball settles 300 forcing periods from the scenario's
``[initial]``, then ``vibroimpact.lyapunov`` carries its tangent flow through every impact
over 2000 periods. On the period-one orbit both exponents are ``ln(e) / T`` (its
multipliers are complex, of modulus ``e``), until the largest rises to 0 at the flip;
beyond, the ball either chatters down onto the table and sticks, which loses every
direction (the exponent is minus infinity, drawn at the bottom), or bounces chaotically
(a positive exponent).
"""

from dataclasses import replace
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
RESTITUTION = 0.8
G = 9.81  # m/s^2, the scenario's gravity
stop = replace(system.stops[0], restitution=RESTITUTION)
table = system.excitations[0].signal  # the table's acceleration, m/s^2
period = 1 / table.frequency  # s

gammas = np.linspace(1.0, 3.0, 41)
largest = []
for gamma in gammas:
    shaken = system.replace(
        stops=(stop,), excitations=(vi.Base(signal=replace(table, amplitude=gamma * G)),)
    )
    largest.append(vi.lyapunov(shaken, settle=300, periods=2000).largest)  # 1/s
largest = np.array(largest)

stuck = np.isneginf(largest)
floor = 1.3 * np.log(RESTITUTION) / period
fig, ax = plt.subplots(figsize=(7, 4))
ax.plot(gammas[~stuck], largest[~stuck], "k.", label="largest exponent")
ax.plot(gammas[stuck], np.full(stuck.sum(), floor), "rv", label="the ball stuck: -inf")
ax.axhline(np.log(RESTITUTION) / period, color="b", ls=":", label="period one: ln(e) / T")
ax.axhline(0.0, color="grey", ls="--")
ax.set_xlabel("Gamma (table acceleration amplitude / g)")
ax.set_ylabel("largest Lyapunov exponent (1/s)")
ax.legend(loc="center right")
plt.show()
