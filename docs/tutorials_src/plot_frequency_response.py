"""
Frequency response with and without dampers
===========================================

The structure of the first tutorial (:math:`f_n = 10` Hz, 2 % damping) under a 5 N
harmonic force, stepped in frequency from 7 to 13 Hz and back. Each point starts from the
last point's final state, runs 200 forcing periods to settle and records 50, so that jumps
between coexisting responses and hysteresis show. A point whose stroboscopic state does
not repeat within 8 periods (a long transient, a long period, or chaos) is *unsettled*:
its spread of peaks over the recorded periods is drawn as a bar.

Without the damper the response is linear, :math:`X = F / |K - M\\omega^2 + i\\omega C|`;
every point of the bare sweep must lie on it.
"""

# %%
# Two systems: bare, and with the loose mass
# ------------------------------------------
import matplotlib.pyplot as plt
import numpy as np

import vibroimpact as vi

MASS, STIFFNESS, DAMPING, FORCE = 1.0, 3947.8, 2.513, 5.0  # kg, N/m, N s/m, N
structure = vi.Oscillator(mass=MASS, stiffness=STIFFNESS, damping=DAMPING)
force = vi.Force(at=0, signal=vi.Harmonic(amplitude=FORCE, frequency=10.0))
solver = vi.Solver(method="exact", t_end=1.0)  # linear between impacts: closed form
damper = vi.Damper(mass=0.05, at=0, clearance=0.005, law="rigid", restitution=0.6)
bare = vi.System(structure=structure, excitations=[force], solver=solver)
damped = vi.System(structure=structure, dampers=[damper], excitations=[force], solver=solver)

# %%
# Sweeps up and down
# ------------------
# ``vi.sweep`` takes the dotted path of any number of the scenario: here the forcing
# frequency (Hz). ``direction="both"`` goes up, then back down.
frequencies = np.linspace(7.0, 13.0, 61)  # Hz
bare_points = vi.sweep(bare, "excitation.0.frequency", frequencies, direction="both")
damped_points = vi.sweep(damped, "excitation.0.frequency", frequencies, direction="both")
bare_amplitude = np.array([p.amplitude[0] for p in bare_points])
unsettled = [p for p in damped_points if not p.settled]
print(f"{len(unsettled)} of {len(damped_points)} points with the damper did not settle")

# %%
# The figure
# ----------
# Up and down are drawn apart; an unsettled point is circled in red, with a bar from the
# smallest of its recorded periods' peaks (``least_period_peak``) to the largest (its
# ``amplitude``). The damper lowers the peak and moves it down in frequency (the loose mass
# adds to the moving mass); from 8.8 to 10.5 Hz its response often does not repeat: the
# impacts come at irregular phases there, and up and down differ.
fig, ax = plt.subplots(figsize=(7, 4), layout="constrained")
ax.plot([p.value for p in bare_points], 1e3 * bare_amplitude, "--", color="0.5", label="no damper")
for direction, marker in (("up", "^"), ("down", "v")):
    points = [p for p in damped_points if p.direction == direction]
    ax.plot(
        [p.value for p in points],
        [1e3 * p.amplitude[0] for p in points],
        marker=marker,
        ms=4,
        lw=0.8,
        label=f"damper, sweep {direction}",
    )
for p in unsettled:
    low, high = 1e3 * np.min(p.least_period_peak), 1e3 * p.amplitude[0]
    ax.plot([p.value, p.value], [low, high], color="tab:red", lw=2)
ax.plot(
    [p.value for p in unsettled],
    [1e3 * p.amplitude[0] for p in unsettled],
    "o",
    mfc="none",
    mec="tab:red",
    ms=8,
    label="unsettled (bar: spread of peaks)",
)
ax.set(
    xlabel="forcing frequency (Hz)",
    ylabel="amplitude of the structure (mm)",
    title="Frequency response, 5 N",
)
ax.legend()

# %%
# The reduction at resonance
# --------------------------
# Each point also has the linear amplitude of the bare structure at its frequency and the
# reduction ``1 - amplitude / linear_amplitude``.
at_resonance = [p for p in damped_points if p.value == 10.0 and p.direction == "up"][0]
print(
    f"at 10 Hz: {1e3 * at_resonance.amplitude[0]:.2f} mm against "
    f"{1e3 * at_resonance.linear_amplitude[0]:.2f} mm bare; settled: "
    f"{at_resonance.settled}, impacts per period: {at_resonance.impacts_per_period}"
)
