"""Read a demo (a jupytext percent-format script) as a notebook for myst-nb.

The scripts carry no kernel metadata: the notebook gets the ``python3`` kernel (the
interpreter that builds the documentation) and the Python language, so that its code cells
are highlighted also when the build does not run them.
"""

import jupytext
import nbformat

KERNELSPEC = {"name": "python3", "display_name": "Python 3", "language": "python"}
LANGUAGE = {"name": "python", "pygments_lexer": "ipython3"}


def read_demo(text: str) -> nbformat.NotebookNode:
    """The notebook of the percent-format script ``text``."""
    notebook = jupytext.reads(text, fmt="py:percent")
    notebook.metadata.setdefault("kernelspec", dict(KERNELSPEC))
    notebook.metadata.setdefault("language_info", dict(LANGUAGE))
    return notebook
