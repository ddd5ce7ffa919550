"""Presets: named initial conditions, declared as data.

A :class:`Preset` says which body and which motion to show, where the case comes from, and
which scene elements, controls and plots it uses; the session creates exactly those and nothing
else. The moments of inertia are *data* here, each with its source; for the solid shapes
(box, disc, rod, T-handle) the numbers are the principal moments of the homogeneous solid of
the stated dimensions, normalised so that the smallest moment is 1, and
``tests/app/test_parts.py`` checks them against trimesh's mass properties of the very mesh
the app draws. The vocabulary (elements, controls, plots, solids) is
:mod:`poinsot.app.model.elements`.
"""

from __future__ import annotations

import dataclasses

from poinsot.app.model.elements import (
    ALL_CONTROLS,
    ALL_ELEMENTS,
    STANDARD_CONTROLS,
    STANDARD_PLOTS,
    TRACE_ELEMENTS,
    Control,
    Element,
    Plot,
    Solid,
)


@dataclasses.dataclass(frozen=True)
class Preset:
    """A named starting point: body, energy, polhode, playback, and what the scene shows."""

    key: str
    label: str
    source: str
    inertia: tuple[float, float, float]
    D: float
    pole_sign: int = 1
    omega_norm: float = 1.0
    speed: float = 1.0
    trail_points: int = 1200
    solid: Solid | None = None
    #: An exact initial omega (data) instead of one built from D, |omega0| and the pole;
    #: for a state that rounding must not move (the separatrix).
    omega0: tuple[float, float, float] | None = None
    elements: frozenset[Element] = ALL_ELEMENTS
    controls: frozenset[Control] = STANDARD_CONTROLS
    plots: frozenset[Plot] = STANDARD_PLOTS
    #: One or two sentences saying what the picture shows, over the legend (a scene sets its
    #: own here; empty: :mod:`poinsot.app.live.panel.legend` has the presets' captions).
    caption: str = ""
    #: A challenge's body (:mod:`poinsot.app.live.lecture.challenges`): its start is the
    #: question's (a click on the ellipsoid does not move it).
    challenge: bool = False
    #: What would tell a challenge's answer (the readouts' regime, period and constants; the
    #: clock's play and step) is withheld while it is shown.
    withheld: bool = False

    def __post_init__(self) -> None:
        if self.pole_sign not in (1, -1):
            raise ValueError(f"preset {self.key}: pole_sign must be +1 or -1")
        if len(self.inertia) != 3:
            raise ValueError(f"preset {self.key}: inertia needs three moments")


# A 3 x 2 x 1 homogeneous box: I = m (b^2 + c^2)/12 cyclic = m (5, 10, 13)/12; m = 12/5.
_BOX_321 = Solid("box", (3.0, 2.0, 1.0))
_BOX_INERTIA = (1.0, 2.0, 2.6)
_BOX_SOURCE = "homogeneous 3 x 2 x 1 box, I = (5, 10, 13)/12 m"

# T-handle: bar 2.0 x r 0.14 along axis 1, stem 0.9 x r 0.14 along -axis 2 (wing-nut shape of
# Dzhanibekov's Salyut-7 observation); moments from trimesh mass properties, ratio 1 : I2 : I3.
T_HANDLE = Solid("t_handle", (2.0, 0.14, 0.9, 0.14), offset=(0.0, 0.183103, 0.0))
_T_HANDLE_INERTIA = (1.0, 2.2782, 3.1839)

# Thin disc r = 1, thickness 0.25: I_axis = m r^2/2, I_transverse = m (3 r^2 + h^2)/12.
_DISC = Solid("cylinder", (1.0, 0.25), axis=2)
_DISC_INERTIA = (1.0, 1.0, 1.9592)

# Rod r = 0.35, length 2: same formulas, I_axis / I_transverse = 0.06125 / 0.3639583.
_ROD = Solid("cylinder", (0.35, 2.0), axis=2)
_ROD_INERTIA = (1.0, 1.0, 0.16829)

# A cube has three equal moments (m a^2 / 6): its energy ellipsoid is a sphere.
_CUBE = Solid("box", (1.0, 1.0, 1.0))

_SPHERE_ELEMENTS = ALL_ELEMENTS - TRACE_ELEMENTS
_SPHERE_CONTROLS = frozenset(
    {Control.INERTIA, Control.OMEGA_NORM, Control.SPEED, Control.PLAYBACK, Control.VISIBILITY}
)

PRESETS: tuple[Preset, ...] = (
    Preset(
        key="major",
        label="Stable about the major axis",
        source="Landau & Lifshitz, Mechanics, Sec. 37 and Fig. 51; Fasano-Marmi Th. 7.3: "
        "D > I2, the polhode circles the axis of largest moment. " + _BOX_SOURCE,
        inertia=_BOX_INERTIA,
        D=2.45,
        omega_norm=1.2,
        solid=_BOX_321,
    ),
    Preset(
        key="minor",
        label="Stable about the minor axis",
        source="Landau & Lifshitz, Mechanics, Sec. 37 and Fig. 51; Fasano-Marmi Th. 7.3: "
        "D < I2, the polhode circles the axis of smallest moment. " + _BOX_SOURCE,
        inertia=_BOX_INERTIA,
        D=1.25,
        omega_norm=1.2,
        solid=_BOX_321,
    ),
    Preset(
        key="t_handle",
        label="Dzhanibekov flip (T-handle)",
        source="Dzhanibekov effect (Salyut 7, 1985); Ashbaugh, Chicone & Cushman, "
        "J. Dyn. Diff. Eq. 3 (1991) 67; Landau Sec. 37 problem 2: a spin close to the "
        "intermediate axis flips periodically. T-handle bar 2.0 x r 0.14, stem 0.9 x r 0.14",
        inertia=_T_HANDLE_INERTIA,
        D=2.2782 * (1.0 + 2e-3),
        omega_norm=2.0,
        trail_points=2400,
        solid=T_HANDLE,
    ),
    Preset(
        key="near_separatrix",
        label="Near the separatrix",
        source="Landau Sec. 37, Eq. (37.12): the period 4K(k^2)/lambda diverges "
        "logarithmically as D -> I2 (k^2 -> 1). " + _BOX_SOURCE,
        inertia=_BOX_INERTIA,
        D=2.0 * (1.0 + 1e-3),
        omega_norm=1.5,
        trail_points=2400,
        solid=_BOX_321,
    ),
    Preset(
        key="separatrix",
        label="Exactly on the separatrix",
        source="Landau Sec. 37 problem 2; Fasano-Marmi Eq. (7.79); Pars 13.12.19-20: D = I2, "
        "omega tends to the intermediate axis as sech/tanh, never returning. I = (1, 2, 9/4), "
        "omega0 = (3/4, 0, 1): I1 (I2 - I1) w1^2 = I3 (I3 - I2) w3^2 holds exactly in binary "
        "floating point, so D = I2 exactly (Fasano-Marmi Eq. 7.57)",
        inertia=(1.0, 2.0, 2.25),
        D=2.0,
        omega_norm=1.25,
        omega0=(0.75, 0.0, 1.0),
        trail_points=2400,
    ),
    Preset(
        key="oblate",
        label="Oblate symmetric (a disc)",
        source="Fasano-Marmi Sec. 7.11; Goldstein Sec. 5.6: I1 = I2 < I3, the axis precesses "
        "uniformly about L; polhode and herpolhode are circles. Disc r 1, thickness 0.25",
        inertia=_DISC_INERTIA,
        D=1.45,
        omega_norm=1.2,
        solid=_DISC,
    ),
    Preset(
        key="prolate",
        label="Prolate symmetric (a rod)",
        source="Fasano-Marmi Sec. 7.11; Goldstein Sec. 5.6: I1 = I2 > I3, body cone rolling "
        "outside the space cone. Rod r 0.35, length 2",
        inertia=_ROD_INERTIA,
        D=0.5,
        omega_norm=1.2,
        solid=_ROD,
    ),
    Preset(
        key="sphere",
        label="Sphere (a cube)",
        source="Fasano-Marmi Sec. 7.8: all three moments equal, every axis is principal "
        "and omega is constant. A homogeneous cube",
        inertia=(1.0, 1.0, 1.0),
        D=1.0,
        omega_norm=1.0,
        solid=_CUBE,
        elements=_SPHERE_ELEMENTS,
        controls=_SPHERE_CONTROLS,
        plots=frozenset(),
    ),
)

#: What a body edited by hand shows: everything. The controls that bring a body of one's own
#: (an uploaded toss or mesh) come with the entries below; a hand edit keeps those the preset
#: edited had (:meth:`poinsot.app.live.session.choice.Choice.edit`), and adds none.
CUSTOM = Preset(
    key="custom",
    label="Custom (edited)",
    source="your own choice of moments and energy",
    inertia=_BOX_INERTIA,
    D=2.45,
    controls=STANDARD_CONTROLS,
)

# The entries for a body of one's own. Until something is uploaded they show these stand-ins
# (the T-handle's moments, normalised as an upload's are: the largest is 1); a session then
# shows its own fitted toss or mesh body under the same label (see poinsot.app.model.own_bodies).
FITTED_TOSS = Preset(
    key="fitted_toss",
    label="Fitted toss",
    source="no recording yet: throw a phone spinning, record its gyroscope with phyphox and "
    "upload the export (.zip or .csv) under 'Your own toss'; the exact free motion fitted to "
    "it plays here, its measured ω drawn over the exact one",
    inertia=(1.0 / 3.1839, 2.2782 / 3.1839, 1.0),
    D=2.2782 / 3.1839 * (1.0 + 2e-3),
    omega_norm=2.0,
    trail_points=2400,
    controls=ALL_CONTROLS,
)
MESH_BODY = Preset(
    key="mesh_body",
    label="Body from a mesh",
    source="no mesh yet: choose a bundled body or upload a closed mesh (STL, OBJ, PLY, GLB) "
    "under 'Any body from its mesh'; its moments at uniform density drive the scene",
    inertia=(5.0 / 13.0, 10.0 / 13.0, 1.0),
    D=10.0 / 13.0 * (1.0 + 2e-3),
    omega_norm=2.0,
    trail_points=2400,
    controls=ALL_CONTROLS,
)
#: The entries of the preset menu, in order.
MENU: tuple[Preset, ...] = (*PRESETS, FITTED_TOSS, MESH_BODY, CUSTOM)

DEFAULT_PRESET = PRESETS[0]


def preset_by_key(key: str) -> Preset:
    for preset in MENU:
        if preset.key == key:
            return preset
    raise KeyError(f"no preset named {key!r}; choose from {[p.key for p in PRESETS]}")


def preset_by_label(label: str) -> Preset:
    for preset in MENU:
        if preset.label == label:
            return preset
    raise KeyError(f"no preset labelled {label!r}")
