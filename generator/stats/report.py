"""The parts of a statistics report: tables (Markdown + CSV), figures (PNG), sections.

A statistics module (one per kind of data: images, LiDAR points, boxes) turns what it reads
into a :class:`Section`; :func:`write_report` writes every section of a dataset into one
Markdown file plus one CSV per table and one PNG per figure, atomically, after everything
has been computed (so a failure leaves nothing half-written).
"""

from __future__ import annotations

import csv
import io
from dataclasses import dataclass, field
from pathlib import Path

from generator.atomic import write_bytes, write_text

Cell = str | int | float


@dataclass(frozen=True)
class Table:
    """One table of the report.

    Attributes
    ----------
    stem : str
        File stem of its CSV (``table1_pixels`` -> ``table1_pixels.csv``).
    title : str
        Heading in the Markdown report.
    columns : list of str
        Markdown column headings.
    csv_columns : list of str
        CSV header (machine-friendly names), one per column.
    rows : list of list
        Cells (str, int or float); ints are printed with thousands separators in Markdown.
    notes : list of str
        Lines printed under the Markdown table.
    csv_rows : list of list, optional
        Rows for the CSV when they differ from the Markdown ones (e.g. ids instead of titles).
    """

    stem: str
    title: str
    columns: list[str]
    csv_columns: list[str]
    rows: list[list[Cell]]
    notes: list[str] = field(default_factory=list)
    csv_rows: list[list[Cell]] | None = None

    def to_csv(self) -> str:
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        w.writerow(self.csv_columns)
        w.writerows(self.rows if self.csv_rows is None else self.csv_rows)
        return buf.getvalue()

    def to_markdown(self) -> str:
        def cell(v: Cell) -> str:
            if isinstance(v, bool):
                return "yes" if v else "no"
            if isinstance(v, int):
                return f"{v:,}"
            if isinstance(v, float):
                return f"{v:,.0f}"
            return str(v)

        right = [all(isinstance(r[i], (int, float)) and not isinstance(r[i], bool) for r in self.rows)
                 for i in range(len(self.columns))]
        lines = ["| " + " | ".join(self.columns) + " |",
                 "|" + "|".join("---:" if r else "---" for r in right) + "|"]
        lines += ["| " + " | ".join(cell(v) for v in row) + " |" for row in self.rows]
        return "\n".join(lines) + ("\n\n" + "\n".join(self.notes) if self.notes else "") + "\n"


@dataclass(frozen=True)
class Figure:
    """A PNG of the report: file name, caption and the encoded image."""

    filename: str
    caption: str
    png: bytes


@dataclass
class Section:
    """What one statistics module reports: summary lines, tables and figures."""

    title: str
    summary: list[str]
    tables: list[Table]
    figures: list[Figure] = field(default_factory=list)


def markdown(dataset: Path, sections: list[Section]) -> str:
    """The whole report as Markdown (figures linked by file name)."""
    out = [f"# Dataset statistics: `{dataset.name or dataset}`", ""]
    for s in sections:
        out += [f"## {s.title}", ""]
        out += [f"- {line}" for line in s.summary] + [""]
        for t in s.tables:
            out += [f"### {t.title}", "", t.to_markdown(), f"CSV: `{t.stem}.csv`", ""]
        for f in s.figures:
            out += [f"![{f.caption}]({f.filename})", "", f"*{f.caption}*", ""]
    return "\n".join(out).rstrip() + "\n"


def report_files(dataset: Path, sections: list[Section]) -> dict[str, bytes]:
    """File name -> content of every file of the report (``stats.md``, CSVs, PNGs)."""
    files = {"stats.md": markdown(dataset, sections).encode("utf-8")}
    for s in sections:
        files.update({f"{t.stem}.csv": t.to_csv().encode("utf-8") for t in s.tables})
        files.update({f.filename: f.png for f in s.figures})
    return files


def write_report(out: Path, dataset: Path, sections: list[Section]) -> list[Path]:
    """Write the report into ``out`` (created if missing); returns the paths written."""
    files = report_files(dataset, sections)
    paths = []
    for name, data in files.items():
        p = out / name
        if name.endswith((".md", ".csv")):
            write_text(p, data.decode("utf-8"))
        else:
            write_bytes(p, data)
        paths.append(p)
    return paths
