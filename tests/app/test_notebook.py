"""The example notebook runs (nbclient, a real IPython kernel) and its outputs hold the viewer:
viser's client with a recording of the scene, under the legend; bad arguments are ValueErrors."""

from __future__ import annotations

import base64
import re
from pathlib import Path

import pytest

from poinsot.app.notebook import clip, show
from poinsot.physics import FreeRigidBody

NOTEBOOK = Path(__file__).resolve().parents[2] / "docs" / "notebook.ipynb"

pytestmark = pytest.mark.slow


def test_the_example_notebook_runs_and_shows_the_viewer():
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    notebook = nbformat.read(NOTEBOOK, as_version=4)
    nbclient.NotebookClient(notebook, timeout=600, kernel_name="python3").execute()
    shows = [c for c in notebook.cells if c.cell_type == "code" and "show(" in c.source]
    assert len(shows) == 3
    for cell in shows:
        htmls = [o["data"]["text/html"] for o in cell.outputs if "text/html" in o.get("data", {})]
        assert len(htmls) == 2, cell.source  # the legend, then the viewer
        assert "polhode" in htmls[0]
        viewer = htmls[1]
        assert "<iframe" in viewer and "__VISER_EMBED_DATA__" in viewer
        data = re.search(r"__VISER_EMBED_DATA__=&quot;([A-Za-z0-9+/=]+)&quot;", viewer)
        assert data and len(base64.b64decode(data.group(1))) > 10_000  # a recording, not empty
        assert not [o for o in cell.outputs if o.get("output_type") == "error"]


def test_a_longer_clip_records_more():
    short, _ = clip(preset="t_handle", seconds=1)
    long, legend = clip(preset="t_handle", seconds=3)
    assert len(long.serialize()) > len(short.serialize())
    assert "herpolhode" in legend


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"preset": "nope"}, "no preset named 'nope'"),
        ({"scene": "nope"}, "no scene named"),
        ({"scene": "dzhanibekov", "nope": 1}, "no setting nope"),
        ({"preset": "t_handle", "epsilon": 1e-8}, "settings belong to a scene"),
        ({"preset": "t_handle", "scene": "dzhanibekov"}, "one of preset, scene or body"),
        ({"body": "a body"}, "must be a FreeRigidBody"),
        ({"preset": "t_handle", "seconds": -1}, "clip length"),
        ({"preset": "t_handle", "view": "ride-along"}, "fixed view"),
        ({"preset": "t_handle", "height": 5}, "height"),
    ],
)
def test_bad_arguments_are_a_clear_value_error(kwargs, message):
    with pytest.raises(ValueError, match=re.escape(message)):
        show(**kwargs)


def test_a_body_of_ones_own_keeps_its_moments_and_omega():
    body = FreeRigidBody((1.0, 2.0, 3.0), (0.1, 1.0, 0.2))
    serializer, legend = clip(body=body, seconds=0.5)
    assert "A body of your own" in legend and len(serializer.serialize()) > 1000
