"""Predict, then play: a short set of challenges, from easy to hard, each with the answer the
theory gives and a sentence a first-year student can follow [LL76 §37; ACC91; FM06 Theorem
7.3].

Three kinds of question: does the body flip or stay, and about which axis was it spun (the
presets' box and T-handle, a random body near a random axis: the body is drawn at t = 0, and
no title or question names the axis or the outcome); when comes the first flip (the
T-handle and a random body near the middle axis, ``(K ± δ)/λ``); how much later does a twin
started n times closer flip (``t₁(ε′) − t₁(ε)``, near ``ln(n)/σ``). :func:`challenge_set`
draws one set from a seed (one per session); every answer comes from :mod:`poinsot.physics`.
"""

from __future__ import annotations

import dataclasses
import math
import random

import numpy as np

from poinsot.app.lessons import dzhanibekov
from poinsot.app.model.elements import Solid
from poinsot.app.model.parameters import Parameters
from poinsot.app.model.presets import T_HANDLE, preset_by_key
from poinsot.physics.models.axis_angles import wobble_theory
from poinsot.physics.models.flip import flip_initial_omega, flip_theory, measure_flips
from poinsot.physics.models.twins import twin_clock

#: A time answer within this fraction of the theory's scores.
TIME_TOLERANCE = 0.2
#: The axes as the student picks them.
AXES = ("e₁ (smallest moment)", "e₂ (middle moment)", "e₃ (largest moment)")
OUTCOMES = ("it flips", "it stays")
#: The first entry of each answer's list: nothing chosen yet.
CHOOSE = "choose…"
#: What each challenge draws.
BOX = "a homogeneous 3 × 2 × 1 box"
HANDLE = "a T-handle (bar 2.0, stem 0.9)"
RANDOM = "a box of random moments"


@dataclasses.dataclass(frozen=True)
class Challenge:
    """One question: ``kind`` is "axis" (flip or stay, about which axis), "time" (the first
    flip) or "lag" (the twin's lag); ``answer`` is (flips, axis) or a time; ``params`` the motion
    that plays; ``twin_ratio`` n for a lag (the twin at ε/n); ``body`` says what is drawn,
    ``solid`` is drawn (None: the box of the same moments)."""

    title: str
    prompt: str
    kind: str
    params: Parameters
    answer: tuple[bool, int] | float
    explanation: str
    twin_ratio: float = 0.0
    body: str = RANDOM
    solid: Solid | None = None

    def judge(self, guess: tuple[bool, int] | float) -> bool:
        """Whether ``guess`` is right: the same outcome and axis, or a time within 20 %."""
        if isinstance(self.answer, tuple):
            return guess == self.answer
        assert isinstance(guess, float)
        return abs(guess - self.answer) <= TIME_TOLERANCE * abs(self.answer)

    def shown(self, guess: tuple[bool, int] | float | None = None) -> str:
        """``guess`` (default: the answer) in words."""
        value = self.answer if guess is None else guess
        if isinstance(value, tuple):
            return f"{OUTCOMES[0 if value[0] else 1]}, about {AXES[value[1]][:2]}"
        return f"{value:.3g} time units"


def _params(inertia: tuple[float, float, float], omega0: np.ndarray) -> Parameters:
    """The exact start ``omega0`` as the session's parameters (D = |L|²/2T for the slider)."""
    J = np.asarray(inertia)
    m = J * omega0
    D = float(m @ m / (m @ omega0))
    w = (float(omega0[0]), float(omega0[1]), float(omega0[2]))
    return Parameters(inertia, D, 1, float(np.linalg.norm(omega0)), omega0=w)


#: The question of every flip-or-stay challenge: it names neither the axis nor the outcome.
AXIS_PROMPT = (
    "The body is drawn at t = 0, paused; ω (the arrow) starts close to one of its principal "
    "axes. About which axis is it spun, and does it flip over or stay?"
)


def _axis_challenge(
    title: str, params: Parameters, drawn: str = RANDOM, solid: Solid | None = None
) -> Challenge:
    """Flip or stay: the axis is the one L starts closest to; it flips if ω along it changes
    sign within one period of the exact motion."""
    body = params.build()
    J = np.asarray(params.inertia)
    w0 = body.omega0
    axis = int(np.argmax(np.abs(J * w0)))
    period = body.period if math.isfinite(body.period) else 100.0
    flips = len(measure_flips(body, 1.05 * period, axis=axis)) > 0
    order = np.argsort(J)
    sorted_axis = int(np.flatnonzero(order == axis)[0])
    name = AXES[sorted_axis][:2]
    if flips:
        text = (
            f"Spun near {name}, the axis of middle moment, the motion is unstable: a small "
            f"tilt grows like e^(σt), and the body turns over every {body.period / 2:.3g} "
            "time units (the Dzhanibekov flip)."
        )
    else:
        G = float(np.linalg.norm(J * w0))
        wobble = float(wobble_theory(J, axis, G / J[axis]))
        side = "largest" if sorted_axis == 2 else "smallest"
        text = (
            f"Spun near {name}, the axis of {side} moment, the motion is stable: L stays close "
            f"to {name}, which only wobbles around it, about every {2 * math.pi / wobble:.3g} "
            f"time units (small oscillations, Ω = {wobble:.3g} rad per time unit)."
        )
    answer = (flips, sorted_axis)
    return Challenge(title, AXIS_PROMPT, "axis", params, answer, text, body=drawn, solid=solid)


def _random_moments(rng: random.Random) -> tuple[float, float, float]:
    """Three moments at least 15 % apart, that a real body can have, smallest first."""
    while True:
        J = sorted(rng.uniform(0.6, 3.0) for _ in range(3))
        if J[1] > 1.15 * J[0] and J[2] > 1.15 * J[1] and J[2] < J[0] + J[1]:
            return (J[0], J[1], J[2])


def _time_challenge(
    title: str,
    inertia: tuple[float, float, float],
    eps: float,
    body: str = RANDOM,
    solid: Solid | None = None,
) -> Challenge:
    spin = 2.0
    w0 = flip_initial_omega(eps, spin)
    theory = flip_theory(inertia, w0)
    sigma = theory.growth_rate
    text = (
        f"The tilt starts at ε = {eps:.0e} rad and grows like ε·e^(σt) with σ = {sigma:.3g} "
        f"per time unit, so it becomes large after about ln(1/ε)/σ = "
        f"{math.log(1 / eps) / sigma:.3g}; the exact first flip is at K/λ = "
        f"{theory.first_flip_time:.4g}."
    )
    prompt = (
        f"Spun at {spin:g} rad per time unit, {eps:.0e} rad from the middle axis: when does it "
        "first flip (a time)?"
    )
    params = _params(inertia, w0)
    answer = theory.first_flip_time
    return Challenge(title, prompt, "time", params, answer, text, body=body, solid=solid)


def _lag_challenge(
    title: str,
    inertia: tuple[float, float, float],
    eps: float,
    n: float,
    body: str = RANDOM,
    solid: Solid | None = None,
) -> Challenge:
    spin = 2.0
    clock = twin_clock(inertia, eps, eps / n, spin)
    text = (
        f"The twin starts {n:g} times closer to the middle axis. Its tilt grows like e^(σt) "
        f"(σ = {clock.growth_rate:.3g}), so it needs ln({n:g})/σ = {clock.limit:.3g} more time "
        f"to grow as large: the exact lag is {clock.lag:.4g}. Ten times closer buys only "
        f"ln(10)/σ = {math.log(10) / clock.growth_rate:.3g} more, however close."
    )
    prompt = (
        f"Two identical bodies spin {eps:.0e} and {eps / n:.0e} rad from the middle axis: how "
        "much later does the second one flip (a time)?"
    )
    params = _params(inertia, flip_initial_omega(eps, spin))
    return Challenge(title, prompt, "lag", params, clock.lag, text, n, body, solid)


def challenge_set(seed: int) -> list[Challenge]:
    """Eight challenges, easy to hard: presets, then random bodies drawn from ``seed``."""
    rng = random.Random(seed)
    I1, I2, I3 = (float(x) for x in dzhanibekov.moments())  # the Dzhanibekov scene's T-handle
    handle = (I1, I2, I3)
    J = _random_moments(rng)
    axis = rng.randrange(3)
    w0 = np.zeros(3)
    tilt = rng.uniform(0.03, 0.1)
    w0[axis], w0[(axis + 1) % 3] = 2.0 * math.cos(tilt), 2.0 * math.sin(tilt)
    K = _random_moments(rng)
    box = preset_by_key("major").solid
    flip = flip_initial_omega(0.05, 2.0)
    return [
        _axis_challenge("A 3 × 2 × 1 box", _preset("major"), BOX, box),
        _axis_challenge("The same box, spun another way", _preset("minor"), BOX, box),
        _axis_challenge("A T-handle", _params(handle, flip), HANDLE, T_HANDLE),
        _axis_challenge("A body of random shape", _params(J, w0)),
        _time_challenge("The T-handle's first flip", handle, 1e-3, HANDLE, T_HANDLE),
        _time_challenge("A random body's first flip", K, 10.0 ** -rng.randint(2, 7)),
        _lag_challenge("Twins: ten times closer", handle, 1e-3, 10.0, HANDLE, T_HANDLE),
        _lag_challenge("Twins: a thousand times closer", K, 10.0 ** -rng.randint(2, 5), 1000.0),
    ]


def _preset(key: str) -> Parameters:
    return Parameters.from_preset(preset_by_key(key))


def parse_time(text: str) -> float:
    """A time the student typed ("3.2", "3,2", "1e1"), else ValueError with a message."""
    cleaned = text.strip().replace(",", ".")
    if not cleaned:
        raise ValueError("type a time first, e.g. 7.5")
    try:
        value = float(cleaned)
    except ValueError:
        raise ValueError(f"“{text.strip()[:40]}” is not a number: type a time, e.g. 7.5") from None
    if not (math.isfinite(value) and value >= 0.0):
        raise ValueError("a time is a number ≥ 0, e.g. 7.5")
    return value
