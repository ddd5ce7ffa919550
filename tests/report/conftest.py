"""Fixtures shared by the report's tests.

``quick_report``: one ``poinsot report --quick`` through the real command line (session scope,
~30 s on the 2-core CI machine), for the tests that read the files it writes.
``small_study``: three cases (Toutatis, 1 - m = 1e-14, the separatrix) at the ``--quick``
settings, run through the study itself without writing a report (~3 s on an idle machine),
for the tests that draw figures or read findings from the results.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

from poinsot.app.cli import main as cli_main
from poinsot.app.report.cases import CASES, StudyConfig
from poinsot.app.report.exact import load_reference
from poinsot.app.report.progress import Progress
from poinsot.app.report.study import CaseResult, study_case

SMALL_STUDY_CASES = ("Toutatis", "near-separatrix 1-m=1e-14", "separatrix")


@pytest.fixture(scope="session")
def quick_report(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("report")
    assert cli_main(["report", "--quick", "--out", str(out)]) == 0
    return out


@pytest.fixture(scope="session")
def small_study() -> list[CaseResult]:
    by_name = {c.name: c for c in CASES}
    quick = StudyConfig.for_mode(quick=True)
    config = dataclasses.replace(quick, cases=tuple(by_name[n] for n in SMALL_STUDY_CASES))
    reference_cls, _ = load_reference()
    progress = Progress(1, enabled=False)
    return [study_case(case, config, reference_cls, progress) for case in config.cases]
