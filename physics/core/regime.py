"""The kinds of torque-free motion a rigid body can have."""

from __future__ import annotations

import enum


class Regime(enum.Enum):
    """Which closed form describes the motion (sorted moments ``I1 <= I2 <= I3``).

    With ``D = |L|²/2T`` (Pars' D [Pars65 §13.12], Fasano-Marmi's J₀ [FM06 Eq. 7.57]), which
    always lies in ``[I1, I3]``:
    """

    #: ``D > I2``: the polhode circles the axis of largest moment; ω = (cn, sn, dn)
    #: [LL76 §37, Eq. 37.10].
    MAJOR_AXIS = "major-axis family"
    #: ``D < I2``: the polhode circles the axis of smallest moment; ω = (dn, sn, cn).
    MINOR_AXIS = "minor-axis family"
    #: ``D = I2`` exactly (and not a pure spin): the limiting polhode, ω = (sech, tanh, sech)
    #: [LL76 §37, Problem 2].
    SEPARATRIX = "separatrix"
    #: Two equal moments: ω turns uniformly about the symmetry axis in the body [FM06 §7.11].
    SYMMETRIC = "symmetric"
    #: All moments equal: every axis is principal and ω is constant.
    SPHERE = "sphere"
    #: ω along a principal axis: it stays there (unstably so about the intermediate axis)
    #: [FM06 Theorems 7.2-7.3].
    PERMANENT_ROTATION = "permanent rotation"
    #: ω = 0.
    REST = "rest"

    @property
    def label(self) -> str:
        """A short human-readable name, e.g. ``"major-axis family"``."""
        return self.value
