"""The Hertz demo runs as a Jupyter notebook and shows its pictures inline."""

import json
import sys
from pathlib import Path
from types import SimpleNamespace

import jupytext
import nbclient
import nbformat
import pytest

from contact_ufl import output

DEMOS = Path(__file__).parents[1] / "demos"
KERNEL = "contact_ufl_test"


@pytest.fixture
def kernel(tmp_path, monkeypatch) -> str:
    """A kernelspec running this interpreter (first on JUPYTER_PATH): the notebook imports
    the same contact_ufl, DOLFINx and PETSc as the tests."""
    spec = tmp_path / "jupyter" / "kernels" / KERNEL
    spec.mkdir(parents=True)
    argv = [sys.executable, "-m", "ipykernel_launcher", "-f", "{connection_file}"]
    spec.joinpath("kernel.json").write_text(
        json.dumps({"argv": argv, "display_name": KERNEL, "language": "python"})
    )
    monkeypatch.setenv("JUPYTER_PATH", str(tmp_path / "jupyter"))
    return KERNEL


@pytest.mark.parametrize(
    ("shell", "kernel"),
    [(None, False), (SimpleNamespace(), False), (SimpleNamespace(kernel=object()), True)],
    ids=["plain python", "terminal IPython", "Jupyter kernel"],
)
def test_inline_pictures_only_in_a_kernel(monkeypatch, shell, kernel):
    assert not output.in_jupyter_kernel()  # pytest is not a kernel
    monkeypatch.setitem(sys.modules, "IPython", SimpleNamespace(get_ipython=lambda: shell))
    assert output.in_jupyter_kernel() == kernel


@pytest.mark.serial
def test_hertz_notebook_shows_pictures(tmp_path, kernel):
    work = tmp_path / "run"
    work.mkdir()
    notebook = jupytext.read(DEMOS / "hertz.py")
    probe = nbformat.v4.new_code_cell("import sys\nprint(sys.executable)")
    notebook.cells.insert(0, probe)
    client = nbclient.NotebookClient(
        notebook, kernel_name=kernel, timeout=300, resources={"metadata": {"path": str(work)}}
    )
    client.execute()
    assert probe.outputs[0]["text"].strip() == sys.executable
    outputs = [o for cell in notebook.cells if cell.cell_type == "code" for o in cell.outputs]
    images = [o for o in outputs if "image/png" in o.get("data", {})]
    assert images, "no cell output holds an image/png"
    assert list(work.rglob("*.png")), "the notebook did not write its pictures as files"


@pytest.mark.slow
@pytest.mark.serial
def test_membrane_notebook_shows_pictures(tmp_path, kernel):
    """The membrane demo (two meshes, a rigid plate, both friction coefficients) as a
    notebook: its four pictures inline and as files."""
    work = tmp_path / "run"
    work.mkdir()
    notebook = jupytext.read(DEMOS / "membrane.py")
    client = nbclient.NotebookClient(
        notebook, kernel_name=kernel, timeout=600, resources={"metadata": {"path": str(work)}}
    )
    client.execute()
    outputs = [o for cell in notebook.cells if cell.cell_type == "code" for o in cell.outputs]
    images = [o for o in outputs if "image/png" in o.get("data", {})]
    assert len(images) == 4
    assert len(list(work.rglob("membrane_mu*.png"))) == 4
