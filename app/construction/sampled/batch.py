"""What a frame sends, precomputed a whole batch at a time.

:class:`FrameBatch` converts one physics batch (:meth:`MotionSampler.batch`) once, vectorised,
into the arrays the frames send: a frame then only picks rows (no numpy work, no allocation per
frame). :class:`Frame` is what one frame drew.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from poinsot.app.construction.sampled.frames import wxyz_from_xyzw
from poinsot.app.construction.sampled.sampling import Samples
from poinsot.app.model.elements import Element


@dataclasses.dataclass(frozen=True)
class Frame:
    """What one call of :meth:`PoinsotScene.advance` drew (for readouts, plots, tests)."""

    t: float
    omega: np.ndarray  # (3,) body frame, physical units
    wxyz: np.ndarray  # (4,) attitude as sent
    contact: np.ndarray  # (3,) space frame, display units, as sent
    samples: int  # trace samples evaluated for this frame


@dataclasses.dataclass(frozen=True)
class FrameBatch:
    """One physics batch converted into what frames send. Row ``i`` is grid index ``k0 + i``;
    the arrays are read-only."""

    source: Samples  # the sampler's batch this was converted from
    k0: int
    t: np.ndarray  # (N,) simulation time
    omega: np.ndarray  # (N, 3) body frame, physical units
    wxyz: np.ndarray  # (N, 4) attitude as viser takes it
    tip: np.ndarray  # (N, 3) contact point, space frame, display units (float64)
    arrow: np.ndarray  # (N, 1, 2, 3) float32: the omega arrow, origin to contact point
    polhode: np.ndarray  # (N, 3) float32 trace points, body frame, display units
    herpolhode: np.ndarray  # (N, 3) float32 trace points, space frame, display units
    keep: np.ndarray  # (N,) bool: grid samples the traces take (every stride-th)

    @classmethod
    def convert(cls, samples: Samples, scale: float, stride: int) -> FrameBatch:
        tip = samples.contact * scale
        arrow = np.zeros((len(tip), 1, 2, 3), np.float32)
        arrow[:, 0, 1] = tip
        batch = cls(
            samples,
            int(samples.k[0]),
            samples.t,
            samples.omega,
            wxyz_from_xyzw(samples.quat_xyzw),
            tip,
            arrow,
            (samples.omega * scale).astype(np.float32),
            tip.astype(np.float32),
            samples.k % stride == 0,
        )
        for field in dataclasses.fields(cls)[2:]:
            getattr(batch, field.name).flags.writeable = False
        return batch

    def frame(self, i: int, j: int) -> Frame:
        """The frame that shows row ``j`` after evaluating rows ``i..j``."""
        return Frame(float(self.t[j]), self.omega[j], self.wxyz[j], self.tip[j], j - i + 1)

    def trace(self, element: Element, i: int, j: int, last: bool) -> np.ndarray:
        """Trace points of rows ``i..j-1`` (the last row too if ``last``)."""
        points = self.polhode if element is Element.POLHODE else self.herpolhode
        keep = self.keep[i:j]
        if last and not keep[-1]:
            keep = keep.copy()
            keep[-1] = True
        return points[i:j][keep]
