"""
A study of the clearance and the damper's mass
==============================================

``examples/clearance_study.toml``: a grid of steady-state runs over the damper's
clearance, its mass and the forcing frequency, written to a NetCDF file chunk by chunk
(resumable); for each mass, the worst amplitude over the band against the clearance.
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt

import vibroimpact as vi
import vibroimpact.study

# The clone's examples/ folder: the nearest at or above the working folder (the build runs
# this from docs/gallery_src; a downloaded copy runs from anywhere in the clone).
EXAMPLES = next(
    (p / "examples" for p in [Path.cwd(), *Path.cwd().parents] if (p / "examples").is_dir()),
    Path("examples"),
)
system = vi.load(EXAMPLES / "clearance_study.toml")
study = vi.study_of(system)
with tempfile.TemporaryDirectory() as folder:
    result = vibroimpact.study.run(study, Path(folder) / "study.nc")
    worst = result["amplitude"].sel(coordinate=0).max("excitation.0.frequency").load()

fig, ax = plt.subplots(figsize=(7, 4))
for mass in worst["damper.0.mass"].values:
    line = worst.sel({"damper.0.mass": mass})
    ax.plot(line["damper.0.clearance"] * 1e3, line * 1e3, "o-", label=f"{mass} kg")
ax.set_xlabel("clearance (mm)")
ax.set_ylabel("worst amplitude over 8-12 Hz (mm)")
ax.legend(title="damper mass")
plt.show()
