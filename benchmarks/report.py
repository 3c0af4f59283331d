"""The benchmark report: ``docs/benchmarks.md`` generated from ``benchmarks/results/*.json``.

Every results file (written by :func:`resultfile.write`, see ``benchmarks/resultfile.py``)
belongs to one table of :data:`SECTIONS`; a table lists the key columns of its files'
records and, under it, each file's stamp (commit, date, machine, ranks) and the command that
makes it again. A results file that no table names, or a table's file that is missing or
has no stamp, is an error: the page always shows every result there is, and only those.

    python benchmarks/report.py            # docs/benchmarks.md and its figures
    python benchmarks/report.py --check    # exit 1 if docs/benchmarks.md is not up to date

The page depends on nothing but the results files (no date or machine of the report's own
run), so running it again on unchanged results gives the same page. The figures (PNG,
matplotlib's Agg backend) go to ``docs/benchmarks/``.
"""

import argparse
import sys
from collections.abc import Iterable
from pathlib import Path

import resultfile
from report_sections import COMMANDS, SECTIONS
from report_sections.tables import Column

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "benchmarks" / "results"
PAGE = ROOT / "docs" / "benchmarks.md"
#: the figures' folder, and its path as the page refers to it
FIGURES = ROOT / "docs" / "benchmarks"
FIGURES_LINK = "benchmarks"


def describe_machine(machine) -> str:
    """The machine of a stamp in words (what was recorded of it)."""
    if not isinstance(machine, dict):
        return str(machine)
    known = {k: v for k, v in machine.items() if v != resultfile.UNRECORDED}
    parts = []
    if "cpu" in known:
        parts.append(str(known["cpu"]))
    if "cores" in known:
        parts.append(f"{known['cores']} cores")
    if "memory_GB" in known:
        parts.append(f"{known['memory_GB']} GB")
    if "platform" in known:
        parts.append(str(known["platform"]))
    names = {"cpu": "CPU", "memory_GB": "memory", "platform": "platform"}
    missing = [names[k] for k in names if k not in known]
    if missing:
        listed = ", ".join(missing[:-1]) + " and " + missing[-1] if len(missing) > 1 else missing[0]
        parts.append(f"{listed} not recorded")
    return ", ".join(parts)


def describe_stamp(name: str, stamp: dict) -> str:
    """One line of a table's stamps: the file, commit, date, machine, ranks, versions, and
    the command that makes it again."""
    commit = str(stamp["commit"])
    text = f"`{name}`: commit `{commit[:7]}`" if commit != resultfile.UNRECORDED else f"`{name}`"
    if stamp.get("dirty") is True:
        text += " with local changes"
    date = str(stamp["date"])
    text += f", {date[:10]} {date[11:16]} UTC" if len(date) >= 16 else f", {date}"
    text += f"; {describe_machine(stamp['machine'])}"
    ranks = stamp["ranks"]
    if isinstance(ranks, list):
        text += f"; {' and '.join(map(str, ranks))} ranks"
    elif ranks == resultfile.UNRECORDED:
        text += "; ranks not recorded"
    else:
        text += f"; {ranks} rank{'s' if ranks != 1 else ''}"
    versions = stamp.get("versions")
    if isinstance(versions, dict):
        labels = {
            "dolfinx": "DOLFINx",
            "petsc4py": "petsc4py",
            "numpy": "NumPy",
            "python": "Python",
        }
        text += "; " + ", ".join(f"{labels.get(k, k)} {v}" for k, v in versions.items())
    if stamp.get("stamp_source") == "git history":
        text += "; stamp rebuilt from the repository's history"
    command = stamp.get("command")
    if not command or command == resultfile.UNRECORDED:
        command = COMMANDS[name].format(path=f"benchmarks/results/{name}")
    return text + f". Made by `{command}`."


def markdown_table(columns: tuple[Column, ...], rows: list[dict]) -> list[str]:
    """A Markdown table: a header row and a row per record."""

    def line(cells: Iterable[str]) -> str:
        return "| " + " | ".join(c.replace("|", "\\|") for c in cells) + " |"

    lines = [line(c.header for c in columns), "|" + "---|" * len(columns)]
    lines += [line(c.cell(r) for c in columns) for r in rows]
    return lines


def files_named() -> list[str]:
    """Every results file the sections name."""
    names = {n for s in SECTIONS for t in s.tables for n in t.files}
    return sorted(names | {n for s in SECTIONS for f in s.figures for n in f.files})


def read_results(folder: Path = RESULTS) -> tuple[dict[str, dict], dict[str, object]]:
    """The stamps and the results of the results files of ``folder``.

    Parameters
    ----------
    folder
        The results files' folder.

    Returns
    -------
    tuple[dict[str, dict], dict[str, object]]
        The stamps and the results, by file name.

    Raises
    ------
    ValueError
        If a file has no stamp, or the sections name a file that is not in ``folder`` or
        leave one of its files out.
    """
    present = sorted(p.name for p in folder.glob("*.json"))
    named = files_named()
    problems = []
    if missing := sorted(set(named) - set(present)):
        problems.append(f"named in the report but not in {folder}: {', '.join(missing)}")
    if unused := sorted(set(present) - set(named)):
        problems.append(f"in {folder} but in no table of the report: {', '.join(unused)}")
    stamps, results = {}, {}
    for name in sorted(set(present) & set(named)):
        stamp, content = resultfile.read(folder / name)
        if stamp is None or any(field not in stamp for field in resultfile.FIELDS):
            problems.append(f"{name} has no stamp (write it with resultfile.write)")
            continue
        stamps[name], results[name] = stamp, content
    if problems:
        raise ValueError("; ".join(problems))
    return stamps, results


def render(folder: Path = RESULTS) -> str:
    """The report page (MyST Markdown) of the results files of ``folder``.

    Parameters
    ----------
    folder
        The results files' folder.

    Returns
    -------
    str
        The page: a section per benchmark of :data:`SECTIONS`, each with its usage, figures
        and tables, every table followed by its files' stamps.
    """
    stamps, results = read_results(folder)
    out = [
        "---",
        "orphan: true",  # builds with or without an entry in a toctree
        "---",
        "",
        "% Generated by benchmarks/report.py from benchmarks/results/*.json: do not edit;",
        "% run `make benchmark-report` after a benchmark has written its file.",
        "",
        "# Benchmarks",
        "",
        "The scripts in `benchmarks/` measure the accuracy and the cost of the contact "
        "formulation: errors against closed-form solutions and published results, Newton "
        "iterations, and where the time goes. Each writes its records to a JSON file in "
        "`benchmarks/results/` with a stamp: the commit of the code, the date, the machine, "
        "the number of MPI ranks, the command line and the versions of DOLFINx, petsc4py and "
        "NumPy. This page is generated from those files (`make benchmark-report`, that is "
        "`python benchmarks/report.py`); under each table are its files' stamps and the "
        "command that makes each file again.",
        "",
        "Times depend on the machine and its load. The files whose stamp is *rebuilt from "
        "the repository's history* were measured before the stamp existed, on a shared "
        "2-core machine: their commit is the one that last wrote the file (the run used its "
        "code or the working tree just before it), and their CPU model, memory and software "
        "versions were not recorded. Where a record has the machine's load average, it is in "
        "the *load* column. Errors are relative: +1.00% is 1% above the reference.",
    ]
    for section in SECTIONS:
        out += ["", f"## {section.title}", "", section.text, "", "```console"]
        out += [f"$ {line}" for line in section.usage.split("\n")]
        out += ["```"]
        for figure in section.figures:
            out += [
                "",
                f"```{{figure}} {FIGURES_LINK}/{figure.name}",
                f":alt: {figure.alt}",
                ":width: 100%",
                "",
                figure.caption,
                "```",
            ]
        for table in section.tables:
            out += [
                "",
                f"### {table.caption}" if len(section.tables) > 1 else f"**{table.caption}**",
                "",
            ]
            out += markdown_table(table.columns, table.table_rows(results))
            out += [""]
            out += [f"- {describe_stamp(name, stamps[name])}" for name in table.files]
    return "\n".join(out) + "\n"


def write_figures(folder: Path = RESULTS, figures: Path = FIGURES) -> list[Path]:
    """Draw the figures of :data:`SECTIONS` from the results files of ``folder``.

    Parameters
    ----------
    folder
        The results files' folder.
    figures
        The folder the PNG files go to (made if missing).

    Returns
    -------
    list[Path]
        The files written.
    """
    _, results = read_results(folder)
    figures.mkdir(parents=True, exist_ok=True)
    paths = []
    for section in SECTIONS:
        for figure in section.figures:
            path = figures / figure.name
            figure.draw(results, path)
            paths.append(path)
    return paths


def main(argv: list[str] | None = None) -> int:
    """Write the page and its figures, or with ``--check`` compare the page; the exit
    status."""
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--results", type=Path, default=RESULTS, help="the results files")
    parser.add_argument("--output", type=Path, default=PAGE, help="the page")
    parser.add_argument("--figures", type=Path, default=FIGURES, help="the figures' folder")
    parser.add_argument("--no-figures", action="store_true", help="write the page only")
    parser.add_argument(
        "--check", action="store_true", help="exit 1 if the page differs from the results'"
    )
    args = parser.parse_args(argv)
    page = render(args.results)
    if args.check:
        if not args.output.exists() or args.output.read_text() != page:
            print(f"{args.output} is not the report of {args.results}: run benchmarks/report.py")
            return 1
        return 0
    args.output.write_text(page)
    print(f"wrote {args.output}")
    if not args.no_figures:
        for path in write_figures(args.results, args.figures):
            print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
