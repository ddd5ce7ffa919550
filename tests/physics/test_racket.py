"""The racket's twist [VMS17; VMS20]: the separatrix formula against the twist read off the exact
attitude of tosses ever closer to the middle axis, and off a DOP853 integration that uses no closed
form; its bounds, and the ideal-racket limit."""

from __future__ import annotations

import math

import numpy as np
import pytest

from poinsot.physics import FreeRigidBody, attitude_with_L_along_z
from poinsot.physics.models.flip import flip_initial_omega
from poinsot.physics.models.racket import LIMIT_ACCURACY, measure_twist, separatrix_twist

BRODY = (0.00121, 0.01638, 0.01748)
BODIES = [BRODY, (0.077, 0.925, 1.0), (1.0, 2.0, 3.0), (0.3, 0.5, 1.0)]


def toss(inertia: tuple[float, float, float], epsilon: float, azimuth: float) -> FreeRigidBody:
    w0 = flip_initial_omega(epsilon, 2.0, azimuth)
    return FreeRigidBody(inertia, w0, attitude_with_L_along_z(inertia, w0))


@pytest.mark.parametrize("inertia", BODIES)
@pytest.mark.parametrize("azimuth", [0.0, 1.0, math.pi / 2])
def test_measured_twist_tends_to_the_formula(
    inertia: tuple[float, float, float], azimuth: float
) -> None:
    theory = separatrix_twist(inertia)
    gaps = []
    for epsilon in (1e-2, 1e-3, 1e-5):
        body = toss(inertia, epsilon, azimuth)
        m = measure_twist(body)
        assert m.handle_turn == pytest.approx(2 * math.pi, abs=1e-12)
        assert m.start < m.flip < m.end
        gap = abs(m.twist - float(theory.twist))
        bound = LIMIT_ACCURACY * body.complementary_parameter * math.cosh(float(theory.tau)) ** 2
        assert gap <= bound
        gaps.append(gap)
    assert gaps[-1] < 1e-8
    # Inside the bounds once the toss is close enough to e2.
    m = measure_twist(toss(inertia, 1e-5, azimuth))
    assert float(theory.defect_low) <= m.defect <= float(theory.defect_high)


def test_bounds_bracket_the_formula_and_a_stack_is_vectorised() -> None:
    th = separatrix_twist(np.array(BODIES))
    assert th.twist.shape == (4,)
    assert np.all(th.defect_low <= th.defect) and np.all(th.defect <= th.defect_high)
    single = separatrix_twist(BRODY)
    assert float(single.defect) == pytest.approx(float(th.defect[0]), rel=1e-15)
    # tau solves tau - A(tanh tau) = pi r: the handle's turn integrated by quadrature is 2 pi.
    from scipy import integrate

    I1, I2, I3 = BRODY
    a = (I3 - I2) / (I3 - I1)
    b = I1 / I2 * a

    def rate(t: float) -> float:
        s = 1 / math.cosh(t) ** 2
        return (1 - a * s) / (1 - b * s)

    turn, _ = integrate.quad(rate, -float(single.tau), float(single.tau), epsabs=1e-14)
    assert turn / float(single.ratio) == pytest.approx(2 * math.pi, rel=1e-12)


def test_ideal_racket_twists_perfectly() -> None:
    """I1 -> 0 (a massless handle): the defect vanishes like 4 c3 exp(-pi r)."""
    defects = [float(separatrix_twist((x, 0.9, 1.0)).defect) for x in (1e-1, 1e-2, 1e-3, 1e-4)]
    assert all(a > b for a, b in zip(defects, defects[1:], strict=False))
    assert defects[-1] < 1e-12


def test_bad_moments_are_refused() -> None:
    with pytest.raises(ValueError, match="distinct"):
        separatrix_twist((1.0, 1.0, 2.0))


def _dop853_twist(inertia: tuple[float, float, float], epsilon: float, azimuth: float) -> float:
    """|Δψ| over one full turn of the handle about L centred on the first flip, from a DOP853
    integration of Euler's equations and the attitude (R' = R [ω]×), not the closed form."""
    from scipy import integrate, optimize

    moments = np.asarray(inertia, dtype=float)
    w0 = flip_initial_omega(epsilon, 2.0, azimuth)
    r0 = attitude_with_L_along_z(inertia, w0).as_matrix()
    n = r0 @ (moments * w0)
    gnorm = float(np.linalg.norm(n))
    n /= gnorm
    u = np.cross(n, np.eye(3)[int(np.argmin(np.abs(n)))])
    u /= np.linalg.norm(u)
    v = np.cross(n, u)

    def rhs(_t: float, y: np.ndarray) -> np.ndarray:
        w, rot = y[:3], y[3:].reshape(3, 3)
        dw = np.cross(moments * w, w) / moments
        skew = np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])
        return np.concatenate([dw, (rot @ skew).ravel()])

    def flip_event(_t: float, y: np.ndarray) -> float:
        return float(y[1])

    flip_event.terminal = True  # type: ignore[attr-defined]
    tol = {"method": "DOP853", "rtol": 1e-12, "atol": 1e-13}
    first = integrate.solve_ivp(
        rhs, (0.0, 1e4), np.concatenate([w0, r0.ravel()]), events=flip_event, **tol
    )
    t_f, y_f = float(first.t_events[0][0]), first.y_events[0][0]
    reach = 8.0 * math.pi * moments[1] / gnorm

    def azimuth_of(sol: object, t: np.ndarray) -> np.ndarray:
        h = sol.sol(t)[3:].reshape(3, 3, -1)[:, 0, :]  # type: ignore[attr-defined]
        return np.arctan2(v @ h, u @ h)

    def half_turn_end(sign: float) -> tuple[object, float]:
        sol = integrate.solve_ivp(rhs, (t_f, t_f + sign * reach), y_f, dense_output=True, **tol)
        t = t_f + sign * np.linspace(0.0, reach, 8192)
        az = np.unwrap(azimuth_of(sol, t))
        k = int(np.nonzero(np.abs(az - az[0]) >= math.pi)[0][0])

        def gap(s: float) -> float:
            a = float(azimuth_of(sol, np.array([s]))[0])
            return abs(az[k - 1] + math.remainder(a - az[k - 1], 2 * math.pi) - az[0]) - math.pi

        return sol, float(optimize.brentq(gap, float(t[k - 1]), float(t[k]), xtol=1e-14))

    def psi(sol: object, grid: np.ndarray) -> np.ndarray:
        """ψ = atan2(l2, l3) of l = Rᵀ L/|L| on the grid, unwrapped (it turns smoothly)."""
        rot = sol.sol(grid)[3:].reshape(3, 3, -1)  # type: ignore[attr-defined]
        lb = np.einsum("ijk,i->jk", rot, n)
        return np.unwrap(np.arctan2(lb[1], lb[2]))

    (back, t_a), (ahead, t_b) = half_turn_end(-1.0), half_turn_end(1.0)
    psi_a = psi(back, np.linspace(t_a, t_f, 4096))
    psi_b = psi(ahead, np.linspace(t_f, t_b, 4096))
    assert math.remainder(psi_a[-1] - psi_b[0], 2 * math.pi) == pytest.approx(0.0, abs=1e-9)
    return abs((psi_a[-1] - psi_a[0]) + (psi_b[-1] - psi_b[0]))


@pytest.mark.parametrize("inertia", [BRODY, (1.0, 2.0, 3.0), (0.3, 0.5, 1.0)])
@pytest.mark.parametrize("azimuth", [0.0, 1.0])
def test_formula_and_bounds_against_a_dop853_toss(
    inertia: tuple[float, float, float], azimuth: float
) -> None:
    """The separatrix formula and its bounds against a twist measured without the closed form:
    DOP853 on Euler's equations and R' = R [ω]×, the window and ψ read off that integration."""
    theory = separatrix_twist(inertia)
    gaps = []
    for epsilon in (1e-3, 1e-5):
        twist = _dop853_twist(inertia, epsilon, azimuth)
        body = toss(inertia, epsilon, azimuth)
        stated = LIMIT_ACCURACY * body.complementary_parameter * math.cosh(float(theory.tau)) ** 2
        gaps.append(abs(twist - float(theory.twist)))
        assert gaps[-1] <= stated + 1e-11
        # The exact attitude's measurement agrees with the integration to its tolerance.
        assert twist == pytest.approx(measure_twist(body).twist, abs=1e-10)
    # The gap to the formula is O(1 - k²) = O(ε²): a hundredfold smaller ε, 1e4 smaller gap.
    assert gaps[1] <= 2e-4 * gaps[0]
    assert float(theory.defect_low) <= math.pi - twist <= float(theory.defect_high)
