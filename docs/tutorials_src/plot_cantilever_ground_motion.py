"""
A cantilever under a recorded ground motion
===========================================

An aluminium bar clamped at its root to a shaking floor (a sign post, an antenna mast,
an instrument boom): length 1 m, a 40 x 10 mm section bending about its weak axis,
:math:`E = 70` GPa, :math:`\\rho = 2700` kg/m\\ :sup:`3`, 2 % damping in every mode. Its
first mode is at 8.2 Hz. What matters for the engineer is the tip's displacement (the
clearance to its neighbours) and the root's bending moment (the stress that fatigues the
clamp: :math:`\\sigma = M c / I`).

The beam is an Euler-Bernoulli cantilever in its first three modes. The floor's
acceleration enters as a base excitation: the coordinates are relative to the base and
each mode is loaded by :math:`-\\Gamma_i a(t)`, its participation times the ground
acceleration. An impact damper (a 50 g loose mass with 2 mm of clearance, a damped Hertz
contact) is then put at the tip.
"""

# %%
# The record
# ----------
# A recorded accelerogram is a CSV of time (s) and acceleration (m/s\ :sup:`2`),
# interpolated linearly and zero outside the record. No record ships with the package,
# so this one is made here, as a record would look: 100 samples per second, 8 s of
# band-limited noise under a build-up and decay envelope, peak 3 m/s\ :sup:`2`.
import shutil
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import vibroimpact as vi

rng = np.random.default_rng(2024)
record_time = np.arange(0.0, 8.0, 0.01)  # s
noise = np.convolve(rng.standard_normal(record_time.size), np.ones(4) / 4, mode="same")
envelope = np.minimum(record_time / 1.0, 1.0) * np.exp(-np.maximum(record_time - 3.0, 0) / 1.5)
acceleration = noise * envelope
acceleration[-50:] *= np.cos(np.linspace(0, np.pi / 2, 50))  # its end tapered to zero
acceleration *= 3.0 / np.max(np.abs(acceleration))  # m/s^2
folder = Path(tempfile.mkdtemp())
record_file = folder / "ground.csv"
np.savetxt(
    record_file,
    np.column_stack([record_time, acceleration]),
    delimiter=",",
    header="time_s,acceleration_m_s2",
    comments="",
)

# %%
# The beam and what to follow
# ---------------------------
# ``[output] points`` and ``moments`` (m from the clamp) follow the deflection at the tip
# and the bending moment :math:`EI\,w''` at the root.
LENGTH, WIDTH, THICKNESS = 1.0, 0.04, 0.01  # m
YOUNGS_MODULUS, DENSITY = 70e9, 2700.0  # Pa, kg/m^3
beam = vi.Cantilever(
    length=LENGTH,
    youngs_modulus=YOUNGS_MODULUS,
    second_moment=WIDTH * THICKNESS**3 / 12,  # m^4
    mass_per_length=DENSITY * WIDTH * THICKNESS,  # kg/m
    modes=3,
    damping_ratio=0.02,
)
ground = vi.Base(signal=vi.Recorded(file=str(record_file)))
follow = vi.Output(points=[LENGTH], moments=[0.0], every=4)
solver = vi.Solver(method="dop853", t_end=10.0, rtol=1e-9, atol=1e-12)
bare = vi.System(structure=beam, excitations=[ground], solver=solver, output=follow)
bare_run = vi.simulate(bare)
tip = bare_run.displacement_at(LENGTH)  # m
root_moment = bare_run.moment_at(0.0)  # N m
print(
    f"bare: tip peak {1e3 * np.max(np.abs(tip)):.1f} mm, "
    f"root moment peak {np.max(np.abs(root_moment)):.2f} N m"
)

# %%
# With an impact damper at the tip
# --------------------------------
# A damped Hertz law (``"hertz-damped"``) rebounds at exactly its restitution and, unlike
# a rigid impact, converges as modes are added. The damper's displacement, like the beam's,
# is relative to the moving ground (every coordinate is, under base excitation), not to the
# beam: its gap is its displacement less the tip's.
damper = vi.Damper(
    mass=0.05, at=LENGTH, clearance=0.002, law="hertz-damped", stiffness=1e8, restitution=0.6
)
damped = vi.System(
    structure=beam, dampers=[damper], excitations=[ground], solver=solver, output=follow
)
damped_run = vi.simulate(damped)
shutil.rmtree(folder)  # the record is read; the runs keep what they need
print(
    f"damped: tip peak {1e3 * np.max(np.abs(damped_run.displacement_at(LENGTH))):.1f} mm, "
    f"root moment peak {np.max(np.abs(damped_run.moment_at(0.0))):.2f} N m, "
    f"{len(damped_run.contacts)} contacts"
)

fig, axes = plt.subplots(3, 1, figsize=(7, 7), sharex=True, layout="constrained")
axes[0].plot(record_time, acceleration, color="0.4", lw=0.7)
axes[0].set(ylabel="ground (m/s$^2$)", title="A cantilever under a ground motion")
for run, label, style in (
    (bare_run, "bare", dict(color="0.6")),
    (damped_run, "damper at the tip", dict(lw=0.8)),
):
    axes[1].plot(run.t, 1e3 * run.displacement_at(LENGTH), label=label, **style)
    axes[2].plot(run.t, run.moment_at(0.0), label=label, **style)
axes[1].set(ylabel="tip displacement (mm)")
axes[2].set(ylabel="root moment (N m)", xlabel="time (s)")
axes[1].legend(loc="upper right")

# %%
# The stress at the clamp
# -----------------------
# The root's bending stress is :math:`M (h/2) / I`: compare its peak with the
# alloy's fatigue strength (about 100 MPa for 6061-T6 at :math:`10^7` cycles).
section_modulus = WIDTH * THICKNESS**2 / 6  # m^3
for run, label in ((bare_run, "bare"), (damped_run, "damper")):
    print(
        f"{label}: peak root stress "
        f"{np.max(np.abs(run.moment_at(0.0))) / section_modulus / 1e6:.1f} MPa"
    )
