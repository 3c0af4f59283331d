"""The demos run as scripts and are valid jupytext notebooks."""

import subprocess
import sys
from pathlib import Path

import jupytext
import pytest

DEMOS = Path(__file__).parents[1] / "demos"


@pytest.mark.serial
def test_hertz_demo_runs(tmp_path):
    out = tmp_path / "out"
    result = subprocess.run(
        [sys.executable, str(DEMOS / "hertz.py"), "--h", "0.01", "--out", str(out)],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=tmp_path,
    )
    assert result.returncode == 0, result.stderr
    assert "half-width" in result.stdout
    for name in ("hertz_pressure.png", "hertz_deformed.png"):
        assert (out / name).stat().st_size > 10_000
    assert (out / "hertz" / "displacement.bp").is_dir()


@pytest.mark.parametrize("demo", sorted(DEMOS.glob("*.py")), ids=lambda p: p.name)
def test_demo_is_a_notebook(demo):
    notebook = jupytext.read(demo)
    kinds = {cell.cell_type for cell in notebook.cells}
    assert kinds == {"markdown", "code"}
