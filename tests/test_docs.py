"""The documentation builds (Sphinx, MyST; the demos rendered, not run) with warnings as
errors, so with every reference resolved, and every public name has its entry in the API
reference."""

import importlib.util
import os
import subprocess
import sys
import zlib
from pathlib import Path

import pytest
from mpi4py import MPI

import contact_ufl as cu

DOCS = Path(__file__).parents[1] / "docs"
TOOLS = ("sphinx", "myst_nb", "furo", "jupytext", "sphinx-mathjax-offline")
MISSING = [name for name in TOOLS if importlib.util.find_spec(name) is None]

pytestmark = [
    pytest.mark.serial,
    pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="builds the documentation on one rank"),
    pytest.mark.skipif(
        bool(MISSING),
        reason=f"not installed: {', '.join(MISSING)} (pip install -e .[docs])",
    ),
]


@pytest.fixture(scope="module")
def build(tmp_path_factory) -> tuple[subprocess.CompletedProcess, Path]:
    """``sphinx-build -W --keep-going`` of docs/ into a temporary folder, the demos not run:
    the result of the run and the HTML folder."""
    out = tmp_path_factory.mktemp("docs") / "html"
    command = [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html"]
    command += ["-d", str(out.parent / "doctrees"), str(DOCS), str(out)]
    env = {**os.environ, "CONTACT_UFL_DOCS_EXECUTE": "off"}
    result = subprocess.run(command, capture_output=True, text=True, env=env, timeout=600)
    return result, out


def inventory_names(path: Path) -> set[str]:
    """The names of the objects in a Sphinx inventory (``objects.inv``, version 2: four
    header lines, then ``name domain:role priority uri display-name`` lines, compressed)."""
    data = path.read_bytes()
    header, body = data.split(b"\n", 4)[:4], data.split(b"\n", 4)[4]
    assert header[0].strip() == b"# Sphinx inventory version 2", header[0]
    lines = zlib.decompress(body).decode().splitlines()
    return {line.split(" py:", 1)[0] for line in lines if " py:" in line}


def test_docs_build_without_warnings(build):
    result, out = build
    assert result.returncode == 0, f"sphinx-build -W failed:\n{result.stderr[-6000:]}"
    assert (out / "index.html").exists()
    for page in ("api", "developer", "tutorial/hertz", "guide/index", "theory", "benchmarks"):
        assert (out / f"{page}.html").exists(), page


def test_formulas_need_no_network(build):
    """The pages load MathJax from the site's own _static folder, not from the web."""
    _, out = build
    theory = (out / "theory.html").read_text()
    assert "_static/mathjax/tex-chtml.js" in theory
    assert "cdn.jsdelivr" not in theory
    assert (out / "_static" / "mathjax" / "tex-chtml.js").stat().st_size > 100_000


def test_every_public_name_has_an_api_entry(build):
    result, out = build
    inventory = out / "objects.inv"
    assert inventory.exists(), f"no objects.inv:\n{result.stderr[-3000:]}"
    names = inventory_names(inventory)
    missing = [name for name in cu.__all__ if f"contact_ufl.{name}" not in names]
    assert not missing, f"not in docs/api.md: {missing}"
