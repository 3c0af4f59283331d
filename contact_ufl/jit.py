"""How the package's forms are compiled: FFCx writes C, the C compiler builds it.

DOLFINx builds every kernel with ``-O2``. The package's kernels run as fast built with
``-O1``, which compiles faster: the large 3D contact kernels are most of a new scene's
set-up time (see ``docs/developer.md``). A process that finds a form being compiled by
another (parallel tests, two notebooks) waits for it, ``timeout`` seconds, long enough for
the largest contact kernels.

Change :data:`JIT_OPTIONS` before a problem is built to compile otherwise; it takes
precedence over DOLFINx's ``dolfinx_jit_options.json`` for the options it names.
"""

from __future__ import annotations

import dolfinx
import numpy as np

#: The DOLFINx JIT options of every form and expression the package compiles.
JIT_OPTIONS: dict = {"cffi_extra_compile_args": ["-O1", "-g0"], "timeout": 300}


def form(forms, **kwargs) -> dolfinx.fem.Form:
    """:func:`dolfinx.fem.form` with :data:`JIT_OPTIONS` (nested lists of forms too)."""
    return dolfinx.fem.form(forms, jit_options=JIT_OPTIONS, **kwargs)


def expression(expr, points: np.ndarray, **kwargs) -> dolfinx.fem.Expression:
    """:class:`dolfinx.fem.Expression` with :data:`JIT_OPTIONS`."""
    return dolfinx.fem.Expression(expr, points, jit_options=JIT_OPTIONS, **kwargs)
