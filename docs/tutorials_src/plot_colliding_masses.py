"""
Loose masses that collide: from two masses to a particle column
================================================================

Multi-unit and particle-column dampers hold several loose masses in one cavity, which
strike each other as well as the cavity's walls. In a scenario each such pair is a
``[[collision]]``: ``dampers = [i, j]`` (damper ``i`` below damper ``j`` along the axis),
their free distance at rest ``gap`` (m), and a contact law as for any pair. This tutorial
checks one rigid collision against Newton's law, shows what a row of touching masses does
when struck (rigid and Hertzian), and then shakes a column of particles in a cavity.
"""

# %%
# Two masses, one collision
# -------------------------
# Two loose masses on a carrier that does not move (no wall within reach: the lower
# has a floor 1 m below, the upper a ceiling 1 m above, and ``inf`` leaves the other
# sides open). The lower (100 g) rises at 1 m/s towards the upper (300 g), which comes
# down at 0.5 m/s, 10 mm away. Newton's law with restitution ``e``: they part at ``e``
# times their closing speed, with their momentum kept, and lose
# :math:`\tfrac12 \mu (1 - e^2) v^2` (:math:`\mu` the reduced mass).
import math

import matplotlib.pyplot as plt

import vibroimpact as vi

LOWER, UPPER, RESTITUTION, GAP = 0.1, 0.3, 0.7, 0.01  # kg, kg, -, m
carrier = vi.Oscillator(mass=1.0, stiffness=100.0, damping=0.0)
rigid = {"law": "rigid", "restitution": RESTITUTION}
pair = vi.System(
    structure=carrier,
    dampers=[
        vi.Damper(mass=LOWER, at=0, lower_clearance=1.0, upper_clearance=math.inf, **rigid),
        vi.Damper(mass=UPPER, at=0, lower_clearance=math.inf, upper_clearance=1.0, **rigid),
    ],
    collisions=[vi.Collision(dampers=(0, 1), gap=GAP, **rigid)],
    initial=vi.Initial(damper_velocity=[1.0, -0.5]),
)
two = vi.simulate(pair, method="exact", t_end=0.05)
print(two.contacts.to_pandas()[["pair", "onset", "approach_speed", "rebound_speed"]])
velocities = two.final_state["damper_velocity"]
reduced = LOWER * UPPER / (LOWER + UPPER)
print(
    f"velocities after: {velocities}; momentum {LOWER * velocities[0] + UPPER * velocities[1]:.6f}"
    f" kg m/s (before {LOWER * 1.0 - UPPER * 0.5:.6f}); loss {two.energy['impact']:.6f} J, "
    f"Newton's {0.5 * reduced * (1 - RESTITUTION**2) * 1.5**2:.6f} J"
)


# %%
# A row of touching masses, struck
# --------------------------------
# Three equal masses, the last two touching, the first arriving at 1 m/s. With rigid
# contacts both close at one instant and are resolved together (one complementarity
# problem, as for any simultaneous impacts): the touching pair stays together, so with
# ``e = 1`` the first leaves at -1/3 and the pair at 2/3 each. That is not a Newton's
# cradle: a cradle's answer (the first stops, the last leaves at 1 m/s) needs the
# contacts to act one after the other, which a compliant law gives, as a wave running
# along the row.
def row(law: dict[str, float | str]) -> vi.System:
    ends = {"lower_clearance": math.inf, "upper_clearance": math.inf}
    return vi.System(
        structure=carrier,
        dampers=[
            vi.Damper(mass=0.1, at=0, lower_clearance=1.0, upper_clearance=math.inf, **law),
            vi.Damper(mass=0.1, at=0, **ends, **law),
            vi.Damper(mass=0.1, at=0, lower_clearance=math.inf, upper_clearance=1.0, **law),
        ],
        collisions=[
            vi.Collision(dampers=(0, 1), gap=0.01, **law),
            vi.Collision(dampers=(1, 2), gap=0.0, **law),
        ],
        initial=vi.Initial(damper_velocity=[1.0, 0.0, 0.0]),
    )


ROW_RIGID = vi.simulate(row({"law": "rigid", "restitution": 1.0}), method="exact", t_end=0.05)
ROW_HERTZ = vi.simulate(
    row({"law": "hertz", "stiffness": 1e9}),
    method="dop853",
    t_end=0.05,
    rtol=1e-11,
    atol=1e-14,
    dt=1e-6,
)
fig, ax = plt.subplots(figsize=(7, 3.5), layout="constrained")
for j in range(3):
    ax.plot(1e3 * ROW_HERTZ.t, ROW_HERTZ.damper_velocity[:, j], label=f"mass {j} (Hertz)")
    ax.axhline(ROW_RIGID.final_state["damper_velocity"][j], color=f"C{j}", ls=":", lw=1)
ax.set_xlim(9.9, 10.2)
ax.set_xlabel("time (ms)")
ax.set_ylabel("velocity (m/s)")
ax.set_title("Hertzian contacts pass the impact on as a wave; dotted: rigid, all at once")
ax.legend(fontsize=8)
plt.show()
print("rigid:", ROW_RIGID.final_state["damper_velocity"])
print("Hertz:", ROW_HERTZ.final_state["damper_velocity"])

# %%
# A column of particles in a forced cavity
# ----------------------------------------
# As ``examples/particle_column.toml``: particles stacked 2 mm apart in a cavity on a
# forced 15 Hz structure, under gravity: only the lowest reaches the floor and only
# the highest the ceiling, so the others have no wall of their own (``inf`` on both
# sides; a collision holds them). Here the same cavity is filled with 50 g of
# particles in one, two or five pieces, and the structure's steady amplitude is
# compared: the force's work goes to the structure's damper and to the contacts.
CAVITY = vi.System(
    structure=vi.Oscillator(mass=1.0, stiffness=8883.0, damping=9.42),  # 15 Hz, 5 %
    gravity=vi.Gravity(acceleration=9.81),
    excitations=[vi.Force(at=0, signal=vi.Harmonic(amplitude=25.0, frequency=10.0))],
    solver=vi.Solver(method="dop853", t_end=4.0),
)
TOTAL = 0.05  # kg of particles


def filled(count: int) -> vi.System:
    law = {"law": "hertz-damped", "stiffness": 1e8, "restitution": 0.6}
    dampers = [
        vi.Damper(
            mass=TOTAL / count,
            at=0,
            lower_clearance=0.002 if j == 0 else math.inf,
            upper_clearance=0.03 if j == count - 1 else math.inf,
            **law,
        )
        for j in range(count)
    ]
    collisions = [vi.Collision(dampers=(j, j + 1), gap=0.002, **law) for j in range(count - 1)]
    return CAVITY.replace(dampers=dampers, collisions=collisions)


COUNTS = (1, 2, 5)
RUNS = {n: vi.simulate(filled(n), t_end=4.0, record_from=2.0) for n in COUNTS}
fig, ax = plt.subplots(figsize=(7, 3.5), layout="constrained")
for n, sol in RUNS.items():
    ax.plot(sol.t, 1e3 * sol.structure_displacement[:, 0], lw=0.7, label=f"{n} particle(s)")
    energy = sol.energy
    print(
        f"{n} particle(s): peak {1e3 * sol.peak[0]:.2f} mm after 2 s, {len(sol.contacts)} "
        f"contacts, contacts' loss {energy['contact']:.3f} J of the force's "
        f"{energy['input_work']:.3f} J (balance residual {energy['residual']:.1e} J)"
    )
ax.set_xlabel("time (s)")
ax.set_ylabel("structure (mm)")
ax.legend(fontsize=8)
plt.show()

# %%
# The contacts' share of the force's work is read from each run's energy ledger
# (``energy["contact"]``, the sum of every contact's ``energy_dissipated``), which closes
# to its residual. Splitting the same mass into more particles multiplies the contacts;
# whether it lowers the structure's response depends on the forcing, the gaps and the
# restitution: a study over ``collision.N.gap`` or the particles' number answers it for
# a given design.
