"""The verification report: ``docs/verification.md`` generated from the tests' own records.

A test records a checked quantity with the ``verification`` fixture of ``tests/conftest.py``
(a user property, which ``pytest --junitxml=FILE`` writes into the test's ``testcase``
element). This script runs nothing: it reads such a JUnit XML file, keeps its records with
the outcome of their tests in ``docs/verification.json`` (committed, so that the page can
be made again and checked without running the suite), and writes the page from that file.

    python tests/verification_report.py --from-junit build/verification.xml   # JSON + page
    python tests/verification_report.py                                       # page from JSON
    python tests/verification_report.py --check    # exit 1 if the page is not the JSON's

The page depends on nothing but the records (no date or machine of the run), sorted, so
the same records give the same page.
"""

import argparse
import json
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "docs" / "verification.json"
PAGE = ROOT / "docs" / "verification.md"
#: the name of the user property that carries a record
PROPERTY = "verification"
#: the kinds of a record, in the page's order, with what each means
KINDS = {
    "verification": "against something nobody here wrote: a closed form, a published value, "
    "another solver, the slope of a Taylor remainder",
    "consistency": "holds by construction, whatever the solution: the equilibrium of a "
    "converged solve, action equals reaction",
    "regression": "against a snapshot of the code's own earlier output",
}
#: the fields of a record (``outcome`` from the JUnit XML, the others from the test)
FIELDS = (
    "case",
    "quantity",
    "measured",
    "reference",
    "tolerance",
    "source",
    "kind",
    "nodeid",
    "outcome",
)
OUTCOMES = ("passed", "failed", "error", "skipped")
COMMAND = "make verification-report"


def _outcome(testcase: ET.Element) -> str:
    """The outcome of a JUnit ``testcase``: failed, error, skipped or passed."""
    for tag in ("failure", "error", "skipped"):
        if testcase.find(tag) is not None:
            return {"failure": "failed"}.get(tag, tag)
    return "passed"


def sort_key(record: dict) -> tuple:
    """Kind (in the order of :data:`KINDS`), case, quantity, test."""
    text = (record["case"].casefold(), record["quantity"].casefold(), record["nodeid"])
    return (list(KINDS).index(record["kind"]), *text)


def read_junit(path: Path) -> list[dict]:
    """The records of a JUnit XML file of pytest, each with its test's outcome, sorted.

    Parameters
    ----------
    path
        The file of ``pytest --junitxml``.

    Returns
    -------
    list[dict]
        One dictionary per record, with the keys :data:`FIELDS`.
    """
    records = []
    for testcase in ET.parse(path).getroot().iter("testcase"):
        outcome = _outcome(testcase)
        for prop in testcase.iter("property"):
            if prop.get("name") == PROPERTY:
                records.append({**json.loads(prop.get("value")), "outcome": outcome})
    for record in records:
        check(record)
    return sorted(records, key=sort_key)


def check(record: dict) -> None:
    """Raise ``ValueError`` unless ``record`` has exactly the :data:`FIELDS`, a known kind
    and outcome."""
    if sorted(record) != sorted(FIELDS):
        raise ValueError(f"a record has the fields {sorted(record)}, not {sorted(FIELDS)}")
    if record["kind"] not in KINDS:
        raise ValueError(f"{record['nodeid']}: unknown kind {record['kind']!r}")
    if record["outcome"] not in OUTCOMES:
        raise ValueError(f"{record['nodeid']}: unknown outcome {record['outcome']!r}")


def load(path: Path = DATA) -> list[dict]:
    """The records of a JSON file written by :func:`save`, checked and sorted."""
    records = json.loads(path.read_text())["records"]
    for record in records:
        check(record)
    return sorted(records, key=sort_key)


def save(records: list[dict], path: Path = DATA) -> None:
    """Write ``records`` (sorted) to the JSON file ``path``."""
    records = sorted(records, key=sort_key)
    path.write_text(json.dumps({"records": records}, indent=1, sort_keys=True) + "\n")


# -- the page ------------------------------------------------------------------------------------
def number(x) -> str:
    """Four significant digits (six from 0.5 to 10, where slopes and ratios near one are),
    with an exponent below 1e-3 and from 1e4: ``0.01234``, ``2.00005``, ``3.2e-16``."""
    if x == 0:
        return "0"
    if abs(x) < 1e-3 or abs(x) >= 1e4:
        mantissa, exponent = f"{x:.1e}".split("e")
        return f"{mantissa}e{int(exponent)}"
    return f"{x:.6g}" if 0.5 <= abs(x) < 10 else f"{x:.4g}"


def value(x) -> str:
    """A measured value, reference or tolerance as the text of a cell."""
    if isinstance(x, str):
        return x
    if isinstance(x, list):
        return ", ".join(number(v) for v in x)
    return number(x)


def cell(text: str) -> str:
    """``text`` safe in a Markdown table cell (its pipes escaped)."""
    return text.replace("|", "\\|").replace("\n", " ")


def recording_files(records: list[dict]) -> list[str]:
    """The test files that have records, sorted."""
    return sorted({r["nodeid"].split("::")[0] for r in records})


RESULT = {"passed": "pass", "failed": "**FAIL**", "error": "**ERROR**", "skipped": "skipped"}
HEADER = ("case", "quantity", "reference; source", "tolerance", "measured", "test", "result")


def table(records: list[dict]) -> list[str]:
    """The Markdown table of ``records``, one row each."""
    lines = ["| " + " | ".join(HEADER) + " |", "|" + "---|" * len(HEADER)]
    for r in records:
        row = (
            r["case"],
            r["quantity"],
            f"{value(r['reference'])}; {r['source']}",
            value(r["tolerance"]),
            value(r["measured"]),
            f"`{r['nodeid']}`",
            RESULT[r["outcome"]],
        )
        lines.append("| " + " | ".join(cell(c) for c in row) + " |")
    return lines


TITLES = {
    "verification": "Verification",
    "consistency": "Consistency checks",
    "regression": "Regression checks",
}


def render(records: list[dict]) -> str:
    """The page of ``records``.

    Parameters
    ----------
    records
        Records with the keys :data:`FIELDS` (as :func:`load` returns them).

    Returns
    -------
    str
        The Markdown (MyST) text of ``docs/verification.md``.
    """
    records = sorted(records, key=sort_key)
    files = recording_files(records)
    counts = {k: sum(r["kind"] == k for r in records) for k in KINDS}
    out = [
        "% Generated by tests/verification_report.py from docs/verification.json: do not edit;",
        f"% run `{COMMAND}` to run the tests again and remake both.",
        "",
        "# Verification",
        "",
        "This page is generated from the test suite's own records, not typed: a test that "
        "compares a computed quantity with a reference records the value it asserts on, the "
        "tolerance it enforces and where the reference comes from (the `verification` fixture "
        "of `tests/conftest.py`), pytest writes the records into its JUnit XML file, and "
        "`tests/verification_report.py` makes this page of them. The records are kept in "
        "`docs/verification.json`; a test checks that this page is made from that file. "
        f"To run the tests again and remake both: `{COMMAND}`, that is",
        "",
        "```console",
        "$ python -m pytest -q -p no:cacheprovider -n 2 --dist loadfile "
        "--junitxml=build/verification.xml tests",
        "$ python tests/verification_report.py --from-junit build/verification.xml",
        "```",
        "",
        "```{note}",
        f"Every test file that checks a computed quantity records ({len(files)} files): "
        + ", ".join(f"`{f}`" for f in files)
        + ". The files that check the tools (the demos and notebooks run, the docs build, "
        "the benchmark report) do not. The page is made from a run of the default suite on "
        "one rank: the slow tier (`make test-all`) and the comparisons of 2 ranks with one "
        "(run by `make test`'s 2-rank half) are not in it.",
        "```",
        "",
        "The checks are of three kinds, listed apart: "
        + "; ".join(f"*{k}*, {KINDS[k]}" for k in KINDS)
        + ". Only the first compares the code with something outside it. *result* is the "
        "outcome of the test in the run that made the records (a test can assert more than "
        "it records). Relative errors are fractions: 0.01 is 1%.",
        "",
        "| kind | records |",
        "|---|---|",
        *(f"| {k} | {counts[k]} |" for k in KINDS),
    ]
    for kind in KINDS:
        rows = [r for r in records if r["kind"] == kind]
        out += ["", f"## {TITLES[kind]}", "", f"{KINDS[kind][0].upper()}{KINDS[kind][1:]}.", ""]
        out += table(rows) if rows else ["No records of this kind yet."]
    return "\n".join(out) + "\n"


def main(argv: list[str] | None = None) -> int:
    """Write the JSON and the page, the page alone, or with ``--check`` compare the page;
    the exit status."""
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument(
        "--from-junit", type=Path, metavar="FILE", help="read the records from this JUnit XML"
    )
    parser.add_argument("--data", type=Path, default=DATA, help="the records' JSON file")
    parser.add_argument("--output", type=Path, default=PAGE, help="the page")
    parser.add_argument(
        "--check", action="store_true", help="exit 1 if the page is not the JSON file's"
    )
    args = parser.parse_args(argv)
    if args.from_junit is not None:
        if args.check:
            parser.error("--check compares the page with the JSON file: no --from-junit")
        records = read_junit(args.from_junit)
        if not records:
            print(f"{args.from_junit} has no verification records")
            return 1
        save(records, args.data)
        print(f"wrote {args.data} ({len(records)} records)")
    page = render(load(args.data))
    if args.check:
        if not args.output.exists() or args.output.read_text() != page:
            print(f"{args.output} is not the page of {args.data}: run tests/verification_report.py")
            return 1
        return 0
    args.output.write_text(page)
    print(f"wrote {args.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
