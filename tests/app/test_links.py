"""Links to a state without a browser: what each link opens, the bad links' messages and
``poinsot serve --link`` (the browser's side: tests/browser/test_links_page.py)."""

from __future__ import annotations

import urllib.parse

import pytest

from poinsot.app.cli import main as cli
from poinsot.app.lessons import SCENES, scene_by_name
from poinsot.app.lessons.support.spec import Slider
from poinsot.app.live.classroom import links
from poinsot.app.live.classroom.links import LinkError, opening, parse
from poinsot.app.live.hardening import network
from poinsot.app.model.presets import CUSTOM, DEFAULT_PRESET, preset_by_key


def test_a_preset_at_a_time_from_a_view():
    link = parse("preset=t_handle&t=12&view=side&paused=1")
    assert link.preset is preset_by_key("t_handle") and link.scene is None
    assert (link.t, link.view, link.paused, link.speed) == (12.0, "side", True, None)


def test_a_scene_and_its_controls_by_their_keys():
    link = parse("scene=dzhanibekov&epsilon=1e-8")
    assert link.scene is not None and link.scene.defaults()["epsilon"] == 1e-8
    assert parse("scene=dzhanibekov&epsilon=1e-08").scene.defaults()["epsilon"] == 1e-8
    top = parse("scene=gyroscope-torque&M=-0.25&spin=2").scene.defaults()
    assert (top["M"], top["spin"]) == (-0.25, 2.0)
    assert parse("scene=long-cylinder&lapse=×10").scene.initial_speed() == 10.0
    assert scene_by_name("dzhanibekov").defaults()["epsilon"] == 1e-3  # the catalogue's kept


@pytest.mark.parametrize("spec", SCENES, ids=lambda spec: spec.name)
def test_every_control_of_every_scene_comes_back_from_its_link(spec):
    """Copy link's query for each control moved (a slider to its top, a choice to its last
    option) opens that scene with that control there (the polhode family's D too: a scene's
    own control, not a body's parameter)."""
    for control in spec.controls:
        if isinstance(control, Slider):
            moved: float | str = control.hi
        elif control.speed:  # the clock's speed: a link's speed parameter
            continue
        else:
            moved = control.value(control.options[-1])
        pairs = [("scene", spec.name), *links._settings(spec, {control.key: moved})]
        opened = parse(urllib.parse.urlencode(pairs, safe=","))
        assert opened.scene is not None and opened.scene.defaults()[control.key] == moved, (
            control.key,
            pairs,
        )


def test_a_body_of_ones_own():
    link = parse("I=1,2,2.6&D=2.1&side=major&pole=plus&w=1.2&speed=0.5&paused=1")
    p = link.preset
    assert p.key == CUSTOM.key and p.label == CUSTOM.label
    assert (p.inertia, p.D, p.pole_sign, p.omega_norm) == ((1.0, 2.0, 2.6), 2.1, 1, 1.2)
    assert (link.speed, link.paused) == (0.5, True)
    # side=minor mirrors D = 2.1 (a sixth of the way from I2 to I3) into [I1, I2]
    assert parse("I=1,2,2.6&D=2.1&side=minor").preset.D == pytest.approx(2 - 0.1 / 0.6)
    assert parse("I=1,2,2.6&D=2.1&pole=minus").preset.pole_sign == -1


def test_viser_s_own_parameters_are_left_to_viser():
    assert parse("preset=oblate&websocket=ws://h:1&darkMode").preset is preset_by_key("oblate")
    assert parse("fixedDpr=1&preset=oblate&showStats").preset is preset_by_key("oblate")


@pytest.mark.parametrize(
    ("query", "named"),
    [
        ("preset=nope", "preset='nope'"),
        ("lead=1", "'lead'"),
        ("preset=t_handle&scene=dzhanibekov", "not both"),
        ("scene=dzhanibekov&D=2", "brings its own body"),
        ("scene=dzhanibekov&epsilon=3", "epsilon='3'"),
        ("scene=dzhanibekov&foo=1", "'foo' is not a parameter of the scene dzhanibekov"),
        ("scene=gyroscope-torque&M=9", "M=9 is outside [-1, 1]"),
        ("t=-1", "t=-1"),
        ("t=nan", "t=nan"),
        ("t=abc", "t='abc'"),
        ("t=1&t=2", "'t' is given twice"),
        ("view=top-down", "view='top-down'"),
        ("speed=99", "speed=99"),
        ("paused=maybe", "paused='maybe'"),
        ("I=1,2", "three moments"),
        ("I=1,1,5", "no body has I"),
        ("I=1,2,3&D=7", "D=7 is outside [1, 3]"),
        ("w=0", "w=0"),
        ("pole=up", "pole='up'"),
        ("side=left", "side='left'"),
    ],
)
def test_a_bad_link_names_its_parameter(query, named):
    with pytest.raises(LinkError) as caught:
        parse(query)
    assert named in str(caught.value)
    # opened: the server's default, with that message; never an exception
    opened = opening(f"http://h:1/?{query}", DEFAULT_PRESET, None)
    assert opened.preset is DEFAULT_PRESET and opened.scene is None and opened.t is None
    assert named in opened.problem and opened.problem.startswith("This link could not be opened")


def test_no_link_opens_the_server_s_default_without_a_message():
    scene = scene_by_name("explorer-1")
    for address in (None, "http://h:1/", "http://h:1/?", "http://h:1/?websocket=ws://h:1"):
        opened = opening(address, DEFAULT_PRESET, scene)
        assert (opened.preset, opened.scene, opened.problem) == (DEFAULT_PRESET, scene, "")


def test_a_worker_s_page_copies_links_that_name_the_landing():
    address = "http://10.0.0.7:8081/?preset=oblate"
    assert opening(address, DEFAULT_PRESET, None, (8081, 8080)).page == "http://10.0.0.7:8080/"
    assert opening(address, DEFAULT_PRESET, None, (8081, 0)).page == "http://10.0.0.7:8081/"
    # through a proxy the page is not on this server's port: its address is kept
    proxied = "https://lab.example/?preset=oblate"
    assert opening(proxied, DEFAULT_PRESET, None, (8081, 8080)).page == "https://lab.example/"


def test_serve_link_prints_the_link_and_its_qr_code(monkeypatch):
    monkeypatch.setattr(network, "_interface_addresses", lambda: [("wlan0", "10.0.0.7")])
    monkeypatch.setattr(network, "_route_address", lambda: "10.0.0.7")
    text = network.board("0.0.0.0", 8080, "preset=t_handle&t=12")
    url = "http://10.0.0.7:8080/?preset=t_handle&t=12"
    assert f"The link to this state: {url}" in text
    assert text.endswith("\n" + network.qr_text(url))
    assert (
        network.board("127.0.0.1", 8080, "t=1")
        .splitlines()[1]
        .endswith("http://127.0.0.1:8080/?t=1")
    )


@pytest.mark.parametrize("bad", ["preset=nope", "http://h:1/?t=-3", ""])
def test_serve_with_a_bad_link_is_one_line_and_status_2(bad, capsys):
    with pytest.raises(SystemExit) as caught:
        cli.main(["serve", "--link", bad, "--port", "0"])
    err = capsys.readouterr().err
    assert caught.value.code == 2 and err.count("\n") == 1 and "--link" in err
