"""``tests/durations.py``: a JUnit report's seconds summed by the suite's worker groups."""

from __future__ import annotations

from pathlib import Path

from tests import durations

REPORT = """<?xml version="1.0" encoding="utf-8"?>
<testsuites><testsuite name="pytest">
<testcase classname="tests.browser.test_video_page" name="test_a" time="30.0"/>
<testcase classname="tests.browser.test_live_page" name="test_b" time="20.0"/>
<testcase classname="tests.browser.test_live_page" name="test_c[x]" time="5.0"/>
<testcase classname="tests.report.test_study" name="test_d" time="12.5"/>
<testcase classname="tests.physics.test_corners" name="test_e" time="1.5"/>
</testsuite></testsuites>
"""


def test_the_groups_and_the_slowest_tests_are_printed(tmp_path: Path, capsys) -> None:
    report = tmp_path / "junit.xml"
    report.write_text(REPORT)
    assert durations.node_ids(report)[2] == ("tests/browser/test_live_page.py::test_c[x]", 5.0)
    assert durations.main([str(report), "--slowest", "2", "--workers", "4"]) == 0
    out = capsys.readouterr().out
    assert "5 tests, 69 s of test time in all" in out
    # The browser groups: the video page's in browser-2, the live page's in browser-1 (25 s).
    assert "the parallel stage lasts at least 30 s:" in out
    lines = out.splitlines()
    groups = lines[lines.index(" seconds  tests  group") + 1 :][:4]
    assert [g.split()[-1] for g in groups] == [
        "browser-2",
        "browser-1",
        "report",
        "tests/physics/test_corners.py",
    ]
    assert "12.5" in groups[2] and "25.0" in groups[1]
    slowest = out.split("slowest tests")[1].split()
    assert slowest[:2] == ["30.0", "tests/browser/test_video_page.py::test_a"]
    assert "test_e" not in out.split("slowest tests")[1]
