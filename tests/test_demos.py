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
#: the longer demos on 2 ranks run with the slow tests (their scenes' rank independence is
#: tested in test_plasticity; the membrane scenes run on 2 ranks in the 2-rank suite; the
#: beams and Hertz demos keep their 2-rank runs)
RANKS_SLOW_2 = pytest.mark.parametrize(
    "ranks", [1, pytest.param(2, marks=pytest.mark.slow)], ids=["1 rank", "2 ranks"]
)
#: the beams and Hertz demos on 2 ranks (as the README runs the beams); on 1 rank with the
#: slow tests (tests/test_notebooks.py runs the Hertz demo on one rank as a notebook)
RANKS_SLOW_1 = pytest.mark.parametrize(
    "ranks", [pytest.param(1, marks=pytest.mark.slow), 2], ids=["1 rank", "2 ranks"]
)


def run_demo(
    name: str, args: list[str], cwd: Path, timeout: int = 300, ranks: int = 1
) -> tuple[str, Path]:
    """Run ``demos/<name>`` as a script on ``ranks`` MPI ranks in ``cwd``, writing its
    output in ``cwd / "out"`` (``--out``); its standard output (it must succeed) and that
    folder."""
    out = cwd / "out"
    args = [*args, "--out", str(out)]
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
    return result.stdout, out


def assert_written(out: Path, pictures: list[str], directories: list[str]) -> None:
    """The demo wrote the ``pictures`` (each larger than 10 kB) and the (ADIOS2)
    ``directories`` in ``out``."""
    for name in pictures:
        assert (out / name).stat().st_size > 10_000
    for name in directories:
        assert (out / name).is_dir()


@pytest.mark.serial
@RANKS_SLOW_1
def test_hertz_demo_runs(tmp_path, ranks):
    stdout, out = run_demo("hertz.py", ["--h", "0.01"], tmp_path, ranks=ranks)
    assert "half-width" in stdout
    # the deformed mesh is drawn from a serial run only (output.plot_deformed)
    pictures = ["hertz_pressure.png"] + (["hertz_deformed.png"] if ranks == 1 else [])
    assert_written(out, pictures, ["hertz/displacement.bp"])


@pytest.mark.serial
@RANKS_SLOW_1
def test_beams_demo_runs(tmp_path, ranks):
    args = ["--divisions", "3", "--mu", "0", "--load", "2", "--steps", "8"]
    stdout, out = run_demo("beams.py", args, tmp_path, timeout=600, ranks=ranks)
    for text in ("tip displacement", "contact force", "wall time"):
        assert text in stdout
    pictures = ["beams_reference.png", "beams_reference_xz.png", "beams_mu0_iso.png"]
    assert_written(out, pictures, ["beams_mu0/contact_0.bp"])


@pytest.mark.serial
@RANKS_SLOW_2
def test_plastic_indentation_demo_runs(tmp_path, ranks):
    stdout, out = run_demo("plastic_indentation.py", ["--steps", "4"], tmp_path, ranks=ranks)
    assert "plastic: peak pressure" in stdout and "imprint" in stdout
    pictures = ["indentation_force.png"]
    pictures += ["indentation_plastic_strain.png"] if ranks == 1 else []  # serial only
    assert_written(out, pictures, ["indentation_plastic/plastic_strain_2.bp"])


@pytest.mark.serial
@pytest.mark.slow  # one rank: tests/test_notebooks.py runs this demo as a notebook
@RANKS
def test_membrane_demo_runs(tmp_path, ranks):
    stdout, out = run_demo("membrane.py", ["--mu", "0.3"], tmp_path, ranks=ranks)
    assert "12 steps, 0 cut-backs" in stdout
    # the plate slides under the whole underside: the sideways force is mu times the normal
    assert "sideways / normal plate force +0.300" in stdout
    pictures = ["membrane_mu0.3_above.png", "membrane_mu0.3_below.png"]
    files = ["displacement_0.bp", "displacement_1.bp", "contact_0.bp", "contact_1.bp"]
    assert_written(out, pictures, [f"membrane_mu0.3/{name}" for name in files])


@pytest.mark.serial
@pytest.mark.slow  # its loop: tests/test_adapt.py
@RANKS
def test_adaptive_hertz_demo_runs(tmp_path, ranks):
    # a looser tolerance than the demo's 0.05: five meshes instead of seven
    stdout, out = run_demo("adaptive_hertz.py", ["--tolerance", "0.1"], tmp_path, ranks=ranks)
    # the loop stopped because the relative estimate met the tolerance
    assert "stopped by the tolerance" in stdout
    assert stdout.strip().splitlines()[-1] == "reached: True"
    assert "normal contact force" in stdout and "estimated error -" in stdout
    views = ["first_whole", "first_contact", "last_whole", "last_contact", "last_edge"]
    pictures = [f"adaptive_hertz_{view}.png" for view in views] + ["adaptive_hertz_pressure.png"]
    assert_written(out, pictures, [])


@pytest.mark.parametrize("demo", sorted(DEMOS.glob("*.py")), ids=lambda p: p.name)
def test_demo_is_a_notebook(demo):
    notebook = jupytext.read(demo)
    kinds = {cell.cell_type for cell in notebook.cells}
    assert kinds == {"markdown", "code"}
