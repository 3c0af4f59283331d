"""The compiled kernel of the closest-point search (``search_kernel.c``), built on first use.

The C source is compiled by the system C compiler into a shared library and loaded with
:mod:`cffi` in its ABI mode (``ffi.dlopen``: no Python headers, no setuptools needed; FFCx
needs the same compiler and cffi, so every DOLFINx install has both). The library is cached in
``$CONTACT_UFL_CACHE_DIR`` (default ``$XDG_CACHE_HOME/contact_ufl``, else
``~/.cache/contact_ufl``) under a name keyed by a hash of the source, the declarations, the
compiler command and the platform: a changed source builds a new library, an unchanged one
is built once per machine and user. Several processes (MPI ranks) may build at once without
any collective call: each compiles into a file of its own and renames it atomically onto the
cached name (the last rename wins; every candidate is a complete library of the same source),
so no process ever loads a half-written file. A process that builds a library removes the
libraries of other source hashes (and leftover temporary files) last changed over a day ago
(:func:`remove_stale`; loading a library sets its time of change, so a library loaded within
the day is kept, and a process that finds its library removed between its check and its
load builds it again).

The compiler is ``$CC`` if set, else the one Python was built with, else ``cc``; the flags
``-O3 -fPIC -shared -ffp-contract=off -fno-fast-math`` (no fused multiply-add: the kernels
repeat the NumPy operations to the last bit).
"""

from __future__ import annotations

import hashlib
import os
import platform
import shlex
import shutil
import subprocess
import sysconfig
import tempfile
import threading
import time
from pathlib import Path

import cffi
from mpi4py import MPI

__all__ = ["CompilerNotFound", "cache_dir", "kernel", "remove_stale", "require"]

CDEF = """
typedef long long i64;
i64 bvh_build(int g, i64 n, const double *c, i64 *perm, i64 *a, i64 *b);
double bvh_refit(int g, int nn, i64 n, const double *nodes, const i64 *perm, i64 m,
                 const i64 *a, const i64 *b, void *tree, double *leaves, double *boxes,
                 double *change);
int bvh_record(int g, int nn);
int same_nodes(int g, int nn, i64 n, const double *nodes, const i64 *perm,
               const double *leaves);
int morton_order(int g, i64 n, const double *x, i64 *order);
i64 bvh_query(int kind, int g, int nn, const double *leaves, const i64 *perm, i64 m,
              const void *tree, double rmax, i64 npts, const double *x, double radius,
              const i64 *index, i64 *facet, double *oxi, double *y, double *normal,
              double *gap, double *distance, double *sliding, int mp, const i64 *pnodes,
              const double *pnormal, int mf, const i64 *fnodes, const double *axis);
"""

FLAGS = ("-O3", "-fPIC", "-shared", "-ffp-contract=off", "-fno-fast-math")
SOURCE = Path(__file__).with_name("search_kernel.c")
STALE_AGE = 86400.0  # seconds after which a kernel of another source hash is removed

_lock = threading.Lock()
_loaded: tuple[cffi.FFI, object] | None = None


class CompilerNotFound(RuntimeError):
    """No working C compiler to build the search kernel."""


def cache_dir() -> Path:
    """Where the built library is kept: ``$CONTACT_UFL_CACHE_DIR``, else
    ``$XDG_CACHE_HOME/contact_ufl``, else ``~/.cache/contact_ufl``."""
    if os.environ.get("CONTACT_UFL_CACHE_DIR"):
        return Path(os.environ["CONTACT_UFL_CACHE_DIR"])
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "contact_ufl"


def _compiler() -> list[str]:
    """The compiler command: ``$CC``, else Python's own ``CC``, else ``cc``."""
    command = os.environ.get("CC") or sysconfig.get_config_var("CC") or "cc"
    words = shlex.split(command)
    if not words or shutil.which(words[0]) is None:
        fallback = shutil.which("cc") or shutil.which("gcc") or shutil.which("clang")
        if fallback is None:
            raise CompilerNotFound(
                "the closest-point search needs a C compiler to build its kernel and found "
                f"none: neither {words[0] if words else '$CC'!r} nor cc, gcc or clang is on "
                "the PATH (install one, e.g. 'apt install gcc' or the conda package "
                "'c-compiler', as FFCx needs too, or set CC)"
            )
        words = [fallback]
    return words


def _build(library: Path, compiler: list[str]) -> None:
    """Compile the source into ``library`` (a private file, then an atomic rename)."""
    try:
        library.parent.mkdir(parents=True, exist_ok=True)
        fd, private = tempfile.mkstemp(prefix=library.stem + ".", suffix=".tmp", dir=library.parent)
    except OSError as error:
        raise OSError(
            f"cannot write the closest-point search kernel to {library.parent} ({error}); "
            "set CONTACT_UFL_CACHE_DIR to a writable directory"
        ) from error
    os.close(fd)
    try:
        command = [*compiler, *FLAGS, "-o", private, str(SOURCE), "-lm"]
        run = subprocess.run(command, capture_output=True, text=True, check=False)
        if run.returncode != 0:
            raise CompilerNotFound(
                f"building the closest-point search kernel failed ({shlex.join(command)}):\n"
                f"{run.stderr.strip()}"
            )
        os.replace(private, library)
    finally:
        if os.path.exists(private):
            os.unlink(private)


def remove_stale(library: Path, age: float = STALE_AGE) -> list[Path]:
    """Remove the kernels of other source hashes from ``library``'s directory, and the
    temporary files of builds, last changed over ``age`` seconds ago (a day by default: no
    process is still building or loading them), best effort: a file that cannot be removed
    (gone already, no permission) is left. Returns the files removed."""
    removed = []
    now = time.time()
    try:
        candidates = list(library.parent.glob("search_kernel_*"))
    except OSError:
        return removed
    for path in candidates:
        if path.name == library.name or not path.name.endswith((".so", ".tmp")):
            continue
        try:
            if now - path.stat().st_mtime > age:
                path.unlink()
                removed.append(path)
        except OSError:
            continue
    return removed


def kernel() -> tuple[cffi.FFI, object]:
    """The cffi interface and the loaded library of the search kernel (built if needed)."""
    global _loaded
    with _lock:
        if _loaded is None:
            compiler = _compiler()
            key = hashlib.sha256(
                "\0".join(
                    [
                        SOURCE.read_text(),
                        CDEF,
                        shlex.join([*compiler, *FLAGS]),
                        platform.machine(),
                        platform.system(),
                    ]
                ).encode()
            ).hexdigest()[:20]
            library = cache_dir() / f"search_kernel_{key}.so"
            if not library.exists():
                _build(library, compiler)
                remove_stale(library)
            ffi = cffi.FFI()
            ffi.cdef(CDEF)
            _loaded = (ffi, _open(ffi, library, compiler))
        return _loaded


def _open(ffi: cffi.FFI, library: Path, compiler: list[str]) -> object:
    """The loaded ``library``, its time of change set to now (a library in use is never
    stale: :func:`remove_stale`); built again if it was removed meanwhile."""
    try:
        os.utime(library)
    except OSError:  # a read-only cache: nothing is removed from it either
        pass
    try:
        return ffi.dlopen(str(library))
    except OSError:
        _build(library, compiler)
        return ffi.dlopen(str(library))


def require(comm: MPI.Comm) -> None:
    """Build or load the kernel on every rank of ``comm`` (collective): where any rank
    cannot (no C compiler, a failed build, an unwritable cache), raise its error on every
    rank, not on the ranks that search only (the others would wait in their next collective
    call). The error is :class:`CompilerNotFound`, or :class:`OSError` for the cache."""
    failure = None
    try:
        kernel()
    except CompilerNotFound as error:
        failure = ("compiler", str(error))
    except OSError as error:
        failure = ("cache", str(error))
    failures = [f for f in comm.allgather(failure) if f is not None]
    if failures:
        kind, message = failures[0]
        raise (CompilerNotFound if kind == "compiler" else OSError)(message)
