"""What the picture shows, in words and in colours: a caption, and a legend with a swatch of
each element's colour beside its name, at the top of the left column, on screen from the first
frame (the names "polhode" and "herpolhode" with them; the scene also labels the two curves).

A preset's caption is its own :attr:`~poinsot.app.model.presets.Preset.caption` if it has one (a
scene of :mod:`poinsot.app.lessons` sets it there, or calls :meth:`Legend.show_caption` at any
time), else the one written here for it. The legend lists the elements the scene declares, in the
colours of the current look (:func:`poinsot.app.construction.palette.look`: theme and projector),
plus the rows of the drawings a scene or a lecture tool adds (:meth:`Legend.show_rows`: a scene's
parts, the neighbour body). Each row's swatch shows its shape and style too (a thinner or dashed
line), the cue that tells it from a row of a like colour (:class:`~poinsot.app.construction.
palette.Entry`).
"""

from __future__ import annotations

import html
from collections.abc import Callable, Iterable, Sequence

import viser

from poinsot.app.construction import palette
from poinsot.app.construction.palette import Entry, Look
from poinsot.app.model.elements import Element
from poinsot.app.model.presets import Preset

CAPTIONS: dict[str, str] = {
    "major": "Stable spin about the axis of largest moment (D > I₂). The energy ellipsoid rolls "
    "on the invariable plane ⊥ L; ω's tip, the contact point, traces the polhode on the body "
    "and the herpolhode on the plane.",
    "minor": "Stable spin about the axis of smallest moment (D < I₂): the polhode loops round it "
    "on the body while the herpolhode winds round L on the plane.",
    "t_handle": "A T-handle spun close to its intermediate axis (D just above I₂): the polhode "
    "sweeps from near one pole of that axis to near the other, and the handle flips over each "
    "time (the Dzhanibekov effect).",
    "near_separatrix": "Just off the separatrix (D = 1.001 I₂): ω lingers near the intermediate "
    "axis, so the period is long (it grows without bound as D → I₂).",
    "separatrix": "Exactly on the separatrix (D = I₂): ω tends to the unstable intermediate axis "
    "and never returns; the polhode is an arc between its two poles.",
    "oblate": "A disc (I₁ = I₂ < I₃): ω keeps its angle to the symmetry axis, so the polhode and "
    "the herpolhode are circles and the axis precesses uniformly about L.",
    "prolate": "A rod (I₁ = I₂ > I₃): the polhode and the herpolhode are circles; the body cone "
    "rolls on the outside of the space cone.",
    "sphere": "A cube: three equal moments, so the energy ellipsoid is a sphere, ω is constant "
    "and parallel to L, and there is no polhode to trace.",
    "custom": "Your own body: the energy ellipsoid rolls without slipping on the invariable plane "
    "⊥ L; ω's tip, the contact point, traces the polhode on the body and the herpolhode on the "
    "plane.",
    "fitted_toss": "A real toss: the exact free motion fitted to a gyroscope recording, its "
    "measured ω drawn over the exact one; the ellipsoid of the fitted moments rolls on the "
    "invariable plane.",
    "mesh_body": "A body from its mesh: the moments of the solid at uniform density make the "
    "energy ellipsoid, which rolls on the invariable plane while the polhode and the herpolhode "
    "are traced.",
}


def caption(preset: Preset) -> str:
    """The caption of ``preset``: its own, or the one written here for its key; none for a
    scene that has not written one."""
    return preset.caption or CAPTIONS.get(preset.key, "")


__all__ = ["CAPTIONS", "Entry", "Legend", "caption", "entries", "legend_html", "merged"]


def entries(elements: Iterable[Element], look: Look) -> list[Entry]:
    """The legend of the declared ``elements`` in ``look``'s colours, curves first."""
    table: dict[Element, Entry] = {
        Element.POLHODE: Entry("polhode (body)", (look.polhode,), "line"),
        Element.HERPOLHODE: Entry("herpolhode (plane)", (look.herpolhode,), "line"),
        Element.OMEGA: Entry("ω ang. velocity", (look.omega,), "arrow"),
        Element.L: Entry("L ang. momentum", (look.angular_momentum,), "arrow"),
        Element.CONTACT: Entry("contact point", (look.contact,), "dot"),
        Element.PLANE: Entry("invariable plane", (look.plane,), "patch", "translucent"),
        Element.ELLIPSOID: Entry("energy ellipsoid", (look.ellipsoid,), "patch", "translucent"),
        Element.POLHODE_FULL: Entry("whole polhode", (look.polhode_full,), "line", "thin"),
        Element.AXES: Entry("axes 1 2 3", look.axes, "axes", "labelled"),
        Element.SOLID: Entry("the body", (look.solid,), "patch"),
    }
    declared = set(elements)
    return [entry for element, entry in table.items() if element in declared]


#: A line swatch's thickness [em] by style (the traces' 0.32 em; a thin line half as thick).
_LINE_HEIGHT = {"thin": 0.14, "thick": 0.5}


def merged(rows: Iterable[Entry]) -> list[Entry]:
    """``rows`` once each, in order (two pictures of one thing, one row)."""
    return list(dict.fromkeys(rows))


_OUTLINE = "box-shadow:0 0 0 1px rgba(128,128,128,0.7);"


def _span(style: str, inner: str = "") -> str:
    return f'<span style="display:inline-block;vertical-align:middle;{style}">{inner}</span>'


def _swatch(entry: Entry) -> str:
    """A small inline picture of the entry's colour(s), about 1.6 em wide."""
    c = [palette.css(rgb) for rgb in entry.colors]
    if entry.shape == "line":
        height = _LINE_HEIGHT.get(entry.style, 0.32)
        paint = (
            f"repeating-linear-gradient(90deg,{c[0]} 0 0.3em,transparent 0.3em 0.5em)"
            if entry.style == "dashed"
            else c[0]
        )
        return _span(
            f"width:1.6em;height:{height}em;border-radius:{height / 2:g}em;background:{paint}"
        )
    if entry.shape == "arrow":
        bar = _span(f"width:1.15em;height:0.22em;background:{c[0]}")
        head = _span(
            "width:0;height:0;border-top:0.32em solid transparent;"
            f"border-bottom:0.32em solid transparent;border-left:0.45em solid {c[0]}"
        )
        return bar + head
    if entry.shape == "dot":
        return _span(
            f"width:0.7em;height:0.7em;margin:0 0.45em;border-radius:50%;background:{c[0]};"
            + _OUTLINE
        )
    if entry.shape == "patch":
        paint = (  # a translucent surface hatched, an opaque one filled
            f"repeating-linear-gradient(135deg,{c[0]} 0 0.22em,transparent 0.22em 0.36em)"
            if entry.style == "translucent"
            else c[0]
        )
        return _span(
            f"width:1.6em;height:0.8em;border-radius:0.15em;background:{paint};opacity:0.85;"
            + _OUTLINE
        )
    bars = "".join(
        _span(f"width:0.45em;height:0.3em;margin-right:0.08em;background:{color}") for color in c
    )
    return _span("width:1.6em", bars)


def legend_html(items: Sequence[Entry]) -> str:
    """The legend as HTML: two columns of swatch and name (text in the theme's colour)."""
    cells = "".join(
        f'<div data-legend="{html.escape(e.name)}" data-cue="{e.style}" style="white-space:nowrap">'
        f'<span style="display:inline-block;width:1.9em">{_swatch(e)}</span>'
        f"{html.escape(e.name)}</div>"
        for e in items
    )
    return (
        '<div class="poinsot-legend" style="display:grid;grid-template-columns:1fr 1fr;'
        "column-gap:0.6em;row-gap:0.15em;font-size:0.78rem;line-height:1.35;"
        f'padding:0.1em 0.75em 0.4em 0.75em">{cells}</div>'
    )


class Legend:
    """The caption and the legend at the top of the left column. Frame thread only."""

    def __init__(self, gui: viser.GuiApi, order: float = -2.0) -> None:
        self.caption = gui.add_markdown("", order=order)
        self.legend = gui.add_html("", order=order + 0.5)
        self._elements: frozenset[Element] = frozenset()
        self._extra: tuple[Entry, ...] = ()
        #: Rows of the drawings a scene or a lecture tool adds, by who added them.
        self._rows: dict[str, tuple[Entry, ...]] = {}
        self._look = palette.DARK
        #: Other places that show the legend too, each with its wrapping (a phone's sheet).
        self._mirrors: list[tuple[viser.GuiHtmlHandle, Callable[[str], str]]] = []

    def show_caption(self, text: str) -> None:
        """Say what the picture shows (a preset's caption, or a scene's at any time)."""
        content = f"<small>{text}</small>" if text else ""
        if self.caption.content != content:
            self.caption.content = content

    def show(self, elements: Iterable[Element], extra: Sequence[Entry] = ()) -> None:
        """List ``elements`` (the declared ones), and ``extra`` entries after them."""
        self._elements, self._extra = frozenset(elements), tuple(extra)
        self._render()

    def show_rows(self, owner: str, rows: Sequence[Entry]) -> None:
        """List ``rows`` after the elements' for ``owner``'s drawings (a scene's parts, the
        neighbour body), replacing what ``owner`` listed before; no rows take them away."""
        if tuple(rows) == self._rows.get(owner, ()):
            return
        if rows:
            self._rows[owner] = tuple(rows)
        else:
            self._rows.pop(owner, None)
        self._render()

    def restyle(self, look: Look) -> None:
        """The scene's colours changed (theme, projector)."""
        self._look = look
        self._render()

    def mirror(self, place: viser.GuiHtmlHandle, wrap: Callable[[str], str]) -> None:
        """Show the legend in ``place`` too, as ``wrap(the legend's HTML)``, kept up to date."""
        self._mirrors.append((place, wrap))
        self._render()

    def items(self) -> list[Entry]:
        added = [row for rows in self._rows.values() for row in rows]
        return merged([*entries(self._elements, self._look), *self._extra, *added])

    def _render(self) -> None:
        items = self.items()
        content = legend_html(items) if items else ""
        if self.legend.content != content:
            self.legend.content = content
        for place, wrap in self._mirrors:
            if place.content != (text := wrap(content)):
                place.content = text
