"""How the package's forms are compiled: FFCx writes C, the C compiler builds it.

DOLFINx builds every kernel with ``-O2``. The package's kernels run as fast built with
``-O1``, which compiles faster: the large 3D contact kernels are most of a new scene's
set-up time (see ``docs/developer.md``). A process that finds a form being compiled by
another (parallel tests, two notebooks) waits for it, ``timeout`` seconds, long enough for
the largest contact kernels.

A form compiled once in a process is kept, by its UFL signature, and the next form of the
same signature (the same problem on another mesh: a new scene, a level of adaptive
refinement) is made from it with :func:`dolfinx.fem.create_form` instead of looking it up
in the disk cache of FFCx again. Each rank compiles (or finds in the disk cache) on its
own, so that ranks whose memos differ do not wait for each other.

Change :data:`JIT_OPTIONS` before a problem is built to compile otherwise; it takes
precedence over DOLFINx's ``dolfinx_jit_options.json`` for the options it names.
"""

from __future__ import annotations

import dolfinx
import numpy as np
import ufl
from dolfinx.fem import IntegralType
from dolfinx.fem.forms import CompiledForm, get_integration_domains
from mpi4py import MPI

#: The DOLFINx JIT options of every form and expression the package compiles.
JIT_OPTIONS: dict = {"cffi_extra_compile_args": ["-O1", "-g0"], "timeout": 300}

#: the code of the forms compiled in this process (the compiled form, its module, its C
#: code and scalar type; not the UFL form, which would keep its mesh), by signature and
#: options
_COMPILED: dict[tuple[str, str], tuple] = {}

_INTEGRAL_TYPES = {t.name: t for t in IntegralType}


def form(forms, entity_maps=None, **kwargs):
    """:func:`dolfinx.fem.form` with :data:`JIT_OPTIONS` (nested lists of forms too), a form
    compiled before in this process made from its compiled code."""
    if isinstance(forms, list | tuple):
        return [form(f, entity_maps, **kwargs) for f in forms]
    mesh = _integration_mesh(forms) if not kwargs else None
    if mesh is None:
        return dolfinx.fem.form(forms, jit_options=JIT_OPTIONS, entity_maps=entity_maps, **kwargs)
    key = (forms.signature(), repr(sorted(JIT_OPTIONS.items())))
    code = _COMPILED.get(key)
    if code is None:  # on this rank alone: the memo's hits may differ between ranks
        compiled = dolfinx.fem.compile_form(MPI.COMM_SELF, forms, jit_options=JIT_OPTIONS)
        code = _COMPILED[key] = (compiled.ufcx_form, compiled.module, compiled.code, compiled.dtype)
    return _create(CompiledForm(forms, *code), mesh, entity_maps)


def _integration_mesh(a) -> dolfinx.mesh.Mesh | None:
    """The DOLFINx mesh ``a`` integrates over, found among its arguments' and coefficients'
    spaces (``None``: not a form with integrals, or no such space: left to DOLFINx)."""
    if not isinstance(a, ufl.Form) or a.empty():
        return None
    data = a.subdomain_data()
    if len(data) != 1:
        return None
    (domain,) = data
    for tags in data[domain].values():  # one subdomain data an integral type, as DOLFINx asks
        if any(t is not tags[0] for t in tags if t is not None):
            return None
    cpp = domain.ufl_cargo()
    spaces = [v.ufl_function_space() for v in a.arguments()]
    spaces += [c.function_space for c in a.coefficients() if hasattr(c, "function_space")]
    for space in spaces:
        if space.mesh._cpp_object is cpp:
            return space.mesh
    return None


def _create(compiled: CompiledForm, mesh, entity_maps) -> dolfinx.fem.Form:
    """The form of ``compiled`` (its UFL form with the code compiled for a form of the same
    signature, whose coefficients and constants the signature numbers in the same order)."""
    a, ufcx = compiled.ufl_form, compiled.ufcx_form
    coefficients = {c: c for c in a.coefficients()}
    constants = {c: c for c in a.constants()}
    (data,) = a.subdomain_data().values()
    offsets = [ufcx.form_integral_offsets[i] for i in range(len(IntegralType) + 1)]
    subdomains = {}
    for name, tags in data.items():
        kind = _INTEGRAL_TYPES[name]
        first, last = offsets[kind.value], offsets[kind.value + 1]
        ids = [ufcx.form_integral_ids[j] for j in range(first, last)]
        subdomains[kind] = get_integration_domains(kind, tags[0], ids)
    spaces = [v.ufl_function_space() for v in a.arguments()]
    return dolfinx.fem.create_form(
        compiled, spaces, mesh, subdomains, coefficients, constants, entity_maps
    )


def expression(expr, points: np.ndarray, **kwargs) -> dolfinx.fem.Expression:
    """:class:`dolfinx.fem.Expression` with :data:`JIT_OPTIONS`."""
    return dolfinx.fem.Expression(expr, points, jit_options=JIT_OPTIONS, **kwargs)
