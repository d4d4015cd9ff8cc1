"""What each scenario key means, for the format reference (``scenario_reference``).

The keys, their types, defaults and the solver's ranges come from the code (the schemas in
``vibroimpact.system.schema`` and ``vibroimpact.scenario.two_mass``, the analyses' in
``vibroimpact.analysis.settings`` and ``vibroimpact.study.settings``, the core registry
``vibroimpact.METHOD_OPTIONS``, the units of ``vibroimpact.units``). This table adds
the meaning, and the unit and range where the code holds none. The build fails on a key of
a schema missing here, on an entry here that no schema has, and on a unit here that differs
from the code's: so the reference cannot drift from the format.

section -> key -> (unit or None, range or None, meaning).
"""

from __future__ import annotations

_LAW = {
    "law": (None, None, "the contact law"),
    "stiffness": (
        'N m-1.5 (N m-1 for "linear")',
        "> 0",
        'the compliant law\'s stiffness K_hz (k1 for "linear"); not for "rigid"',
    ),
    "restitution": (
        "1",
        '[0, 1] for "rigid", (0, 1] for "hyster-hertz" and "hertz-damped"',
        "Newton's coefficient e (\"rigid\") or the compliant law's target rebound ratio",
    ),
    "damping": ("N s m-1", ">= 0", "the contact damper c1 (compliant laws only)"),
}
_POINT = "a coordinate index, or m from the clamp along a cantilever"
_SOLVER = {
    "method": (None, None, "the integration method"),
    "dt": ("s", "> 0", "the step of the fixed-step methods, the first step of the adaptive"),
    "t_end": ("s", "> 0", "the end of the run (fixed steps: rounded up to whole steps)"),
    "stepping": (
        None,
        '"fixed" or "events"',
        '"events" locates every contact to round-off; "fixed" (the fixed-step methods, '
        "compliant laws) does not cut steps at contacts",
    ),
    "beta": (None, None, "Newmark's beta"),
    "gamma": (None, None, "Newmark's gamma"),
    "spectral_radius": ("1", None, "generalized-alpha's high-frequency spectral radius"),
    "rtol": (None, None, "the adaptive methods' relative tolerance"),
    "atol": ("m and m s-1", None, "the adaptive methods' absolute tolerance"),
    "max_steps": (None, None, "the most steps a run may take"),
    "contact_timing": (
        None,
        '"located" or "step-count"',
        "fixed stepping: contact instants located inside the step, or counted in whole steps "
        "as the founding paper did",
    ),
    "energy_tolerance": (
        "1",
        "(0, 1]",
        "the relative miss allowed in the run's energy balance",
    ),
    "max_rows": ("1", ">= 1", "the most history rows plus contacts a run may keep"),
}
_OUTPUT = {
    "every": ("1", ">= 1", "keep every N-th step of the history"),
    "history": (None, "true or false", "false keeps no history at all"),
}

TWO_MASS = {
    "system": {
        "main_mass": ("kg", "> 0", "M, the main mass"),
        "stiffness": ("N m-1", ">= 0", "K, the main spring"),
        "damping": ("N s m-1", ">= 0", "C, the main damper"),
        "impact_mass": ("kg", "> 0", "m, the loose impact mass"),
        "clearance": ("m", ">= 0", "d, the clearance on each side of the impact mass"),
    },
    "contact": {
        **_LAW,
        "law": (None, '"hertz", "hyster-hertz", "hertz-damped" or "linear"', "the contact law"),
        "stiffness": (
            'N m-1.5 (N m-1 for "linear")',
            "> 0",
            'the law\'s stiffness K_hz (k1 for "linear")',
        ),
        "restitution": (
            "1",
            '(0, 1]; required by "hyster-hertz" and "hertz-damped" only',
            "the law's restitution e",
        ),
    },
    "initial": {
        "main_displacement": ("m", None, "w at t = 0"),
        "main_velocity": ("m s-1", None, "w' at t = 0"),
        "impact_displacement": ("m", None, "y at t = 0"),
        "impact_velocity": ("m s-1", None, "y' at t = 0"),
    },
    "solver": _SOLVER,
    "output": _OUTPUT,
}

SYSTEM = {
    "structure": {
        "kind": (None, '"oscillator", "matrices" or "cantilever"', "the kind of structure"),
        "mass": (
            "kg",
            "> 0; matrices: symmetric positive definite",
            "the oscillator's mass, or the mass matrix (an array of rows)",
        ),
        "stiffness": (
            "N m-1",
            ">= 0; matrices: symmetric positive semi-definite",
            "the oscillator's spring, or the stiffness matrix",
        ),
        "damping": (
            "N s m-1",
            ">= 0; matrices: symmetric positive semi-definite (default zeros)",
            "the oscillator's damper, or the damping matrix",
        ),
        "length": ("m", "> 0", "the cantilever's length"),
        "youngs_modulus": ("Pa", "> 0", "Young's modulus E (else the material's)"),
        "second_moment": (
            "m4",
            "> 0",
            "the second moment of area I of the section (or give section and its dimensions)",
        ),
        "mass_per_length": (
            "kg m-1",
            "> 0",
            "the mass per unit length (or give density or material, and a section)",
        ),
        "section": (None, '"rectangle", "circle" or "tube"', "the beam's cross-section"),
        "width": ("m", "> 0", "a rectangle's width (bending about the axis along it)"),
        "height": ("m", "> 0", "a rectangle's height, in the plane of bending"),
        "diameter": ("m", "> 0", "a circle's diameter"),
        "outer_diameter": ("m", "> 0", "a tube's outer diameter"),
        "inner_diameter": ("m", "> 0 and < outer_diameter", "a tube's inner diameter"),
        "material": (
            None,
            '"steel", "aluminium" or "titanium"',
            "a named material's Young's modulus and density (cited in vibroimpact.system.beam)",
        ),
        "density": ("kg m-3", "> 0", "the material's density (instead of mass_per_length)"),
        "modes": ("1", "[1, 200]", "the modes kept (modal coordinates)"),
        "damping_ratio": ("1", "[0, 1]", "every mode's damping ratio"),
    },
    "damper": {
        "mass": ("kg", "> 0", "the loose mass"),
        "at": (None, _POINT, "the point it rattles against"),
        "clearance": ("m", ">= 0", "the clearance on each side"),
        "lower_clearance": (
            "m",
            ">= 0 or inf",
            "the clearance below (instead of clearance); inf: no wall below",
        ),
        "upper_clearance": (
            "m",
            ">= 0 or inf",
            "the clearance above (instead of clearance); inf: no wall above",
        ),
        **_LAW,
        "law": (
            None,
            '"rigid", "hertz", "hyster-hertz", "hertz-damped" or "linear"',
            "the contact law",
        ),
        "friction": (
            None,
            ">= 0",
            "Coulomb's kinetic coefficient between the mass and its carrier (a horizontal "
            "damper sliding on its cavity's floor); needs normal_force",
        ),
        "static_friction": (
            None,
            ">= friction",
            "the static coefficient: stuck, the mass holds while the force needed is within "
            "static_friction * normal_force (default: friction)",
        ),
        "normal_force": (
            "N",
            ">= 0",
            "the force pressing the mass on its floor: its weight, or a preload",
        ),
    },
    "stop": {
        "at": (None, _POINT, "the point that hits the stop"),
        "side": (
            None,
            '"upper" or "lower"',
            '"upper" keeps the point at or below +gap, "lower" at or above -gap',
        ),
        "gap": ("m", ">= 0", "the distance to the stop"),
        "against": (
            None,
            _POINT,
            "a second point that carries the stop, so that the two pound on each other",
        ),
        **_LAW,
        "law": (
            None,
            '"rigid", "hertz", "hyster-hertz", "hertz-damped" or "linear"',
            "the contact law",
        ),
    },
    "friction": {
        "at": (None, _POINT, "the point of the structure that rubs"),
        "against": (
            None,
            _POINT,
            "the point it rubs on (default: the base, or the ground)",
        ),
        "coefficient": (None, ">= 0", "Coulomb's kinetic coefficient"),
        "static_coefficient": (
            None,
            ">= coefficient",
            "the static coefficient: stuck while the force needed is within "
            "static_coefficient * normal_force (default: coefficient)",
        ),
        "normal_force": ("N", ">= 0", "the force pressing the two sides together"),
    },
    "collision": {
        "dampers": (
            None,
            "two different damper indices",
            "[i, j]: damper i below damper j along the axis",
        ),
        "gap": (
            "m",
            ">= 0",
            "their free distance at rest: they touch when i's displacement minus j's reaches it",
        ),
        **_LAW,
        "law": (
            None,
            '"rigid", "hertz", "hyster-hertz", "hertz-damped" or "linear"',
            "the contact law",
        ),
    },
    "gravity": {"acceleration": ("m s-2", ">= 0", "along -x, on every mass")},
    "excitation": {
        "kind": (
            None,
            '"force" or "base"',
            "a force at a point, or a support acceleration (every coordinate is relative to "
            "the base)",
        ),
        "at": (None, _POINT, 'the point a force acts at (kind "force" only)'),
        "signal": (
            None,
            '"harmonic", "sweep", "harmonics", "recorded", "white-noise" or "kanai-tajimi"',
            "the signal's shape",
        ),
        "amplitude": (
            "N (force) or m s-2 (base)",
            None,
            '"harmonic": amplitude cos(2 pi frequency t + phase); "sweep" likewise',
        ),
        "frequency": ("Hz", ">= 0", '"harmonic"\'s frequency'),
        "phase": ("rad", None, '"harmonic" and "sweep" (default 0)'),
        "start_frequency": (
            "Hz",
            '>= 0 (linear sweep), > 0 ("logarithmic")',
            '"sweep"\'s frequency at t = 0',
        ),
        "end_frequency": (
            "Hz",
            '>= 0 (linear sweep), > 0 ("logarithmic")',
            '"sweep"\'s frequency at its duration',
        ),
        "duration": (
            "s",
            "> 0",
            '"sweep", "white-noise", "kanai-tajimi": how long (default t_end)',
        ),
        "sweep": (None, '"linear" or "logarithmic"', '"sweep"\'s law of frequency'),
        "amplitudes": ("N (force) or m s-2 (base)", None, '"harmonics": one per term'),
        "frequencies": ("Hz", ">= 0", '"harmonics": one per amplitude (0: a constant term)'),
        "phases": ("rad", None, '"harmonics": one per amplitude (default 0)'),
        "file": (
            None,
            "a CSV of time and value, at most 64 MiB",
            '"recorded": read relative to the scenario',
        ),
        "time": ("s", "increasing strictly, at least two", '"recorded": the sample times'),
        "value": ("N (force) or m s-2 (base)", None, '"recorded": the samples'),
        "scale": ("1", None, '"recorded": a factor on every value (default 1)'),
        "intensity": (
            "N2 s (force) or m2 s-3 (base)",
            ">= 0",
            '"white-noise", "kanai-tajimi": two-sided spectral density S0 per rad/s',
        ),
        "cutoff_frequency": ("Hz", "> 0", "random signals: the band's upper end"),
        "ground_frequency": ("Hz", "> 0", '"kanai-tajimi": the ground filter\'s frequency'),
        "ground_damping": ("1", "> 0", '"kanai-tajimi": the ground filter\'s damping ratio'),
        "seed": (
            "1",
            "a whole number",
            "random signals (required): the same seed, the same samples",
        ),
    },
    "initial": {
        "structure_displacement": ("m", None, "the structure's coordinates at t = 0 (zeros)"),
        "structure_velocity": ("m s-1", None, "their rates at t = 0 (zeros)"),
        "damper_displacement": ("m", None, "each loose mass's own displacement (zeros)"),
        "damper_velocity": ("m s-1", None, "each loose mass's velocity (zeros)"),
    },
    "solver": _SOLVER,
    "output": {
        **_OUTPUT,
        "record_from": (
            "s",
            ">= 0",
            "the located peaks and RMS (peak, rms, point_*, moment_*) from this time on; the "
            "history, contacts, strobe and energy balance still start at t = 0",
        ),
        "strobe_period": (
            "s",
            "> 0",
            "keep the state once every period (Poincare section); an adaptive method steps "
            "onto each of its instants, so its steps differ (within rtol) from a run without",
        ),
        "points": (None, _POINT, "structure points whose displacement every reduction follows"),
        "moments": (
            "m",
            "[0, length], a cantilever only",
            "positions from the clamp whose bending moment E I w'' (N m) every reduction follows",
        ),
    },
}

_PARAMETER = 'a dotted path to a number of the scenario, such as "excitation.0.frequency"'
_SETTLE = (
    "1",
    ">= 0",
    "forcing periods run and forgotten before recording (settle plus record: at most 10^7)",
)
_RECORD = ("1", ">= 1", "forcing periods recorded once settled")
_SETTLED = (
    "1",
    "> 0",
    "the stroboscopic state repeats within this, relative to the size of the motion",
)
_VALUES_AXIS = {
    "start": ("the parameter's", 'finite; > 0 for spacing = "log"', "the first value"),
    "stop": ("the parameter's", 'finite; > 0 for spacing = "log"', "the last value"),
    "count": (
        "1",
        ">= 1; >= 2 where stop differs from start",
        "how many values, start and stop among them",
    ),
    "spacing": (None, '"linear" or "log"', "even steps, or an even ratio"),
}

ANALYSES = {
    "sweep": {
        **_VALUES_AXIS,
        "parameter": (None, _PARAMETER, "the parameter swept"),
        "count": (
            "1",
            "[1, 100000]; >= 2 where stop differs from start",
            "how many values, start and stop among them",
        ),
        "direction": (
            None,
            '"up", "down" or "both"',
            "each value starts from the last one's settled state: in increasing order, "
            'decreasing, or "up" then "down" (hysteresis)',
        ),
        "settle_periods": _SETTLE,
        "record_periods": _RECORD,
        "tolerance": _SETTLED,
        "derivatives": (
            None,
            "an array of dotted paths to numbers of the scenario",
            "sweep only: at each point, the derivatives of the orbit through its settled "
            "state in each (its amplitude's, m per unit of the parameter), as --derivative "
            "(default none)",
        ),
        "sample": (
            None,
            '"displacement", "impact-velocity" or "impact-phase"',
            "bifurcation only: coordinate 0's displacement once a period (m), or at each "
            "impact its approach speed (m s-1) or its phase w t modulo 2 pi (rad)",
        ),
        "pair": (
            None,
            'a pair of the scenario, such as "stop 0" or "damper 1"',
            'bifurcation, "impact-velocity" and "impact-phase" only: whose impacts (default '
            "every pair's)",
        ),
    },
    "continuation": {
        "parameter": (None, _PARAMETER, "the parameter continued, from the scenario's value"),
        "stop": ("the parameter's", None, "the value the branch is continued to"),
        "periods": ("1", "[1, 10000000]", "K: the orbit's period in forcing periods"),
        "step": ("the parameter's", "> 0", "the step along the branch, about (default chosen)"),
        "max_points": ("1", "[2, 100000]", "the most points the branch may have"),
        "tolerance": ("1", "(0, 1)", "the shooting's Newton tolerance on the orbit"),
        "switch": (
            None,
            "true or false",
            "at the first located flip, go on along the period-doubled branch (JSON switched)",
        ),
    },
    "curve": {
        "kind": (
            None,
            '"flip", "fold", "neimark-sacker" or "grazing"',
            "the bifurcation followed (every pair rigid: the multipliers come from the "
            "tangent flow; a grazing: where the orbit touches a stop at zero speed)",
        ),
        "parameter": (
            None,
            _PARAMETER,
            "the first parameter: the bifurcation is located along the orbit's branch in it",
        ),
        "start": ("the parameter's", "finite", "where the branch starts (the orbit found there)"),
        "stop": ("the parameter's", "finite, not start", "where the search for it ends"),
        "second": (None, _PARAMETER + ", not parameter", "the second parameter, followed"),
        "second_stop": (
            "the second's",
            "finite",
            "where the curve ends (it starts at the scenario's value of second)",
        ),
        "step": ("the second's", "> 0", "the step in the second parameter (halved where needed)"),
        "periods": ("1", "[1, 10000000]", "K: the orbit's period in forcing periods"),
        "max_points": ("1", "[2, 100000]", "the most points the curve may have"),
        "tolerance": ("1", "(0, 1)", "the Newton tolerance on the orbit"),
    },
    "basins": {
        "x": (None, "a table: state, start, stop, count", "the grid's first axis"),
        "y": (None, "a table: state, start, stop, count", "its second, another entry"),
        "settle_periods": _SETTLE,
        "record_periods": _RECORD,
        "tolerance": _SETTLED,
    },
    "basins.x": {
        "state": (
            None,
            '"structure_displacement", "structure_velocity", "damper_displacement" or '
            '"damper_velocity" with an index, such as "structure_displacement.0"',
            "the entry of [initial] the axis varies",
        ),
        "start": ("m or m s-1", "finite", "its first value"),
        "stop": ("m or m s-1", "finite", "its last value"),
        "count": (
            "1",
            ">= 1; >= 2 where stop differs from start",
            "how many values (x count times y count at most 10^6)",
        ),
    },
    "study": {
        "analysis": (
            None,
            '"run", "steady-state" or "orbit"',
            '"run": each point to [solver] t_end; "steady-state": settle then record; '
            '"orbit": settle, then shoot a periodic orbit and its stability',
        ),
        "metrics": (
            None,
            '"peak", "rms", "impacts", "energy_dissipated" (run, steady-state); '
            '"amplitude", "impacts_per_period", "settled" (steady-state); "amplitude", '
            '"impacts_per_period", "stable", "largest_multiplier" (orbit); '
            '"largest_lyapunov" (any: 1/s, every pair rigid); "point_peak", '
            '"point_rms", "point_amplitude", "moment_peak"...',
            'what each point keeps (default "peak", "rms", "impacts"; an orbit\'s four for '
            '"orbit")',
        ),
        "settle_periods": _SETTLE,
        "record_periods": _RECORD,
        "orbit_periods": ("1", ">= 1", '"orbit": K, the orbit\'s period in forcing periods'),
        "record_from": (
            "s",
            ">= 0",
            '"run": metrics from this time on (default [output] record_from, else 0)',
        ),
        "tolerance": _SETTLED,
        "chunk_size": ("1", ">= 1", "runs per chunk: the most an interruption can lose"),
        "samples": (
            "1",
            "0 without [study.random], >= 1 with it",
            "the random draws at each point of the grid",
        ),
        "seed": ("1", "a whole number", "the seed of every [study.random] draw"),
        "stepping": (
            None,
            '"events" or "fixed"',
            '"fixed" runs the points in lockstep at [solver] dt (analysis = "run"; '
            'metrics "peak", "rms", "impacts")',
        ),
        "axes": (None, "see [study.axes]", "the grid: one axis per parameter"),
        "random": (None, "see [study.random]", "parameters drawn at random for each sample"),
    },
    "study.axes": {
        "<parameter>": (
            "the parameter's",
            "a list of numbers, or a table: start, stop, count, spacing",
            'a dotted path such as "damper.0.mass" (quoted) = its values; the study runs '
            "every combination (10^7 runs at most)",
        ),
    },
    "study.random": {
        "<parameter>": (
            "the parameter's",
            "{uniform = [low, high]}, {normal = [mean, std]}; a seed: {from = N}",
            "a dotted path (quoted) = its distribution, drawn [study] samples times "
            "(a seed: N, N + 1, ...)",
        ),
    },
}
