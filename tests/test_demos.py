"""The demos run as scripts and are valid jupytext notebooks."""

import subprocess
import sys
from pathlib import Path

import jupytext
import pytest

DEMOS = Path(__file__).parents[1] / "demos"


def run_demo(name: str, args: list[str], cwd: Path, timeout: int = 300) -> str:
    """Run ``demos/<name>`` as a script; its standard output (it must succeed)."""
    result = subprocess.run(
        [sys.executable, str(DEMOS / name), *args],
        capture_output=True,
        text=True,
        timeout=timeout,
        cwd=cwd,
    )
    assert result.returncode == 0, result.stderr
    return result.stdout


@pytest.mark.serial
def test_hertz_demo_runs(tmp_path):
    out = tmp_path / "out"
    stdout = run_demo("hertz.py", ["--h", "0.01", "--out", str(out)], tmp_path)
    assert "half-width" in stdout
    for name in ("hertz_pressure.png", "hertz_deformed.png"):
        assert (out / name).stat().st_size > 10_000
    assert (out / "hertz" / "displacement.bp").is_dir()


@pytest.mark.serial
def test_beams_demo_runs(tmp_path):
    out = tmp_path / "out"
    args = ["--divisions", "3", "--mu", "0", "--load", "2", "--steps", "8", "--out", str(out)]
    stdout = run_demo("beams.py", args, tmp_path, timeout=600)
    for text in ("tip displacement", "contact force", "wall time"):
        assert text in stdout
    for name in ("beams_reference.png", "beams_reference_xz.png", "beams_mu0_iso.png"):
        assert (out / name).stat().st_size > 10_000
    assert (out / "beams_mu0" / "contact_0.bp").is_dir()


@pytest.mark.serial
def test_plastic_indentation_demo_runs(tmp_path):
    out = tmp_path / "out"
    stdout = run_demo("plastic_indentation.py", ["--steps", "4", "--out", str(out)], tmp_path)
    assert "plastic: peak pressure" in stdout and "imprint" in stdout
    for name in ("indentation_force.png", "indentation_plastic_strain.png"):
        assert (out / name).stat().st_size > 10_000
    assert (out / "indentation_plastic" / "plastic_strain_2.bp").is_dir()


@pytest.mark.parametrize("demo", sorted(DEMOS.glob("*.py")), ids=lambda p: p.name)
def test_demo_is_a_notebook(demo):
    notebook = jupytext.read(demo)
    kinds = {cell.cell_type for cell in notebook.cells}
    assert kinds == {"markdown", "code"}
