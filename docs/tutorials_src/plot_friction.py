"""
Dry friction: stick-slip, from a block to a horizontal impact damper
====================================================================

Coulomb friction acts along the axis between two sides that slide on each other: while
they slide, a force ``coefficient * normal_force`` opposes their relative velocity; when
it reaches zero they stick if the force needed to hold them together is within
``static_coefficient * normal_force``, and slip again where it no longer is. Both
transitions are events, located to round-off like impacts. A scenario gives friction in
two places: a ``[[damper]]``'s ``friction``, ``static_friction`` and ``normal_force``
(between the loose mass and its carrier, as a ball sliding on its cavity's floor), and
``[[friction]]`` elements between points of the structure or to the ground (a
dry-friction damper). This tutorial checks the free decay against its closed form, then
follows a horizontal impact damper and where its energy goes.
"""

# %%
# The free decay with Coulomb friction
# ------------------------------------
# A 2 kg mass on an 800 N/m spring rubs on the ground with 3 N sliding and 4 N static
# (``[[friction]]`` at the structure's coordinate, against the ground). From 51.3 mm
# each half cycle swings about the offset ``a = F / k`` and loses ``2 a`` of amplitude;
# the mass stops at the first turning point inside ``|x| <= F_s / k`` (5 mm), and the
# spring's energy lost is the friction's, in the ledger's ``friction``.
import matplotlib.pyplot as plt
import numpy as np

import vibroimpact as vi

MASS, STIFFNESS, KINETIC, STATIC, NORMAL, X0 = 2.0, 800.0, 0.3, 0.4, 10.0, 0.0513
decay_system = vi.System(
    structure=vi.Oscillator(mass=MASS, stiffness=STIFFNESS, damping=0.0),
    frictions=[
        vi.Friction(at=0, coefficient=KINETIC, static_coefficient=STATIC, normal_force=NORMAL)
    ],
    initial=vi.Initial(structure_displacement=[X0]),
)
decay = vi.simulate(decay_system, method="exact", t_end=1.2)
offset, band = KINETIC * NORMAL / STIFFNESS, STATIC * NORMAL / STIFFNESS
turning = [X0]
while abs(turning[-1]) > band:
    x = turning[-1]
    turning.append(-(x - 2 * offset * np.sign(x)))
print(f"closed form's turning points (mm): {np.round(np.array(turning) * 1e3, 6)}")
print(
    f"at rest at {decay.final_state['structure_displacement'][0] * 1e3:.9f} mm; "
    f"friction took {decay.energy['friction']:.9f} J, the spring lost "
    f"{0.5 * STIFFNESS * (X0**2 - turning[-1] ** 2):.9f} J"
)
print(decay.contacts.to_pandas()[["pair", "kind", "onset"]])

fig, ax = plt.subplots(figsize=(7, 3))
ax.plot(decay.t, decay.structure_displacement[:, 0] * 1e3)
ax.axhspan(-band * 1e3, band * 1e3, color="0.9", label="static band |x| <= F_s / k")
ax.set_xlabel("time (s)")
ax.set_ylabel("x (mm)")
ax.legend()

# %%
# A horizontal impact damper
# --------------------------
# A 0.1 kg ball in a +-10 mm cavity of a one-mode structure forced at 10 Hz with 30 N
# (``examples/horizontal_friction_damper.toml`` forces it with 5 N): it strikes the
# walls (``e = 0.6``), chatters onto them and rides along, and slides on the floor
# with ``mu = 0.2`` under its weight (0.3 static). The contacts table holds the impacts
# and the stuck intervals (``"damper 0 friction"``, kind ``"sticking"``); the ledger
# splits the losses.
forced = vi.System(
    structure=vi.Oscillator(mass=1.0, stiffness=4000.0, damping=2.0),
    dampers=[
        vi.Damper(
            mass=0.1,
            at=0,
            clearance=0.01,
            law="rigid",
            restitution=0.6,
            friction=0.2,
            static_friction=0.3,
            normal_force=0.1 * 9.81,
        )
    ],
    excitations=[vi.Force(at=0, signal=vi.Harmonic(amplitude=30.0, frequency=10.0))],
)
response = vi.simulate(forced, method="exact", t_end=2.0)
table = response.contacts.to_pandas()
print(table.groupby(["pair", "kind"]).size())
energy = response.energy
print(
    {
        key: round(energy[key], 4)
        for key in ("input_work", "viscous", "impact", "friction", "stored_end", "residual")
    }
)

fig, ax = plt.subplots(figsize=(7, 3))
relative = response.damper_displacement[:, 0] - response.structure_displacement[:, 0]
ax.plot(response.t, relative * 1e3, lw=0.8)
for row in table[table.pair == "damper 0 friction"].itertuples():
    ax.axvspan(row.onset, row.separation, color="C1", alpha=0.3, lw=0)
ax.set_xlabel("time (s)")
ax.set_ylabel("ball in its cavity (mm)")
ax.set_title("shaded: stuck to the cavity's floor")

# %%
# The stability of a stick-slip orbit
# -----------------------------------
# The tangent flow passes through stick-slip: each stop, stick and slip jumps it by its
# saltation matrix. A 1 kg, 100 N/m oscillator rubbing on the ground (1 N sliding,
# 1.6 N static) and forced with 4 N at 0.8 Hz sticks once a cycle. Its orbit's Floquet
# multipliers come from that flow; one is zero, because a stick forgets the velocity it
# started with: every nearby start that sticks leaves the stuck interval at rest. The
# monodromy by central differences of whole runs agrees.
import vibroimpact.analysis as an  # noqa: E402

rubbing = vi.System(
    structure=vi.Oscillator(mass=1.0, stiffness=100.0, damping=0.5),
    frictions=[vi.Friction(at=0, coefficient=1.0, static_coefficient=1.6, normal_force=1.0)],
    excitations=[vi.Force(at=0, signal=vi.Harmonic(amplitude=4.0, frequency=0.8))],
    initial=vi.Initial(structure_velocity=[1e-3]),
    solver=vi.Solver(t_end=1.0, method="exact"),
)
orbit = an.orbit(rubbing)
checked = an.orbit(rubbing, orbit.state, jacobian="differences")
print(f"Floquet multipliers (tangent flow): {np.round(orbit.floquet_multipliers, 9)}")
print(f"  by differences of whole runs:     {np.round(checked.floquet_multipliers, 9)}")
cycle = vi.simulate(
    rubbing.replace(
        initial=vi.Initial(
            structure_displacement=[orbit.state[0]], structure_velocity=[orbit.state[1]]
        ),
        solver=vi.Solver(t_end=2.5, method="exact"),
    )
)
fig, ax = plt.subplots(figsize=(5, 3.5))
ax.plot(cycle.structure_displacement[:, 0] * 1e3, cycle.structure_velocity[:, 0])
ax.set_xlabel("x (mm)")
ax.set_ylabel("v (m/s)")
ax.set_title("the orbit: stuck where v = 0 for a while")
plt.show()
