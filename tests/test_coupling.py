"""Everything that adds unknowns or gathered fields is a ``Coupling``: checked statically
(mypy, on the classes) and on the objects of a problem."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

from contact_ufl.coupling import Coupling
from contact_ufl.problem import ContactProblem
from contact_ufl.verification import scenes

HERE = Path(__file__).parent


@pytest.mark.serial
def test_the_couplings_are_checked_statically(tmp_path):
    """mypy finds ``ContactInterface`` and ``VolumeConstraint`` to be ``Coupling``s, and
    refuses a class that lacks a member (so the check can fail)."""
    pytest.importorskip("mypy")
    cache = Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache")) / "contact_ufl" / "mypy"
    wrong = tmp_path / "wrong.py"
    wrong.write_text(
        "from contact_ufl.coupling import Coupling\n\n\n"
        "class Partial:\n    fields: list = []\n    unknowns: list = []\n\n\n"
        "def coupling(p: Partial) -> Coupling:\n    return p\n"
    )
    command = [sys.executable, "-m", "mypy", "--ignore-missing-imports", "--follow-imports=silent"]
    command += ["--cache-dir", str(cache), "--no-error-summary"]
    good = subprocess.run([*command, str(HERE / "coupling_types.py")], capture_output=True)
    assert good.returncode == 0, good.stdout.decode()
    bad = subprocess.run([*command, str(wrong)], capture_output=True, text=True)
    assert bad.returncode == 1 and "missing following" in bad.stdout, bad.stdout


def test_a_problem_s_couplings_are_couplings():
    """The operator's couplings of a scene with contact and friction (runtime check of the
    protocol's members)."""
    problem = ContactProblem(
        scenes.hertz_2d(h_contact=0.05, depth=0.01, mu=0.3).scene, verbose=False
    )
    couplings = problem.operator.system.couplings
    assert len(couplings) == 1 and all(isinstance(c, Coupling) for c in couplings)
