"""The scenes: lecture topics with a body, a motion and drawings of their own, declared as data
(:mod:`poinsot.app.lessons.support.spec`) and chosen from the same menu as the presets, or by name
with ``poinsot serve|screenshot|export-html --scene NAME``.

One module per scene, each with a docstring saying what it shows and its sources:

- ``polhode-family`` (:mod:`.polhode_family`): the family of polhodes on the energy ellipsoid
  and Landau's momentum sphere [LL76 §37; FM06 §7.8; Pars65 §13.12];
- ``dzhanibekov`` (:mod:`.dzhanibekov`): the T-handle's intermediate-axis flip as a clock,
  theory against measurement, ε from 1e-1 to 1e-12 [ACC91; LL76 §37];
- ``symmetric-top`` (:mod:`.symmetric_top`): the body cone rolling on the space cone
  [GPS02 §5.6; FM06 §7.11];
- ``gyroscope-torque`` (:mod:`.gyroscope_torque`): a body-fixed torque, ω in closed form, the
  attitude integrated, the drift of the axis [FM06 §7.11];
- ``long-cylinder`` (:mod:`.long_cylinder`): a spin that looks stable for a long time
  [FM06 Remark 7.5];
- ``explorer-1`` (:mod:`.explorer_1`): energy dissipation at fixed |L| turns a minor-axis spin
  into a flat spin [BG58];
- ``geometric-phase`` (:mod:`.geometric_phase`): Montgomery's split of the turn per period into
  2TP/|L| and the solid angle of the cone of L [Mon91];
- ``tennis-racket`` (:mod:`.tennis_racket`): the racquet's head twists by almost π while its
  handle makes one turn [VMS17; VMS20; ACC91].
"""

from __future__ import annotations

from poinsot.app.lessons.dzhanibekov import SPEC as DZHANIBEKOV
from poinsot.app.lessons.explorer_1 import SPEC as EXPLORER_1
from poinsot.app.lessons.geometric_phase import SPEC as GEOMETRIC_PHASE
from poinsot.app.lessons.gyroscope_torque import SPEC as GYROSCOPE_TORQUE
from poinsot.app.lessons.long_cylinder import SPEC as LONG_CYLINDER
from poinsot.app.lessons.polhode_family import SPEC as POLHODE_FAMILY
from poinsot.app.lessons.support.spec import SceneSpec
from poinsot.app.lessons.symmetric_top import SPEC as SYMMETRIC_TOP
from poinsot.app.lessons.tennis_racket import SPEC as TENNIS_RACKET

SCENES: tuple[SceneSpec, ...] = (
    POLHODE_FAMILY,
    DZHANIBEKOV,
    SYMMETRIC_TOP,
    GYROSCOPE_TORQUE,
    LONG_CYLINDER,
    EXPLORER_1,
    GEOMETRIC_PHASE,
    TENNIS_RACKET,
)


def scene_names() -> tuple[str, ...]:
    return tuple(scene.name for scene in SCENES)


def scene_by_name(name: str) -> SceneSpec:
    """A scene by its name (``polhode-family``) or its menu label, case-insensitive."""
    wanted = name.strip().lower()
    for scene in SCENES:
        if wanted in (scene.name, scene.label.lower()):
            return scene
    raise KeyError(f"no scene named {name!r}; choose from {list(scene_names())}")


def scene_by_label(label: str) -> SceneSpec | None:
    """The scene whose menu label is ``label`` exactly (None if it is a preset's)."""
    return next((scene for scene in SCENES if scene.label == label), None)
