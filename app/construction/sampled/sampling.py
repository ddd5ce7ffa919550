"""The exact motion sampled on a uniform time grid, a batch of grid times per physics call.

Physics evaluates a whole array of times for about the price of one (closed form, vectorised),
so rather than calling it every frame the scene reads the motion from a look-ahead batch: the
times ``t0 + k h`` for the next BATCH grid indices. A frame at clock time t shows grid index
``floor((t - t0)/h)`` (at most one grid step, a fraction of a frame, behind the clock), and the
traces take every ``stride``-th grid sample. Everything shown is the exact solution at a grid
time; nothing is interpolated.

The grid step is chosen per body and speed: a quarter of a frame's simulation time, or less if
the faster trace would otherwise move more than ``max_chord`` display units between samples.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from poinsot.physics import FreeRigidBody

#: Grid times evaluated per physics call (about 128 frames' worth: a 512-time call costs
#: little more than a 128-time one, so a frame's share of the physics is a few microseconds).
BATCH = 512
#: The first batch after a parameter change is smaller: the slider-to-redraw time pays for it.
FIRST_BATCH = 64
#: Grid steps per frame when the motion is slow (the display lags the clock by < 1/4 frame).
STEPS_PER_FRAME = 4
#: Samples of the one-period survey that measures how fast the traces move.
SURVEY_SAMPLES = 256


@dataclasses.dataclass(frozen=True)
class Samples:
    """Grid indices ``k`` and the motion at ``t0 + k h``: omega (N,3) body frame, attitude
    quaternions (N,4) scalar-last as physics gives them, contact point (N,3) space frame."""

    k: np.ndarray
    t: np.ndarray
    omega: np.ndarray
    quat_xyzw: np.ndarray
    contact: np.ndarray


def evaluate(body: FreeRigidBody, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """omega, attitude quaternions (scalar-last) and contact point at times ``t``: the only
    place the app evaluates the motion."""
    omega, rotation, contact = body.sample(t)
    return omega, rotation.as_quat(), contact


def trace_speed(body: FreeRigidBody, scale: float) -> float:
    """Largest speed [display units per time unit] of the polhode and herpolhode points over one
    period (or, without a period, over ten turns), measured on the exact solution."""
    return survey(body, scale)[0]


def survey(body: FreeRigidBody, scale: float) -> tuple[float, float]:
    """The traces' largest speed (see :func:`trace_speed`) and the herpolhode's largest distance
    from L's axis [display units], from one survey of a period of the exact solution (the
    distance varies with |ω|, whose period it is)."""
    norm = float(np.linalg.norm(body.omega0))
    if norm == 0.0:
        return 0.0, 0.0
    span = body.period if math.isfinite(body.period) else 20.0 * math.pi / norm
    t = np.linspace(0.0, span, SURVEY_SAMPLES + 1)
    omega, _, contact = evaluate(body, t)
    dt = t[1] - t[0]
    chords = max(
        float(np.max(np.linalg.norm(np.diff(omega, axis=0), axis=1))),
        float(np.max(np.linalg.norm(np.diff(contact, axis=0), axis=1))),
    )
    radius = float(np.max(np.hypot(contact[:, 0], contact[:, 1])))
    # margin: the survey's own chords are under-estimates
    return 1.2 * scale * chords / dt, scale * radius


class MotionSampler:
    """Look-ahead batches of the exact motion on the grid ``t0 + k h``."""

    def __init__(self, body: FreeRigidBody, step: float, stride: int, t0: float = 0.0):
        if not (step > 0.0 and math.isfinite(step)):
            raise ValueError(f"grid step must be positive, got {step}")
        self.body, self.step, self.stride, self.t0 = body, float(step), int(stride), float(t0)
        self._k0 = 0
        self._cache: Samples | None = None
        self.evaluations = 0  # physics calls so far (tests, benchmark)

    @classmethod
    def for_body(
        cls,
        body: FreeRigidBody,
        speed_display: float,
        frame_time: float,
        max_chord: float,
        t0: float = 0.0,
    ) -> MotionSampler:
        """Grid for ``body`` when one frame advances the clock by ``frame_time``."""
        step = frame_time / STEPS_PER_FRAME
        if speed_display > 0.0:
            step = min(step, max_chord / speed_display)
            stride = max(1, int(max_chord / (speed_display * step)))
        else:
            stride = STEPS_PER_FRAME
        return cls(body, step, min(stride, STEPS_PER_FRAME), t0)

    def index(self, t: float) -> int:
        """Grid index shown at clock time ``t`` (the last grid time not after ``t``)."""
        return math.floor((t - self.t0) / self.step + 1e-9)

    def time(self, k: int) -> float:
        return self.t0 + k * self.step

    def batch(self, k_first: int, k_last: int, size: int = BATCH) -> Samples:
        """The whole cached batch holding grid indices ``k_first..k_last`` (inclusive),
        evaluating a new one of ``size`` (or more) grid times starting at ``k_first`` if the
        cache does not hold them all."""
        if k_last < k_first:
            raise ValueError("empty grid range")
        cache = self._cache
        if cache is None or k_first < cache.k[0] or k_last > cache.k[-1]:
            count = max(size, k_last - k_first + 1)
            k = np.arange(k_first, k_first + count)
            t = self.t0 + k * self.step
            omega, quat, contact = evaluate(self.body, t)
            self.evaluations += 1
            # Checked once per batch, so that a frame never draws a NaN.
            for name, values in (("omega", omega), ("attitude", quat), ("contact", contact)):
                if not np.all(np.isfinite(values)):
                    raise ValueError(f"physics gave a non-finite {name}; nothing is drawn")
            cache = self._cache = Samples(k, t, omega, quat, contact)
        return cache

    def samples(self, k_first: int, k_last: int) -> Samples:
        """The motion at grid indices ``k_first..k_last`` (inclusive), from the cache or a new
        batch starting at ``k_first``."""
        cache = self.batch(k_first, k_last)
        i, j = k_first - int(cache.k[0]), k_last - int(cache.k[0]) + 1
        return Samples(
            cache.k[i:j], cache.t[i:j], cache.omega[i:j], cache.quat_xyzw[i:j], cache.contact[i:j]
        )
