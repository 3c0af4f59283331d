"""The report's building blocks: the formats of a cell (a value of a record to its text,
``-`` where there is none), the columns, tables, figures and sections of the page, and the
record helpers that several sections share.
"""

import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path


def _missing(x) -> bool:
    return x is None or (isinstance(x, float) and math.isnan(x))


def percent(x, digits: int = 2) -> str:
    """A relative error as a signed percentage: ``+0.23%``."""
    return "-" if _missing(x) else f"{100.0 * x:+.{digits}f}%"


def significant(x, n: int = 3) -> str:
    """``n`` significant digits, trailing zeros kept, without an exponent down to 1e-4:
    ``0.0120``, ``12.0``, ``1,230``."""
    if _missing(x):
        return "-"
    if x == 0:
        return "0"
    rounded = float(f"{x:.{n}g}")
    if abs(rounded) >= 10 ** (n - 1):
        return f"{rounded:,.0f}"
    if abs(rounded) < 1e-4:
        return scientific(x, n - 1)
    return f"{rounded:#.{n}g}"


def scientific(x, digits: int = 2) -> str:
    """``x`` as ``1.24e6``."""
    if _missing(x):
        return "-"
    if x == 0:
        return "0"
    mantissa, exponent = f"{x:.{digits}e}".split("e")
    return f"{mantissa}e{int(exponent)}"


def integer(x) -> str:
    """An integer with thousands separators: ``12,516``."""
    return "-" if _missing(x) else f"{int(x):,}"


def fixed(digits: int) -> Callable:
    """A number with ``digits`` decimals."""
    return lambda x: "-" if _missing(x) else f"{x:.{digits}f}"


def general(x) -> str:
    """Python's shortest form of a number (mesh sizes: ``0.0035``), or the text of a value."""
    if _missing(x):
        return "-"
    return f"{x:g}" if isinstance(x, float) else str(x)


def milliseconds(x) -> str:
    """Seconds as milliseconds, three significant digits."""
    return "-" if _missing(x) else significant(1e3 * x)


def share(x) -> str:
    """A fraction as a whole percentage: ``64%``."""
    return "-" if _missing(x) else f"{100.0 * x:.0f}%"


def speedup(x) -> str:
    """A ratio of times as ``1.57x``."""
    return "-" if _missing(x) else f"{x:.2f}x"


@dataclass(frozen=True)
class Column:
    """A column: its ``header``, the record's value (a key, or a function of the record)
    and the format of a cell."""

    header: str
    value: str | Callable[[dict], object]
    format: Callable[[object], str] = general

    def cell(self, record: dict) -> str:
        value = record.get(self.value) if isinstance(self.value, str) else self.value(record)
        return self.format(value)


def _records(results) -> list[dict]:
    """The records of a results file: the list itself, or its ``records`` or ``cases``."""
    if isinstance(results, list):
        return results
    return results.get("records", results.get("cases", []))


@dataclass(frozen=True)
class Table:
    """A table of the records of ``files`` (in order): ``rows`` makes the rows of one
    file's results (default: its records), ``where`` keeps some of them."""

    caption: str
    files: tuple[str, ...]
    columns: tuple[Column, ...]
    rows: Callable[[object], list[dict]] = _records
    where: Callable[[dict], bool] | None = None

    def table_rows(self, results: dict[str, object]) -> list[dict]:
        rows = [r for name in self.files for r in self.rows(results[name])]
        return [r for r in rows if self.where is None or self.where(r)]


@dataclass(frozen=True)
class Figure:
    """A figure of the records of ``files``, drawn by ``draw(results, path)``."""

    name: str
    caption: str
    alt: str
    files: tuple[str, ...]
    draw: Callable[[dict[str, object], Path], None]


@dataclass(frozen=True)
class Section:
    """A benchmark: what it measures (``text``, Markdown), how to run it (``usage``: the
    script's command line), its figures and tables."""

    title: str
    text: str
    usage: str
    tables: tuple[Table, ...]
    figures: tuple[Figure, ...] = ()


def _eps_label(record: dict) -> str:
    """The eps of a Hertz or Newton-cost record: ``E / L`` (the package's default) or
    ``E / h`` (the scenes', also where the record predates the choice)."""
    return "E / L" if record.get("eps") == "default" else "E / h"


def _newton_max_mean(record: dict) -> str:
    if "newton_max" not in record:
        return "-"
    return f"{record['newton_max']}/{record['newton_mean']:.1f}"


def _range(values: Iterable[int]) -> str:
    values = list(values)
    return f"{min(values)}-{max(values)}" if values else "-"


def _is_field_split(record: dict) -> bool:
    options = record.get("options") or record.get("petsc_options") or {}
    return isinstance(options, dict) and options.get("pc_type") == "fieldsplit"
