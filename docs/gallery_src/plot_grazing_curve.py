"""
The impact oscillator's grazing in two parameters
=================================================

``examples/impact_oscillator_grazing.toml``: a forced 1 Hz oscillator (5 % damping) under
a rigid stop. Below resonance its orbit misses the stop; as the forcing frequency rises,
it comes to touch it at zero speed, a grazing, located by Newton's method on the
extended system (the orbit, the parameter and the instant of the touch). Followed as the
stop's gap grows from 50 to 70 mm: 101 points. Beside them, the closed form: the orbit
that misses the stop is the linear response, so it grazes where its amplitude
``X(f) = F0 / |k - m w^2 + i c w|`` equals the gap.
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
scenario = vi.load_scenario(EXAMPLES / "impact_oscillator_grazing.toml")
found = curve_of(scenario.data, scenario.base_dir)  # as `vibroimpact curve` runs it
structure = scenario.data["structure"]
m, k, c = structure["mass"], structure["stiffness"], structure["damping"]
force = scenario.data["excitation"][0]["amplitude"]
gap = np.array([p.values[found.second] for p in found.points])
frequency = np.array([p.values[found.parameter] for p in found.points])
w = 2 * np.pi * frequency
amplitude = force / np.abs(k - m * w**2 + 1j * c * w)
print(
    f"{len(found.points)} points; largest relative error {np.max(np.abs(amplitude / gap - 1)):.1e}"
)

fig, ax = plt.subplots(figsize=(7, 4))
ax.plot(gap * 1e3, frequency, "-", color="0.7", lw=4, label="X(f) = gap")
ax.plot(gap * 1e3, frequency, "k.", ms=3, label="vibroimpact curve")
ax.text(52, 0.79, "the orbit strikes the stop", ha="left")
ax.text(62, 0.72, "the orbit misses it", ha="left")
ax.set_xlabel("stop's gap (mm)")
ax.set_ylabel("forcing frequency at the grazing (Hz)")
ax.legend(loc="lower right")
plt.show()
