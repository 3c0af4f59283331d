"""The verification report: docs/verification.md is what tests/verification_report.py makes of
docs/verification.json (so the page is never edited by hand), every record has its fields and
a known kind, and the records of the ``verification`` fixture reach the JUnit XML file."""

import json
import math
import subprocess
import sys
from pathlib import Path

import pytest
import verification_report as report

ROOT = Path(__file__).parents[1]

pytestmark = pytest.mark.serial


def test_the_page_is_the_report_of_the_records():
    assert report.render(report.load(report.DATA)) == report.PAGE.read_text(), (
        "docs/verification.md is not the page of docs/verification.json: run "
        "`python tests/verification_report.py` (or `make verification-report`)"
    )


def test_every_record_has_its_fields_and_a_known_kind():
    records = json.loads(report.DATA.read_text())["records"]
    assert records
    assert records == sorted(records, key=report.sort_key)
    for record in records:
        assert sorted(record) == sorted(report.FIELDS), record
        assert record["kind"] in report.KINDS, record
        assert record["outcome"] in report.OUTCOMES, record
        for name in ("case", "quantity", "source", "nodeid"):
            assert isinstance(record[name], str) and record[name].strip(), record
        assert (ROOT / record["nodeid"].split("::")[0]).is_file(), record
        measured = record["measured"]
        values = measured if isinstance(measured, list) else [measured]
        assert values and all(isinstance(v, float) and math.isfinite(v) for v in values)
        assert isinstance(record["reference"], str | float | list), record
        assert isinstance(record["tolerance"], str | float), record


def test_the_page_says_which_files_record():
    page = report.PAGE.read_text()
    for name in report.recording_files(report.load(report.DATA)):
        assert f"`{name}`" in page
    assert report.COMMAND in page


def test_the_fixture_checks_its_arguments(verification):
    with pytest.raises(ValueError, match="kind"):
        verification("case", "quantity", 1.0, 0.0, 0.1, "source", kind="made up")
    with pytest.raises(TypeError, match="measured"):
        verification("case", "quantity", math.nan, 0.0, 0.1, "source")
    with pytest.raises(TypeError, match="source"):
        verification("case", "quantity", 1.0, 0.0, 0.1, "")


def test_records_reach_the_junit_file_and_the_page(tmp_path):
    """A run of pytest with ``--junitxml`` (on two xdist workers, as `make test` runs) gives
    the records of passed and failed tests, with their outcomes, to the script."""
    (tmp_path / "conftest.py").write_text(  # the fixture of tests/conftest.py
        "import importlib.util, sys\n"
        f"sys.path.insert(0, {str(ROOT / 'tests')!r})\n"
        f"path = {str(ROOT / 'tests' / 'conftest.py')!r}\n"
        "spec = importlib.util.spec_from_file_location('suite', path)\n"
        "suite = importlib.util.module_from_spec(spec)\n"
        "spec.loader.exec_module(suite)\n"
        "verification = suite.verification\n"
    )
    (tmp_path / "test_records.py").write_text(
        "def test_passes(verification):\n"
        "    verification('c', 'q', [1.0, 2.0], 'x = y', '|e| < 1', 's')\n"
        "def test_fails(verification):\n"
        "    verification('c', 'q', 0.5, 0.0, 0.1, 's', kind='consistency')\n"
        "    assert False\n"
    )
    xml = tmp_path / "run.xml"
    command = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-n", "2"]
    command += [f"--junitxml={xml}", "--rootdir", str(tmp_path), str(tmp_path)]
    run = subprocess.run(command, cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert run.returncode == 1, run.stdout + run.stderr  # one test fails
    records = report.read_junit(xml)
    assert [(r["kind"], r["outcome"], r["measured"]) for r in records] == [
        ("verification", "passed", [1.0, 2.0]),
        ("consistency", "failed", 0.5),
    ]
    assert records[0]["nodeid"] == "test_records.py::test_passes"
    data, page = tmp_path / "records.json", tmp_path / "page.md"
    assert report.main(["--from-junit", str(xml), "--data", str(data), "--output", str(page)]) == 0
    assert page.read_text() == report.render(records)
    assert "**FAIL**" in page.read_text() and "|e\\| < 1" in page.read_text()
