"""
A horizontal impact damper with friction
========================================

``examples/horizontal_friction_damper.toml``: a ball in the cavity of a forced one-mode
structure, striking the cavity's walls and sliding on its floor with Coulomb friction
under its weight. The frequency response with friction, beside the same damper without
it (``friction = 0``) and the structure alone: friction drags the ball along with the
structure, so that it strikes later and softer (or rides along at low amplitude), and it
takes energy of its own; the ledger's share of each loss is printed.
"""

import dataclasses
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
system = vi.load(EXAMPLES / "horizontal_friction_damper.toml")
spec = system.analyses["sweep"]
frequencies = np.linspace(spec["start"], spec["stop"], spec["count"])  # Hz
frictionless = system.replace(
    dampers=[dataclasses.replace(system.dampers[0], friction=0.0, static_friction=0.0)]
)

fig, ax = plt.subplots(figsize=(7, 4))
for label, model, marker in (("with friction", system, "o-"), ("without", frictionless, "s--")):
    points = vi.sweep(
        model,
        spec["parameter"],
        frequencies,
        direction=spec["direction"],
        settle_periods=spec["settle_periods"],
        record_periods=spec["record_periods"],
    )
    ax.plot(
        [p.value for p in points], [p.amplitude[0] * 1e3 for p in points], marker, ms=3, label=label
    )
ax.plot(
    frequencies, [p.linear_amplitude[0] * 1e3 for p in points], "k:", lw=1, label="structure alone"
)
ax.set_xlabel("forcing frequency (Hz)")
ax.set_ylabel("amplitude (mm)")
ax.legend()

# Where the energy goes at resonance, over 100 periods.
at_resonance = system.replace(
    excitations=[
        dataclasses.replace(system.excitations[0], signal=vi.Harmonic(amplitude=5.0, frequency=9.6))
    ]
)
energy = vi.simulate(at_resonance, t_end=100 / 9.6, history=False).energy
for key in ("viscous", "impact", "friction"):
    print(f"{key:>9}: {energy[key]:8.3f} J of {energy['input_work']:.3f} J input")
plt.show()
