"""
Sensitivities beside a frequency response
=========================================

``examples/frf_impact_damper.toml`` swept up in frequency, each settled point's periodic
orbit differentiated in the damper's clearance (``derivatives=``, as ``vibroimpact sweep
--derivative damper.0.clearance`` does): by the implicit function theorem on the shooting
equations, ``dz/dp = (I - M)^-1 dP/dp``, the monodromy ``M`` and ``dP/dp`` from one run of
the tangent flow through the impacts. Where the damper rattles, a larger clearance changes
the amplitude by millimetres per millimetre; below, where it rests, not at all.
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
system = vi.load(EXAMPLES / "frf_impact_damper.toml")
spec = system.analyses["sweep"]
path = "damper.0.clearance"
points = vi.sweep(
    system,
    spec["parameter"],
    np.linspace(spec["start"], spec["stop"], 31),  # Hz
    settle_periods=spec["settle_periods"],
    record_periods=spec["record_periods"],
    derivatives=[path],
)
known = [p for p in points if p.derivatives]
print(f"{len(known)} of {len(points)} points with an orbit's derivative")

fig, (left, right) = plt.subplots(1, 2, figsize=(9, 4), sharex=True)
left.plot([p.value for p in points], [p.amplitude[0] * 1e3 for p in points], "o-", ms=3)
left.set_ylabel("amplitude (mm)")
right.plot(
    [p.value for p in known],
    [p.derivatives[path].amplitude[0] for p in known],  # m per m
    "o-",
    ms=3,
    color="tab:red",
)
right.axhline(0.0, color="0.5", lw=0.8)
right.set_ylabel("d amplitude / d clearance (m/m)")
for ax in (left, right):
    ax.set_xlabel("forcing frequency (Hz)")
    ax.grid(alpha=0.3)
fig.tight_layout()
plt.show()
