"""A stiff compliant contact converges to the rigid orbit (Masri and Caughey 1966).

The symmetric orbit with two impacts per forcing period of an impact damper is derived
here in closed form (the helpers are copied from tests/test_analyses.py, not imported;
the formulas are those of /work/shared/reference/forced-oracles.md). The same damper
with a linear spring-dashpot contact (``law = "linear"``, stiffness ``k`` N/m, contact
damper ``c`` N s/m) whose damping is solved for the same restitution ``e`` is shot for
its two-contacts-per-period orbit by ``method = "exact"`` at stiffnesses over several
decades, each seeded on the previous stiffness's orbit (the first on the rigid one).

Damping for a restitution. While they touch, the loose mass ``m`` and the primary ``M``
obey ``m y'' = -F``, ``M x'' = F - K x + f(t)``, ``F = k delta + c delta'`` with the
indentation ``delta``. The contact force grows as ``v sqrt(k m_e)`` without bound while
the primary's spring force and the forcing stay bounded, and the contact lasts
``pi / w_d -> 0``: in the stiff limit the two bodies collide as if free, and the
indentation obeys ``m_e delta'' + c delta' + k delta = 0`` with the two-body effective
mass ``m_e = m M / (m + M)`` (not ``m``: that would be a mass hitting an immovable
wall). Its rebound from ``delta = 0`` to ``delta = 0`` (half a damped period) has the
speed ratio ``e = exp(-zeta pi / sqrt(1 - zeta^2))``, hence
``zeta = -ln e / sqrt(pi^2 + ln^2 e)`` and ``c = 2 zeta sqrt(k m_e)``. Both the
duration and the peak indentation (``v / w``) fall as ``k^-1/2``, so the orbit's
distance from the rigid one does too, to leading order: by ``sqrt(10) = 3.16`` per
decade of stiffness (the reference says "about 2.5"). Solving with ``m`` instead of
``m_e`` gives a different restitution, and the distance stops falling (checked too).
"""

from __future__ import annotations

import itertools
import math
from typing import Any

import numpy as np
import pytest
from numpy.typing import NDArray

from orbit_checks import spectrum_distance, state_error  # noqa: E402
from vibroimpact import analysis as an

Array = NDArray[np.float64]

EXACT: dict[str, Any] = {"method": "exact", "t_end": 1.0}

# SI values behind the scaled parameters: primary M, K, force F0.
from masri_caughey import MC_F0, MC_K, MC_M, masri_caughey, mc_scenario, mc_si  # noqa: E402

# The stable roots of tests/test_analyses.py's MC_CASES: (mu, r, d, e).
CASES = {"two": (0.05, 0.6, 6.0, 0.3), "one": (0.2, 1.2, 4.0, 0.6)}
STIFFNESSES = (1e3, 1e4, 1e5, 1e6)  # N/m: the contact's w / w_n from about 60 to 1e4


# --------------------------------------------------------------------------------------
# The compliant contact


def damping_ratio(e: float) -> float:
    """The damping ratio of a linear spring-dashpot rebounding at ``e``."""
    zeta = -math.log(e) / math.sqrt(math.pi**2 + math.log(e) ** 2)
    # The closed form it inverts: the rebound after half a damped period.
    assert math.exp(-zeta * math.pi / math.sqrt(1 - zeta**2)) == pytest.approx(e, rel=1e-14)
    return zeta


def compliant_scenario(
    mu: float, r: float, d: float, e: float, phase: float, k: float, *, mass: str = "pair"
) -> dict[str, Any]:
    """The damper of ``mc_scenario`` with a linear spring-dashpot of stiffness ``k`` (N/m)
    damped for the restitution ``e`` with the pair's effective mass (``mass = "pair"``)
    or, wrongly, the loose mass alone (``"loose"``)."""
    m = mu * MC_M
    m_e = m * MC_M / (m + MC_M) if mass == "pair" else m
    data = mc_scenario(mu, r, d, e, phase)
    pair = data["damper"][0]
    del pair["restitution"]
    pair.update(law="linear", stiffness=k, damping=2 * damping_ratio(e) * math.sqrt(k * m_e))
    return data


def stiffening(
    params: tuple[float, float, float, float], stiffnesses: tuple[float, ...], mass: str = "pair"
) -> tuple[dict[str, Any], list[an.Orbit]]:
    """The rigid orbit and the compliant orbits at ``stiffnesses`` (ascending), each
    shot from the previous one's state (the first from the rigid orbit's)."""
    mu, r, d, e = params
    root = masri_caughey(mu, r, d, e)[0]  # the larger root: stable in both cases
    assert root["admissible"]
    seed = mc_si(root["mid"])
    found: list[an.Orbit] = []
    for k in stiffnesses:
        run = an.runner(compliant_scenario(mu, r, d, e, root["phase"], k, mass=mass))
        o = an.orbit(run, seed, periods=1)
        found.append(o)
        seed = o.state
    return root, found


@pytest.mark.parametrize("case", list(CASES))
def test_stiff_compliant_orbit_converges_to_the_rigid_orbit(case: str) -> None:
    params = CASES[case]
    e = params[3]
    root, found = stiffening(params, STIFFNESSES)
    mid = mc_si(root["mid"])
    spectrum = np.linalg.eigvals(root["monodromy"])
    assert np.all(np.abs(spectrum) < 1)  # the rigid orbit is stable
    # Two contacts per period, both compliant (no rigid impact left).
    run = an.runner(compliant_scenario(*params, root["phase"], STIFFNESSES[-1]))
    assert list(run.periods(found[-1].state, 1)["contacts"]["kind"]) == ["compliant"] * 2
    errors, distances = [], []
    for o in found:
        assert o.converged
        assert o.impacts_per_period == 2  # two contacts, each of kind "compliant"
        assert o.stable
        errors.append(state_error(o.state, mid))
        distances.append(spectrum_distance(o.floquet_multipliers, spectrum))
    # The state: monotonically closer, by about sqrt(10) per decade of stiffness
    # (the reference's "about 2.5" and the leading order k^-1/2 both within [2.5, 4]).
    factors = [a / b for a, b in itertools.pairwise(errors)]
    assert all(2.5 <= f <= 4.0 for f in factors), (errors, factors)
    assert errors[-1] < 3e-3
    # The leading order k^-1/2: the last two decades within 3 % of sqrt(10).
    assert factors[-2:] == pytest.approx([math.sqrt(10)] * 2, rel=0.03)
    # The multipliers: monotonically closer, over the three decades at least 2.5^3
    # closer, and the stiffest within a few percent of the largest rigid one.
    assert all(b < a for a, b in itertools.pairwise(distances)), distances
    assert distances[0] / distances[-1] >= 2.5**3, distances
    assert distances[-1] < 0.05 * float(np.max(np.abs(spectrum)))
    # The primary's amplitude too, at the same rate.
    amplitude = root["amplitude"] * MC_F0 / MC_K
    misses = [abs(float(o.amplitude[0]) / amplitude - 1) for o in found]
    assert all(2.5 <= a / b <= 4.0 for a, b in itertools.pairwise(misses)), misses
    assert misses[-1] < 5e-3
    # The monodromy's determinant tends to the rigid e^4 (every contact contracts the
    # phase volume by exp(-c t_c / m_e) = e^2, to leading order).
    dets = [float(np.prod(o.floquet_multipliers).real) for o in found]
    assert abs(dets[0] / e**4 - 1) < 0.1
    assert abs(dets[-1] / e**4 - 1) < 5e-3


def test_damping_solved_with_the_loose_mass_alone_misses_the_rigid_orbit() -> None:
    # The check on the choice of m_e: with m in place of m_e, the contact rebounds at
    # another restitution, and the orbit converges to another orbit.
    params = CASES["two"]
    root, found = stiffening(params, STIFFNESSES, mass="loose")
    mid = mc_si(root["mid"])
    errors = [state_error(o.state, mid) for o in found]
    assert all(o.converged for o in found)
    assert errors[-2] / errors[-1] < 1.5, errors  # no longer falling
    _, right = stiffening(params, STIFFNESSES)
    assert errors[-1] > 10 * state_error(right[-1].state, mid)


def test_stiffer_contacts_keep_converging_in_the_multipliers() -> None:
    # Beyond 1e6 N/m the trend of the passing test goes on (dop853 at rtol 1e-13
    # converges at every stiffness here, with the determinant's error falling about
    # 3.2x per decade: -4.0e-3, -1.3e-3, -3.8e-4, -1.1e-4 from 1e5 to 1e8).
    params = CASES["two"]
    e = params[3]
    root, found = stiffening(params, (1e5, 1e6, 1e7, 1e8))
    spectrum = np.linalg.eigvals(root["monodromy"])
    assert all(o.converged for o in found), [o.residual for o in found]
    distances = [spectrum_distance(o.floquet_multipliers, spectrum) for o in found]
    deviations = [abs(float(np.prod(o.floquet_multipliers).real) / e**4 - 1) for o in found]
    assert all(a / b >= 2.0 for a, b in itertools.pairwise(distances)), distances
    assert all(a / b >= 2.0 for a, b in itertools.pairwise(deviations)), deviations
