"""The demos run as scripts, serially and on 2 MPI ranks (launched with ``mpirun`` from
the serial test session), and are valid jupytext notebooks."""

import shutil
import subprocess
import sys
from pathlib import Path

import jupytext
import pytest

DEMOS = Path(__file__).parents[1] / "demos"
#: the MPI launcher beside the interpreter (the wheel's MPICH), else the one on PATH
MPIRUN = shutil.which("mpirun", path=str(Path(sys.executable).parent)) or shutil.which("mpirun")
RANKS = pytest.mark.parametrize("ranks", [1, 2], ids=["1 rank", "2 ranks"])


def run_demo(name: str, args: list[str], cwd: Path, timeout: int = 300, ranks: int = 1) -> str:
    """Run ``demos/<name>`` as a script on ``ranks`` MPI ranks; its standard output (it
    must succeed)."""
    launcher = []
    if ranks > 1:
        if MPIRUN is None:
            pytest.skip("no mpirun")
        launcher = [MPIRUN, "-n", str(ranks)]
    result = subprocess.run(
        [*launcher, sys.executable, str(DEMOS / name), *args],
        capture_output=True,
        text=True,
        timeout=timeout,
        cwd=cwd,
    )
    assert result.returncode == 0, result.stderr
    return result.stdout


@pytest.mark.serial
@RANKS
def test_hertz_demo_runs(tmp_path, ranks):
    out = tmp_path / "out"
    stdout = run_demo("hertz.py", ["--h", "0.01", "--out", str(out)], tmp_path, ranks=ranks)
    assert "half-width" in stdout
    # the deformed mesh is drawn from a serial run only (output.plot_deformed)
    pictures = ["hertz_pressure.png"] + (["hertz_deformed.png"] if ranks == 1 else [])
    for name in pictures:
        assert (out / name).stat().st_size > 10_000
    assert (out / "hertz" / "displacement.bp").is_dir()


@pytest.mark.serial
@RANKS
def test_beams_demo_runs(tmp_path, ranks):
    out = tmp_path / "out"
    args = ["--divisions", "3", "--mu", "0", "--load", "2", "--steps", "8", "--out", str(out)]
    stdout = run_demo("beams.py", args, tmp_path, timeout=600, ranks=ranks)
    for text in ("tip displacement", "contact force", "wall time"):
        assert text in stdout
    for name in ("beams_reference.png", "beams_reference_xz.png", "beams_mu0_iso.png"):
        assert (out / name).stat().st_size > 10_000
    assert (out / "beams_mu0" / "contact_0.bp").is_dir()


@pytest.mark.serial
@RANKS
def test_plastic_indentation_demo_runs(tmp_path, ranks):
    out = tmp_path / "out"
    args = ["--steps", "4", "--out", str(out)]
    stdout = run_demo("plastic_indentation.py", args, tmp_path, ranks=ranks)
    assert "plastic: peak pressure" in stdout and "imprint" in stdout
    pictures = ["indentation_force.png"]
    pictures += ["indentation_plastic_strain.png"] if ranks == 1 else []  # serial only
    for name in pictures:
        assert (out / name).stat().st_size > 10_000
    assert (out / "indentation_plastic" / "plastic_strain_2.bp").is_dir()


@pytest.mark.serial
@RANKS
def test_membrane_demo_runs(tmp_path, ranks):
    out = tmp_path / "out"
    args = ["--mu", "0.3", "--out", str(out)]
    stdout = run_demo("membrane.py", args, tmp_path, ranks=ranks)
    assert "12 steps, 0 cut-backs" in stdout
    # the plate slides under the whole underside: the sideways force is mu times the normal
    assert "sideways / normal plate force +0.300" in stdout
    for name in ("membrane_mu0.3_above.png", "membrane_mu0.3_below.png"):
        assert (out / name).stat().st_size > 10_000
    for name in ("displacement_0.bp", "displacement_1.bp", "contact_0.bp", "contact_1.bp"):
        assert (out / "membrane_mu0.3" / name).is_dir()


@pytest.mark.parametrize("demo", sorted(DEMOS.glob("*.py")), ids=lambda p: p.name)
def test_demo_is_a_notebook(demo):
    notebook = jupytext.read(demo)
    kinds = {cell.cell_type for cell in notebook.cells}
    assert kinds == {"markdown", "code"}
