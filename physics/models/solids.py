"""Real bodies behind a set of principal moments: the triangle inequality and a box.

The free-body mathematics holds for any positive moments, so
:class:`~poinsot.physics.FreeRigidBody` accepts them all. A *real* mass distribution also obeys
``I_i <= I_j + I_k`` for every axis (since ``I_j + I_k - I_i = 2 Σ m x_i² >= 0``); equality is
a flat lamina in the plane normal to axis i. These helpers let a scene say so and show a
homogeneous box with the same moments.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from poinsot.physics.core.exact import pow2_below
from poinsot.physics.core.validation import check_inertia, check_positive

__all__ = ["check_real_body", "box_dimensions"]

# Relative slack when testing I_i <= I_j + I_k: a lamina computed in floating point may exceed
# the equality by a few ulps, which is rounding, not a violation.
_TRIANGLE_RTOL = 8.0 * np.finfo(float).eps


def check_real_body(inertia: ArrayLike) -> None:
    """Raise ``ValueError`` unless some real body has these principal moments.

    Args:
        inertia: (3,) principal moments (any order, positive, finite).

    Raises:
        ValueError: bad moments (as :class:`FreeRigidBody`), or a moment larger than the sum of
            the other two, with a message naming the offending axis.
    """
    _scaled_moments(check_inertia(inertia))


def _scaled_moments(moments: NDArray[np.float64]) -> tuple[NDArray[np.float64], float]:
    """``(moments / s, s)`` for ``s`` the power of two below the largest (exact: a sum of
    moments ~1e308 would overflow), after the triangle inequality is checked."""
    scale = pow2_below(float(moments.max()))
    J = moments / scale
    total = float(J.sum())
    for i in range(3):
        others = total - float(J[i])
        if J[i] > others * (1.0 + _TRIANGLE_RTOL):
            j, k = (x for x in range(3) if x != i)
            raise ValueError(
                f"no real body has these moments: I{i + 1} = {moments[i]:g} is larger than "
                f"I{j + 1} + I{k + 1} = {others * scale:g} (every moment must be at most the sum "
                "of the other two; equality is a flat plate)"
            )
    return J, scale


def box_dimensions(inertia: ArrayLike, mass: float = 1.0) -> NDArray[np.float64]:
    """Side lengths of the homogeneous box with these principal moments about its centre.

    ``I1 = m (a2² + a3²)/12`` and cyclic, hence ``a1² = 6 (I2 + I3 - I1)/m``.

    Args:
        inertia: (3,) principal moments in the caller's order [mass · length²].
        mass: the box's mass (> 0), in the same mass unit.

    Returns:
        (3,) full side lengths ``(a1, a2, a3)`` along the caller's axes [length]; a flat lamina
        has a zero side.

    Raises:
        ValueError: if no real body has these moments (see :func:`check_real_body`), the
            mass is not positive and finite, or a side would leave the double range.
    """
    J, scale = _scaled_moments(check_inertia(inertia))
    m = check_positive(mass, "the mass")
    excess = np.maximum(J.sum() - 2.0 * J, 0.0)  # (I_j + I_k - I_i)/scale, >= 0 up to rounding
    with np.errstate(over="ignore", under="ignore"):
        sides = np.sqrt(6.0 * excess * scale / m)
        if not np.all(np.isfinite(sides) & ((sides > 0.0) | (excess == 0.0))):
            # sqrt(6 excess scale/m) factored, where the quotient itself leaves the range.
            sides = np.sqrt(6.0 * excess) * (math.sqrt(scale) / math.sqrt(m))
    if not np.all(np.isfinite(sides)):
        raise ValueError(
            f"a box of mass {m:g} with moments up to {scale:g} has sides beyond the "
            "double-precision range (1.8e308): express the mass or the moments in other units"
        )
    return sides
