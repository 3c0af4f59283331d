"""The benchmark report: docs/benchmarks.md is what benchmarks/report.py makes of the results
files (so the page is never edited by hand), every results file carries its stamp, and a
results file is written whole, with its stamp, or not at all."""

import json
import re
import shutil
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).parents[1]
RESULTS = ROOT / "benchmarks" / "results"
PAGE = ROOT / "docs" / "benchmarks.md"
sys.path.insert(0, str(ROOT / "benchmarks"))
import report  # noqa: E402
import resultfile  # noqa: E402

pytestmark = pytest.mark.serial


def test_the_page_is_the_report_of_the_results():
    assert report.render(RESULTS) == PAGE.read_text(), (
        "docs/benchmarks.md is not the report of benchmarks/results/: run `make benchmark-report`"
    )


def test_the_figures_of_the_page_exist():
    figures = re.findall(r"^```\{figure\} (\S+)$", PAGE.read_text(), flags=re.M)
    assert figures
    for name in figures:
        assert (PAGE.parent / name).is_file(), f"{name}: run `make benchmark-report`"


def test_every_results_file_has_a_stamp():
    files = sorted(RESULTS.glob("*.json"))
    assert files
    for path in files:
        stamp, _ = resultfile.read(path)
        assert stamp is not None, f"{path.name} has no stamp"
        assert [f for f in resultfile.FIELDS if f not in stamp] == [], path.name
        assert stamp["stamp_source"] in ("run", "git history"), path.name
        assert re.fullmatch(r"[0-9a-f]{40}", stamp["commit"]), path.name
        assert re.fullmatch(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ", stamp["date"]), path.name
        assert isinstance(stamp["machine"], dict) and "cores" in stamp["machine"], path.name
        ranks = stamp["ranks"]
        counts = ranks if isinstance(ranks, list) else [ranks]
        assert ranks == resultfile.UNRECORDED or all(isinstance(k, int) for k in counts)
        if stamp["stamp_source"] == "run":
            assert isinstance(stamp["dirty"], bool), path.name
            assert re.match(r"(mpirun -n \d+ )?python benchmarks/", stamp["command"]), path.name
            assert {"dolfinx", "petsc4py", "numpy"} <= set(stamp["versions"]), path.name


def test_a_results_file_is_written_whole_with_its_stamp(tmp_path):
    path = tmp_path / "results" / "run.json"
    argv = [str(ROOT / "benchmarks" / "run.py"), "--json", "out.json"]
    resultfile.write(path, [{"x": 1.5}], ranks=2, argv=argv)
    stamp, results = resultfile.read(path)
    assert results == [{"x": 1.5}]
    assert stamp["ranks"] == 2 and stamp["stamp_source"] == "run"
    assert stamp["command"] == "mpirun -n 2 python benchmarks/run.py --json out.json"
    assert set(resultfile.FIELDS) <= set(stamp)
    assert json.loads(path.read_text())["results"] == [{"x": 1.5}]
    with pytest.raises(TypeError):  # not JSON: the file keeps what it had
        resultfile.write(path, [object()], ranks=1, argv=argv)
    assert resultfile.load(path) == [{"x": 1.5}]
    assert [p.name for p in path.parent.iterdir()] == ["run.json"]  # no temporary file left


def test_a_file_without_a_stamp_is_read_whole(tmp_path):
    path = tmp_path / "old.json"
    path.write_text(json.dumps({"quick": True, "records": []}))
    assert resultfile.read(path) == (None, {"quick": True, "records": []})


def test_the_report_shows_every_results_file_and_only_stamped_ones(tmp_path):
    folder = tmp_path / "results"
    shutil.copytree(RESULTS, folder)
    resultfile.write(folder / "extra.json", [], ranks=1, argv=["extra.py"])
    with pytest.raises(ValueError, match="in no table of the report: extra.json"):
        report.render(folder)
    (folder / "extra.json").unlink()
    name = "taylor.json"
    (folder / name).write_text(json.dumps(resultfile.load(folder / name)))
    with pytest.raises(ValueError, match=f"{name} has no stamp"):
        report.render(folder)
    (folder / name).unlink()
    with pytest.raises(ValueError, match=f"named in the report but not in .*: {name}"):
        report.render(folder)
