"""
A Monte Carlo under random excitation
=====================================

A linear oscillator (2 Hz, 5 % damping) on a floor whose acceleration is white noise of
two-sided spectral density :math:`S_0 = 10^{-4}` (m/s\\ :sup:`2`)\\ :sup:`2` per rad/s.
Random-vibration theory gives the stationary mean square of its displacement relative to
the floor,

.. math:: \\sigma_x^2 = \\int_{-\\infty}^{\\infty} |H(\\omega)|^2 S_0\\,d\\omega
          = \\frac{\\pi S_0}{2\\zeta\\omega_n^3},
          \\qquad H(\\omega) = \\frac{1}{\\omega_n^2 - \\omega^2 + 2i\\zeta\\omega_n\\omega}.

A Monte Carlo estimates it as the mean, over independent realisations of the noise, of
each run's time-averaged square; the standard error of that mean tells how far from the
theory it may honestly be. Then the same ensemble with an impact damper gives what theory
cannot: the distribution of the response with impacts.
"""

# %%
# The ensemble: an axis of seeds
# ------------------------------
# Each seed is one realisation of the noise, the same bit for bit on every platform. The
# noise is made of independent samples every :math:`1/(2 f_c)` s interpolated linearly,
# so its density rolls off as :math:`\mathrm{sinc}^4(\omega\pi/(2\omega_c))` within the
# band: with :math:`f_c = 50` Hz, far above the oscillator, the theory above holds to
# 0.3 %. Each run lasts 45 s; the first 5 s (the start from rest, about three time
# constants :math:`1/(\zeta\omega_n)` of 1.6 s) are left out of the metrics.
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import vibroimpact as vi
import vibroimpact.study

MASS, FREQUENCY, ZETA = 1.0, 2.0, 0.05  # kg, Hz, -
INTENSITY, CUTOFF, RUNS = 1e-4, 50.0, 400  # (m/s^2)^2 / (rad/s), Hz, realisations
omega_n = 2 * np.pi * FREQUENCY
structure = vi.Oscillator(mass=MASS, stiffness=MASS * omega_n**2, damping=2 * ZETA * MASS * omega_n)
noise = vi.Base(signal=vi.WhiteNoise(intensity=INTENSITY, cutoff_frequency=CUTOFF, seed=0))
ensemble = {
    "analysis": "run",
    "record_from": 5.0,  # s
    "metrics": ["rms"],
    "axes": {"excitation.0.seed": {"start": 0, "stop": RUNS - 1, "count": RUNS}},
}
# RK4 with a step a fifth of the noise's sample interval: no impacts to locate here.
solver = vi.Solver(method="rk4", dt=2e-3, t_end=45.0)


def mean_squares(system: vi.System) -> np.ndarray:
    """Each realisation's mean square displacement of the structure (m^2)."""
    with tempfile.TemporaryDirectory() as folder:
        result = vibroimpact.study.run(vi.study_of(system), Path(folder) / "runs.nc")
    return np.asarray(result["rms"].sel(coordinate=0)) ** 2


bare = mean_squares(
    vi.System(structure=structure, excitations=[noise], solver=solver, analyses={"study": ensemble})
)
theory = np.pi * INTENSITY / (2 * ZETA * omega_n**3)
standard_error = bare.std(ddof=1) / np.sqrt(RUNS)
print(
    f"Monte Carlo {bare.mean():.4e} m^2 +- {standard_error:.1e} (one standard error), "
    f"theory {theory:.4e} m^2: ratio {bare.mean() / theory:.4f}"
)

# %%
# With an impact damper
# ---------------------
# A loose mass of 5 % of the structure's, with 3 mm of clearance (about twice the bare
# response's standard deviation of 1.3 mm) and a rigid restitution of 0.5. Event-driven
# RK4 locates each impact.
damper = vi.Damper(mass=0.05, at=0, clearance=0.003, law="rigid", restitution=0.5)
damped = mean_squares(
    vi.System(
        structure=structure,
        dampers=[damper],
        excitations=[noise],
        solver=solver,
        analyses={"study": ensemble},
    )
)
print(
    f"with the damper: mean square {damped.mean():.4e} m^2, "
    f"{100 * (1 - np.sqrt(damped.mean() / theory)):.0f} % less RMS than the bare theory"
)

fig, ax = plt.subplots(figsize=(7, 3.8), layout="constrained")
bins = np.linspace(0, 1e3 * np.sqrt(max(bare.max(), damped.max())), 40)
ax.hist(1e3 * np.sqrt(bare), bins=bins, alpha=0.6, label="bare")
ax.hist(1e3 * np.sqrt(damped), bins=bins, alpha=0.6, label="with the damper")
ax.axvline(1e3 * np.sqrt(theory), color="k", lw=1, label=r"theory $\sigma_x$ (bare)")
ax.set(
    xlabel="RMS displacement of a 40 s record (mm)",
    ylabel="realisations",
    title=f"{RUNS} realisations of white noise",
)
ax.legend()
