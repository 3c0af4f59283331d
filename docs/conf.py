"""Sphinx configuration of the contact_ufl documentation (MyST Markdown, built offline).

``make docs`` builds it with the demos run as notebooks (``CONTACT_UFL_DOCS_EXECUTE=cache``,
the default); ``tests/test_docs.py`` builds it without running them
(``CONTACT_UFL_DOCS_EXECUTE=off``).
"""

import dataclasses
import filecmp
import importlib
import inspect
import os
import re
import shutil
import sys
from pathlib import Path

from sphinx.ext import napoleon
from sphinx.pycode import ModuleAnalyzer

import contact_ufl

DOCS = Path(__file__).resolve().parent
ROOT = DOCS.parent
sys.path.insert(0, str(DOCS / "_ext"))  # demo_notebooks, the demos' reader

# -- the tutorial: the demos, copied into docs/tutorial/ (generated, git-ignored) -------------
#: the demos, in the order of the tutorial
DEMOS = ["hertz", "adaptive_hertz", "plastic_indentation", "beams", "membrane"]
TUTORIAL = DOCS / "tutorial"


def copy_demos() -> None:
    """Copy ``demos/<name>.py`` to ``docs/tutorial/<name>.py``. A copy equal to its demo is
    left alone (Sphinx reads a source again when its time stamp changes); other files there
    are removed."""
    TUTORIAL.mkdir(exist_ok=True)
    copies = {TUTORIAL / f"{name}.py": ROOT / "demos" / f"{name}.py" for name in DEMOS}
    for copy, demo in copies.items():
        if not copy.exists() or not filecmp.cmp(demo, copy, shallow=False):
            shutil.copyfile(demo, copy)
    for path in TUTORIAL.iterdir():
        if path not in copies:
            shutil.rmtree(path) if path.is_dir() else path.unlink()


copy_demos()

# -- project -----------------------------------------------------------------------------------
project = "contact_ufl"
author = "the contact_ufl authors"
copyright = "the contact_ufl authors"
release = version = contact_ufl.__version__

extensions = [
    "myst_nb",
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    # a copy of MathJax in _static: the pages show their formulas without the network
    "sphinx-mathjax-offline",
]
root_doc = "index"
# every .py under docs/ would be read as a notebook: only those of tutorial/ are
exclude_patterns = ["conf.py", "_ext", "_build", "jupyter_execute", "**/.ipynb_checkpoints"]
# Every reference must resolve, with two exceptions: objects of other projects (no
# intersphinx: the build is offline), and objects of contact_ufl that exist but are not in
# its public API (`missing_public_reference` below): those are shown as code, not linked.
nitpicky = True
nitpick_ignore_regex = [
    (r"py:.*", r"(dolfinx|ufl|basix|petsc4py|PETSc|mpi4py|MPI|numpy|np|npt|scipy)(\..*)?"),
    (r"py:.*", r"(pyvista|gmsh|cffi|os|pathlib|typing|collections|abc)(\..*)?"),
    (r"py:.*", r"(Path|Callable|Iterable|Iterator|Sequence|Mapping|Any|Expr|Form|Measure)"),
]

# -- MyST and the notebooks --------------------------------------------------------------------
myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence", "deflist"]
myst_heading_anchors = 3
# the demos are jupytext percent-format scripts (_ext/demo_notebooks.py)
nb_custom_formats = {".py": "demo_notebooks.read_demo"}
#: "cache" (make docs: run each demo once, keep its outputs in docs/_build/.jupyter_cache
#: until it changes), "off" (the docs test), "force" or "auto"
nb_execution_mode = os.environ.get("CONTACT_UFL_DOCS_EXECUTE", "cache")
nb_execution_cache_path = str(DOCS / "_build" / ".jupyter_cache")
#: seconds a cell may take (the demos' solves run in one cell each)
nb_execution_timeout = int(os.environ.get("CONTACT_UFL_DOCS_TIMEOUT", "1800"))
nb_execution_in_temp = True  # the demos' files (meshes, VTX) go to a temporary folder
nb_execution_raise_on_error = True
nb_execution_show_tb = True
nb_merge_streams = True

# -- the API (autodoc, NumPy docstrings) -------------------------------------------------------
autodoc_member_order = "bysource"
autodoc_typehints = "signature"
autodoc_default_options = {"members": True}
autodoc_preserve_defaults = True
add_module_names = False
napoleon_google_docstring = False
napoleon_numpy_docstring = True
napoleon_use_rtype = False
# "Attributes" read like "Parameters": a list of the class's attributes (names, several to
# an entry where they share one description), not objects of their own
napoleon_custom_sections = [("Attributes", "params_style")]

# -- HTML --------------------------------------------------------------------------------------
html_theme = "furo"
html_title = "contact_ufl"
html_show_sourcelink = False


# -- hooks ---------------------------------------------------------------------------------------
def _public_aliases() -> dict[str, str]:
    """Where each public class and function is defined (``contact_ufl.scene.Scene``), with
    the name it is documented under (``contact_ufl.Scene``)."""
    aliases = {}
    for name in contact_ufl.__all__:
        obj = getattr(contact_ufl, name)
        if inspect.isclass(obj) or inspect.isfunction(obj):
            aliases[f"{obj.__module__}.{obj.__qualname__}"] = f"contact_ufl.{name}"
    return aliases


ALIASES = _public_aliases()


def _public_name(target: str) -> str | None:
    """``target`` with a public object's defining path replaced by its public name."""
    for defined, public in ALIASES.items():
        if target == defined or target.startswith(defined + "."):
            return public + target[len(defined) :]
    return None


def resolve_public_alias(app, env, node, contnode):
    """Resolve ``contact_ufl.problem.ContactProblem.solve`` (a docstring names an object by
    the module that defines it) to ``contact_ufl.ContactProblem.solve``."""
    if node.get("refdomain") != "py":
        return None
    public = _public_name(node["reftarget"])
    if public is None:
        return None
    domain = env.get_domain("py")
    return domain.resolve_xref(
        env, node["refdoc"], app.builder, node["reftype"], public, node, contnode
    )


def _exists(dotted: str) -> bool:
    """Whether ``dotted`` names a module, or an object or attribute in one (an instance
    attribute: a name its class's source assigns to ``self.<name>``, or annotates)."""
    parts = dotted.split(".")
    for k in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:k]))
        except ImportError:
            continue
        for attr in parts[k:]:
            if hasattr(obj, attr):
                obj = getattr(obj, attr)
            elif inspect.isclass(obj):
                name = re.escape(attr)
                try:
                    source = inspect.getsource(obj)
                except (OSError, TypeError):
                    return False
                return re.search(rf"(self\.{name}\s*[:=]|^\s+{name}\s*:)", source, re.M) is not None
            else:
                return False
        return True
    return False


def missing_public_reference(app, domain, node) -> bool | None:
    """Keep quiet (``True``) about a reference to an object of contact_ufl that exists but is
    not documented here (not public): it stays unlinked code. A docstring names it either in
    full or as seen from its own module, which is one of the package's. A reference to
    nothing is warned about as usual."""
    if domain is None or domain.name != "py":
        return None
    target = node["reftarget"].lstrip(".~")
    candidates = [target] if target.startswith("contact_ufl.") else []
    if node.get("py:class"):  # a member, from its class's docstrings
        candidates.append(f"{node.get('py:module')}.{node['py:class']}.{target}")
    modules = sorted(m for m in sys.modules if m.split(".")[0] == "contact_ufl")
    candidates += [f"{m}.{target}" for m in modules]
    return True if any(_exists(c) for c in candidates) else None


def data_doc_comment(app, what, name, obj, options, lines) -> None:
    """The doc comment (``#:``) of a public constant, from the module that defines it (autodoc
    looks in ``contact_ufl/__init__.py`` and finds none)."""
    if what != "data" or not name.startswith("contact_ufl."):
        return
    attr = name.rsplit(".", 1)[1]
    for module in sorted(m for m in sys.modules if m.startswith("contact_ufl.")):
        if getattr(sys.modules[module], attr, None) is obj:
            comments = ModuleAnalyzer.for_module(module).find_attr_docs()
            if ("", attr) in comments:
                lines[:] = list(comments["", attr])
                return


def dataclass_factories(app, what, name, obj, options, signature, return_annotation):
    """A dataclass field's default made by ``default_factory`` shows as ``<factory>``, which
    is no Python: Sphinx then splits the signature at every comma (``dict[str, int]``).
    Show the factory's call, ``list()``, instead."""
    if not signature or "<factory>" not in signature or not dataclasses.is_dataclass(obj):
        return None
    for f in dataclasses.fields(obj):
        if f.default_factory is not dataclasses.MISSING:
            signature = signature.replace("<factory>", f"{f.default_factory.__name__}()", 1)
    return signature, return_annotation


def numpy_docstrings(app, what, name, obj, options, lines) -> None:
    """Napoleon's reading of the NumPy docstrings, but for properties and attributes:
    napoleon would read the first line of theirs as ``type: description``, and ours are
    sentences (``Whether the body is a membrane (string): ...``)."""
    if what not in ("attribute", "property", "data"):
        napoleon._process_docstring(app, what, name, obj, options, lines)


def setup(app):
    for listener in list(app.events.listeners["autodoc-process-docstring"]):
        if listener.handler is napoleon._process_docstring:
            app.disconnect(listener.id)
    app.connect("autodoc-process-docstring", numpy_docstrings)
    app.connect("autodoc-process-docstring", data_doc_comment)
    app.connect("autodoc-process-signature", dataclass_factories)
    app.connect("missing-reference", resolve_public_alias)
    app.connect("warn-missing-reference", missing_public_reference)
