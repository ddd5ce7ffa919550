"""Elliptic functions and integrals accurate up to the separatrix (``m -> 1``).

* :mod:`~poinsot.physics.core.elliptic.jacobi`: sn, cn, dn from the pair ``(m, 1 - m)`` by the
  descending Landen recurrence [Bul65]; K and F in Carlson's form [DLMF 19.25];
* :mod:`~poinsot.physics.core.elliptic.complete`: K and Π(n|m) to 45 digits from one AGM
  [DLMF 19.8.6-19.8.8];
* :mod:`~poinsot.physics.core.elliptic.third_kind`: the incomplete Π(n; am u | m) and its periodic
  part, the precession integral of the free body [LL76 §37, Eq. 37.16].

Everything is vectorised over the argument ``u`` (shape (N,)) for one scalar parameter, with a
``*_scalar`` twin for one float where the closed forms need it.
"""

from poinsot.physics.core.elliptic.complete import (
    ThirdKindConstants,
    complete_integrals_excess_decimal,
    third_kind_constants,
)
from poinsot.physics.core.elliptic.jacobi import (
    JacobiParameter,
    ellipf_from_angle,
    ellipk,
    reduce_argument,
    reduce_argument_scalar,
    sncndn,
    sncndn_reduced,
    sncndn_reduced_scalar,
    tanh_sech,
    tanh_sech_scalar,
)
from poinsot.physics.core.elliptic.third_kind import (
    PeriodicPi,
    ellippi_from_jacobi,
    periodic_third_kind,
    periodic_third_kind_scalar,
)

__all__ = [
    "JacobiParameter",
    "PeriodicPi",
    "ThirdKindConstants",
    "complete_integrals_excess_decimal",
    "ellipf_from_angle",
    "ellipk",
    "ellippi_from_jacobi",
    "periodic_third_kind",
    "periodic_third_kind_scalar",
    "reduce_argument",
    "reduce_argument_scalar",
    "sncndn",
    "sncndn_reduced",
    "sncndn_reduced_scalar",
    "tanh_sech",
    "tanh_sech_scalar",
    "third_kind_constants",
]
