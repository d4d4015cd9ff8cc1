"""
Bifurcations, Poincare sections and basins of an impact oscillator
==================================================================

Holmes's ball on a vibrating table (1982): a 50 g ball bounces under gravity on a table
moving harmonically at 10 Hz, with Newton's restitution :math:`e = 0.5` at each impact.
The table's acceleration amplitude, scaled as :math:`\\Gamma = A\\omega^2/g`, is the
parameter. A period-one orbit (one impact every forcing period) exists for
:math:`\\Gamma > \\pi(1-e)/(1+e)`, closes at the speed :math:`2\\pi g/(\\omega(1+e))`
and loses its stability by period doubling at

.. math:: \\Gamma_{\\mathrm{flip}} = \\sqrt{\\left(\\frac{\\pi(1-e)}{1+e}\\right)^2
          + \\left(\\frac{2(1+e^2)}{(1+e)^2}\\right)^2} = 1.527,

after which the orbit doubles and, at this restitution, soon lands in complete chattering:
each cycle the ball chatters down to the table and rides it until thrown up again. The
table is the base: its acceleration
is a base excitation, the ball's coordinate is its height above the table, and the table
is a rigid stop below it. The ball is a mass on no spring, so the ``"exact"`` method
integrates its parabolas in closed form.
"""

# %%
# The system
# ----------
import matplotlib.pyplot as plt
import numpy as np

import vibroimpact as vi

GRAVITY, RESTITUTION, FREQUENCY = 9.81, 0.5, 10.0  # m/s^2, -, Hz


def ball_on_table(gamma: float) -> vi.System:
    """The ball on a table whose acceleration amplitude is ``gamma`` g."""
    return vi.System(
        structure=vi.Oscillator(mass=0.05, stiffness=0.0),  # kg, N/m: free
        stops=[vi.Stop(at=0, side="lower", gap=0.0, law="rigid", restitution=RESTITUTION)],
        gravity=vi.Gravity(acceleration=GRAVITY),
        # The phase puts t = 0 in the middle of a flight of the period-one orbit.
        excitations=[
            vi.Base(
                signal=vi.Harmonic(amplitude=gamma * GRAVITY, frequency=FREQUENCY, phase=5.2226)
            )
        ],
        initial=vi.Initial(structure_displacement=[0.015], structure_velocity=[0.16]),
        solver=vi.Solver(method="exact", t_end=1.0),
    )


# %%
# The bifurcation diagram
# -----------------------
# For each :math:`\Gamma`, from the last point's final state, 200 forcing periods settle
# and the approach speed of each impact over the next 32 is sampled: one value on a
# period-one orbit, two after the flip, many where each cycle's chattering sequence spreads
# its impacts over a range of speeds.
gammas = np.linspace(1.2, 2.2, 81)
diagram = vi.bifurcation(
    ball_on_table(1.2),
    "excitation.0.amplitude",
    gammas * GRAVITY,
    settle_periods=200,
    sample_periods=32,
    sample="impact-velocity",
)
omega = 2 * np.pi * FREQUENCY
gamma_flip = np.hypot(
    np.pi * (1 - RESTITUTION) / (1 + RESTITUTION), 2 * (1 + RESTITUTION**2) / (1 + RESTITUTION) ** 2
)
fig, ax = plt.subplots(figsize=(7, 4), layout="constrained")
for point in diagram:
    ax.plot(np.full(len(point.samples), point.value / GRAVITY), point.samples, ",k")
ax.axvline(gamma_flip, color="tab:red", lw=0.8, label=r"$\Gamma_{\rm flip}$ (Holmes)")
ax.axhline(
    2 * np.pi * GRAVITY / (omega * (1 + RESTITUTION)),
    color="tab:blue",
    lw=0.8,
    ls="--",
    label=r"$2\pi g/(\omega(1+e))$",
)
ax.set(xlabel=r"$\Gamma = A\omega^2/g$", ylabel="impact speed (m/s)", title="Bifurcation diagram")
ax.legend(loc="upper left")

# %%
# Poincare sections
# -----------------
# The impact section: each impact's phase in the forcing period and its speed, after
# settling. At :math:`\Gamma = 1.4` the period-one orbit is one point; at 2.1 the 1240
# impacts fall on a few dozen points: a long cycle in which each chattering sequence ends
# with the ball riding the table. It is not chaos: that sticking forgets the state, and
# ``vi.lyapunov`` gives both exponents as :math:`-\infty` (at :math:`e = 0.5`; with a
# livelier ball the cascade goes on to chaos).
sections = {
    gamma: vi.poincare(ball_on_table(gamma), settle_periods=200, periods=400)
    for gamma in (1.4, 2.1)
}
fig, axes = plt.subplots(1, 2, figsize=(9, 3.8), layout="constrained")
for ax, (gamma, section) in zip(axes, sections.items(), strict=True):
    ax.plot(section.impact_phase, section.impact_speed, ".", ms=2)
    ax.set(
        xlabel="impact phase (rad)",
        ylabel="impact speed (m/s)",
        title=rf"$\Gamma = {gamma}$: {len(section.impact_speed)} impacts",
    )

# %%
# Basins of attraction
# --------------------
# At :math:`\Gamma = 1.2` two attractors coexist: the period-one orbit, and a chattering
# motion in which the ball, thrown up when the table falls faster than :math:`g`, lands
# and chatters down to rest on the table every period. Which one a start reaches depends
# on its height (m) and velocity (m/s): indices 0 and 1 of the flat state (x, v).
heights = np.linspace(0.0, 0.03, 21)
speeds = np.linspace(-0.4, 0.4, 21)
basins = vi.basins(
    ball_on_table(1.2), (0, heights), (1, speeds), settle_periods=200, record_periods=20
)
for index, attractor in enumerate(basins.attractors):
    share = np.mean(basins.labels == index)
    print(f"attractor {index}: {attractor}, {100 * share:.0f} % of the starts")
fig, ax = plt.subplots(figsize=(5.5, 4), layout="constrained")
mesh = ax.pcolormesh(
    1e3 * heights, speeds, basins.labels.T, shading="nearest", cmap="tab10", vmin=-3, vmax=6
)
ax.set(
    xlabel="initial height (mm)",
    ylabel="initial velocity (m/s)",
    title=r"Basins at $\Gamma = 1.2$ (label: attractor; -1 unsettled)",
)
fig.colorbar(mesh, ax=ax, label="attractor")
