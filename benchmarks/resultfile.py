"""The results file of a benchmark: its records with a stamp of where they come from.

Every benchmark script writes its JSON file with :func:`write`. The file is one object::

    {"stamp": {...}, "results": <what the script recorded, unchanged>}

The stamp (:data:`FIELDS`):

``commit``, ``dirty``
    ``git rev-parse HEAD`` of the repository the script runs from, and whether a tracked
    file other than the results (``benchmarks/results/``) differs from that commit.
``date``
    When the file was written, UTC, ISO 8601 to the second.
``machine``
    The CPU model (``/proc/cpuinfo``), the number of cores, the memory and the platform:
    what the timings depend on, not the host's name.
``ranks``
    The number of MPI processes (a list where a script runs several counts itself).
``command``
    The command line (``mpirun -n k`` before it on k > 1 processes).
``versions``
    DOLFINx, petsc4py, NumPy and Python.
``stamp_source``
    ``"run"``: stamped by the run that wrote the file. Files older than the stamp carry one
    rebuilt from the repository's history, ``"git history"`` (the commit that last wrote
    the file and its date; what the history does not know is ``"unrecorded"``).

:func:`read` returns the stamp and the results of a file (no stamp for a file written
before stamps were introduced), :func:`load` the results alone.
"""

import importlib
import json
import os
import platform
import shlex
import subprocess
import sys
import tempfile
from datetime import UTC, datetime
from pathlib import Path

#: the members of a stamp
FIELDS = ("commit", "dirty", "date", "machine", "ranks", "command", "versions", "stamp_source")
#: the value of a stamp's field that was not recorded
UNRECORDED = "unrecorded"
#: the repository's root (this file is in its benchmarks/ folder)
ROOT = Path(__file__).resolve().parents[1]
#: paths whose changes do not make the working tree dirty for a stamp
RESULTS = ("benchmarks/results",)


def _git(*args: str) -> str | None:
    """The output of ``git args`` in :data:`ROOT`, stripped; ``None`` if git fails."""
    try:
        done = subprocess.run(
            ["git", *args], cwd=ROOT, capture_output=True, text=True, check=True, timeout=30
        )
    except (OSError, subprocess.SubprocessError):
        return None
    return done.stdout.strip()


def commit() -> tuple[str, bool | str]:
    """The commit checked out in :data:`ROOT` and whether a tracked file other than the
    results differs from it (:data:`UNRECORDED` for both outside a git repository)."""
    head = _git("rev-parse", "HEAD")
    if head is None:
        return UNRECORDED, UNRECORDED
    excluded = [f":(exclude){path}" for path in RESULTS]
    changes = _git("status", "--porcelain", "--untracked-files=no", "--", ".", *excluded)
    return head, UNRECORDED if changes is None else bool(changes)


def _proc_value(path: str, key: str) -> str | None:
    """The value of the first ``key: value`` line of ``path`` (``/proc`` files), if any."""
    try:
        with open(path) as f:
            for line in f:
                name, _, value = line.partition(":")
                if name.strip() == key:
                    return value.strip()
    except OSError:
        pass
    return None


def machine() -> dict:
    """The CPU model, cores, memory (GB) and platform of this machine (no host name)."""
    cpu = _proc_value("/proc/cpuinfo", "model name") or platform.processor() or UNRECORDED
    memory = _proc_value("/proc/meminfo", "MemTotal")  # "24683784 kB"
    return {
        "cpu": cpu,
        "cores": os.cpu_count() or UNRECORDED,
        "memory_GB": round(int(memory.split()[0]) / 1024**2, 1) if memory else UNRECORDED,
        "platform": platform.platform(),
    }


def versions() -> dict:
    """The versions of DOLFINx, petsc4py and NumPy (:data:`UNRECORDED` where one cannot
    be imported) and of Python."""
    found = {}
    for name in ("dolfinx", "petsc4py", "numpy"):
        try:
            if name == "dolfinx":
                importlib.import_module("contact_ufl")  # loads the MPI and PETSc libraries
            found[name] = str(importlib.import_module(name).__version__)
        except Exception:  # any failure to import: not recorded
            found[name] = UNRECORDED
    found["python"] = platform.python_version()
    return found


def mpi_size() -> int:
    """The number of processes of ``MPI.COMM_WORLD``."""
    from mpi4py import MPI

    return MPI.COMM_WORLD.size


def command(argv: list[str] | None = None) -> str:
    """The command line of this process (``argv``, default :data:`sys.argv`) as a shell
    command, the script's path relative to :data:`ROOT` where it lies under it."""
    argv = list(sys.argv if argv is None else argv)
    if argv:
        script = Path(argv[0]).resolve()
        if script.is_relative_to(ROOT):
            argv[0] = str(script.relative_to(ROOT))
    return shlex.join(["python", *argv])


def stamp(ranks: int | list[int] | None = None, argv: list[str] | None = None) -> dict:
    """A stamp of a run on this machine now (:data:`FIELDS`).

    Parameters
    ----------
    ranks
        The number of MPI processes; default that of ``MPI.COMM_WORLD``.
    argv
        The command line; default :data:`sys.argv`.

    Returns
    -------
    dict
        The stamp, ``stamp_source`` ``"run"``.
    """
    head, dirty = commit()
    ranks = mpi_size() if ranks is None else ranks
    line = command(argv)
    if isinstance(ranks, int) and ranks > 1:
        line = f"mpirun -n {ranks} {line}"
    return {
        "commit": head,
        "dirty": dirty,
        "date": datetime.now(UTC).replace(microsecond=0).isoformat().replace("+00:00", "Z"),
        "machine": machine(),
        "ranks": ranks,
        "command": line,
        "versions": versions(),
        "stamp_source": "run",
    }


def dump(path: str | Path, content: dict) -> None:
    """Write ``content`` as JSON to ``path`` atomically: into a temporary file in the same
    folder, then renamed over ``path`` (a reader sees the old file or the new one, never a
    part of either)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    handle, temporary = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(handle, "w") as f:
            json.dump(content, f, indent=1)
            f.write("\n")
            f.flush()
            os.fsync(f.fileno())
        os.chmod(temporary, 0o644)
        os.replace(temporary, path)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise


def write(
    path: str | Path, results, ranks: int | list[int] | None = None, argv: list[str] | None = None
) -> None:
    """Write a benchmark's ``results`` (anything JSON takes) to ``path`` with a
    :func:`stamp`, atomically (:func:`dump`). Call it on one rank.

    Parameters
    ----------
    path
        The results file.
    results
        The records, written unchanged under ``"results"``.
    ranks
        The number of MPI processes of the run; default that of ``MPI.COMM_WORLD``.
    argv
        The command line; default :data:`sys.argv`.
    """
    dump(path, {"stamp": stamp(ranks, argv), "results": results})


def read(path: str | Path) -> tuple[dict | None, object]:
    """The stamp and the results of a results file; the stamp ``None`` and the whole file
    as the results for a file without a stamp."""
    with open(path) as f:
        content = json.load(f)
    if isinstance(content, dict) and set(content) == {"stamp", "results"}:
        return content["stamp"], content["results"]
    return None, content


def load(path: str | Path):
    """The results of a results file (:func:`read` without the stamp)."""
    return read(path)[1]
