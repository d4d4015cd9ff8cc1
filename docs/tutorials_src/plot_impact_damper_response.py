"""
Free and forced response of an impact damper
============================================

A one-mode structure (mass :math:`M = 1` kg, stiffness :math:`K = 3947.8` N/m, so
:math:`f_n = 10` Hz, 2 % of critical damping) carries a loose mass :math:`m = 50` g in an
enclosure with a clearance :math:`d = 5` mm on each side. Every impact obeys Newton's law
with restitution :math:`e = 0.6`: the relative velocity reverses and shrinks by
:math:`e`, momentum is conserved, and the kinetic energy
:math:`\\tfrac12 m_{\\mathrm{eff}} (1 - e^2) v^2` (:math:`m_{\\mathrm{eff}} = Mm/(M+m)`,
:math:`v` the approach speed) is lost.

The structure is linear between impacts and the forcing harmonic, so the ``"exact"``
method integrates it in closed form and locates every impact on the exact flow.
"""

# %%
# The system
# ----------
# Typed parts named as the sections of a TOML scenario; SI units throughout.
import matplotlib.pyplot as plt
import numpy as np

import vibroimpact as vi

MASS, STIFFNESS, DAMPING = 1.0, 3947.8, 2.513  # kg, N/m, N s/m
LOOSE_MASS, CLEARANCE, RESTITUTION = 0.05, 0.005, 0.6  # kg, m, -
structure = vi.Oscillator(mass=MASS, stiffness=STIFFNESS, damping=DAMPING)
damper = vi.Damper(mass=LOOSE_MASS, at=0, clearance=CLEARANCE, law="rigid", restitution=RESTITUTION)

# %%
# Free response
# -------------
# The structure is released from 30 mm with the loose mass at rest beside it, in the
# middle of its enclosure (the damper's displacement is its own, not relative). ``dt``
# caps the exact method's steps so that the history is fine enough to draw.
RELEASE = 0.03  # m
free_system = vi.System(
    structure=structure,
    dampers=[damper],
    initial=vi.Initial(structure_displacement=[RELEASE], damper_displacement=[RELEASE]),
)
free = vi.simulate(free_system, method="exact", t_end=1.0, dt=2e-4)
print(f"{len(free.contacts)} impacts; energy (J): {free.energy}")

fig, ax = plt.subplots(figsize=(7, 3.5), layout="constrained")
ax.plot(free.t, 1e3 * free.structure_displacement[:, 0], label="structure x")
ax.plot(free.t, 1e3 * free.damper_displacement[:, 0], label="loose mass y", lw=0.8)
ax.plot(
    free.contacts.onset,
    1e3 * np.interp(free.contacts.onset, free.t, free.damper_displacement[:, 0]),
    "k.",
    ms=4,
    label="impacts",
)
ax.set(xlabel="time (s)", ylabel="displacement (mm)", title="Free response")
ax.legend()

# %%
# Each impact takes the kinetic energy Newton's law says: the contact table gives the
# approach speed and the energy dissipated of every impact.
m_eff = MASS * LOOSE_MASS / (MASS + LOOSE_MASS)
newton_loss = 0.5 * m_eff * (1 - RESTITUTION**2) * free.contacts.approach_speed**2
print(
    "largest difference from Newton's loss (J):",
    float(np.max(np.abs(free.contacts.energy_dissipated - newton_loss))),
)

# %%
# Forced response
# ---------------
# A harmonic force of 5 N at the natural frequency, from rest, with and without the
# damper. Without it the steady amplitude is :math:`F / |K - M\omega^2 + i\omega C|`
# (31.7 mm); with it the impacts take energy every half period.
FORCE, FREQUENCY = 5.0, 10.0  # N, Hz
force = vi.Force(at=0, signal=vi.Harmonic(amplitude=FORCE, frequency=FREQUENCY))
with_damper = vi.System(structure=structure, dampers=[damper], excitations=[force])
bare = vi.System(structure=structure, excitations=[force])
forced = vi.simulate(with_damper, method="exact", t_end=3.0, dt=2e-4)
forced_bare = vi.simulate(bare, method="exact", t_end=3.0, dt=2e-4)
omega = 2 * np.pi * FREQUENCY
linear_amplitude = FORCE / abs(STIFFNESS - MASS * omega**2 + 1j * omega * DAMPING)
late = forced.t > 2.0
forced_amplitude = float(np.max(np.abs(forced.structure_displacement[late, 0])))
print(
    f"steady amplitude: {1e3 * forced_amplitude:.2f} mm with the damper, "
    f"{1e3 * linear_amplitude:.2f} mm without"
)

fig, ax = plt.subplots(figsize=(7, 3.5), layout="constrained")
ax.plot(
    forced_bare.t, 1e3 * forced_bare.structure_displacement[:, 0], label="no damper", color="0.6"
)
ax.plot(forced.t, 1e3 * forced.structure_displacement[:, 0], label="with the damper")
ax.axhline(1e3 * linear_amplitude, ls="--", color="0.3", lw=0.8)
ax.set(xlabel="time (s)", ylabel="structure displacement (mm)", title="Forced at 10 Hz, 5 N")
ax.legend(loc="lower right")

# %%
# The energy ledger
# -----------------
# Every run keeps its balance (J): the work of the force goes into viscous and impact
# losses and the energy stored at the end.
print(forced.energy)
