"""A body of one's own in a real browser: files chosen in viser's file input (as a student picks
them), then what the page shows: the fit's readout and the measured ω in the plot, the mesh as
the body and its moments in the sliders."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import session_of, wait_until
from uploading import MESH, RECORDING, expected_moments, toss_recording

from poinsot.app.model import own_bodies
from poinsot.app.model.bodies import ASSETS, load_mesh_body
from poinsot.app.model.presets import FITTED_TOSS, MESH_BODY

pytestmark = pytest.mark.browser

SLIDERS = ("I₁", "I₂", "I₃")

#: The page's uPlot charts: series count, and the finite values of each series.
_UPLOTS_JS = """() => {
  const charts = Object.values((window.__viserTestpoints || {}).uplots || {});
  return charts.map(({chart}) => ({
    series: chart.series.map(s => s.label),
    y: [chart.scales.y.min, chart.scales.y.max],
    finite: chart.data.map(col => Array.from(col).filter(Number.isFinite).length),
  }));
}"""


def choose_file(page, button: str, path) -> None:
    """Pick ``path`` in the hidden file input behind the upload button labelled ``button``."""
    uuid = page.page.get_by_role("button", name=button, exact=True).get_attribute("id")
    assert uuid, f"no upload button {button!r}"
    page.page.locator(f"[id='file_upload_{uuid}']").set_input_files(str(path))


@pytest.fixture(scope="module")
def shared(make_module_app, open_module_page):
    """(app, page): one page on one app for both uploads (the mesh's after the recording's),
    drawing no live frames until the mesh's test reads the 3D view's pixels."""
    app = make_module_app()
    return app, open_module_page(app.url, live_view=False)


def open_entry(shared, label: str, button: str):
    """The module's page on the preset ``label``, its upload button ``button`` shown."""
    app, page = shared
    session = session_of(app, timeout=60)  # a loaded machine: the page's session comes late
    assert wait_until(lambda: session.stats.frames > 10, 20), "the scene is not animating"
    page.choose("Preset", label)
    assert wait_until(lambda: session.preset.label == label, 10)
    page.page.get_by_role("button", name=button, exact=True).wait_for(timeout=10000)
    return page, session


def test_an_uploaded_recording_is_fitted_and_drawn_over_the_exact_motion(shared, tmp_path):
    path = tmp_path / "my toss.csv"
    path.write_bytes(toss_recording())
    page, session = open_entry(shared, FITTED_TOSS.label, RECORDING)
    finished = session.uploads.finished
    choose_file(page, RECORDING, path)
    assert wait_until(lambda: session.uploads.finished > finished, 30), "the upload never finished"
    toss = session.uploads.toss
    assert toss is not None, session.uploads.toss_lines.status
    fit = toss.fit
    np.testing.assert_allclose(fit.inertia, expected_moments(), atol=5e-3)
    # the readout: each moment with its sigma, the verdict, both flip periods
    for k in range(3):
        text = own_bodies.plus_minus(float(fit.inertia[k]), float(fit.inertia_sigma[k]))
        page.page.get_by_text(text, exact=True).first.wait_for(timeout=10000)
    for text in ("rms residual", "explained", "flip period, predicted", "flip period, measured"):
        assert page.page.get_by_text(text, exact=True).count() >= 1, text
    # the sliders show the fitted body
    for label, moment in zip(SLIDERS, session.params.inertia, strict=True):
        assert wait_until(lambda la=label, m=moment: abs(page.slider_value(la) - m) < 1e-6, 10)
    assert page.slider_value("|ω₀|") == pytest.approx(np.linalg.norm(fit.omega0), rel=1e-6)

    # the plot: seven series, the measured ones holding every kept sample of the recording
    def overlaid() -> bool:
        charts = page.page.evaluate(_UPLOTS_JS)
        return any(len(c["series"]) == 7 and c["finite"][4] == toss.tau.size for c in charts)

    assert wait_until(overlaid, 15), page.page.evaluate(_UPLOTS_JS)
    (chart,) = [c for c in page.page.evaluate(_UPLOTS_JS) if len(c["series"]) == 7]
    assert chart["series"][4:] == ["ω₁ measured", "ω₂ measured", "ω₃ measured"]
    assert chart["finite"][1] == chart["finite"][0]  # the exact solution: everywhere
    low, high = chart["y"]  # an axis ranged over NaN would be NaN: nothing drawn
    assert low is not None and high is not None and low < -9.0 and high > 9.0  # |ω₂| ≈ 10
    assert page.errors == []
    assert session.stats.errors == 0, session.stats.last_error


def test_an_uploaded_mesh_becomes_the_body(shared):
    book = ASSETS / "book.stl"
    measured = load_mesh_body(book.read_bytes(), "book.stl")
    page, session = open_entry(shared, MESH_BODY.label, MESH)
    if not session.clock.paused:  # (the module's page: as the test before left it)
        page.click_button("Pause")
    assert wait_until(lambda: session.clock.paused, 30)
    page.set_live_view(True)
    page.drawn_after(session.client)
    before = page.screenshot_rgb()
    finished = session.uploads.finished
    choose_file(page, MESH, book)
    assert wait_until(lambda: session.uploads.finished > finished, 30), "the upload never finished"
    assert wait_until(lambda: session.scene.geometry.solid_key[0] == "mesh", 10)
    solid = session.scene.geometry.solid_base
    assert len(solid.vertices) == len(measured.mesh.vertices)
    assert len(solid.faces) == len(measured.mesh.faces)
    for label, moment in zip(SLIDERS, measured.ratios, strict=True):
        assert wait_until(lambda la=label, m=moment: abs(page.slider_value(la) - m) < 1e-6, 10)
    page.page.get_by_text("book.stl", exact=False).first.wait_for(timeout=10000)
    page.drawn_after(session.client)
    after = page.screenshot_rgb()
    view = slice(None), slice(0, int(before.shape[1] * 0.6))
    changed = np.mean(np.any(np.abs(after[view].astype(int) - before[view]) > 24, axis=2))
    assert changed > 0.005, f"only {changed:.4f} of the view changed"
    assert page.errors == []
    assert session.stats.errors == 0, session.stats.last_error
