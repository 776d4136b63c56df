"""A benchmark's result table, written with the command and the date it was measured.

`write_table` writes `STEM.csv` (the rows), `STEM.md` (the Markdown table, then the line
"Measured DATE with `COMMAND`.") and `STEM.json` (the command, the date, the machine and the
rows). The documentation includes the `.md` files of `benchmarks/results/`, so a table on a
page is the one its script wrote. Nothing here imports matplotlib: timing scripts use it too.
"""

from __future__ import annotations

import os
import platform
import shlex
import sys
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass
from datetime import UTC, datetime
from pathlib import Path

from vplane_mj.files import write_atomically, write_csv, write_json

CPU_INFO = Path("/proc/cpuinfo")


@dataclass(frozen=True)
class Measurement:
    """How and when a table was measured: `command` as typed at the repository's root
    (`python benchmarks/NAME.py ARGS`), `date` in UTC (ISO 8601) and, when known, `machine`
    (its CPUs)."""

    command: str
    date: str
    machine: str | None = None

    def line(self) -> str:
        """The sentence under the table: "Measured DATE with `COMMAND` on MACHINE."."""
        where = f" on {self.machine}" if self.machine else ""
        return f"Measured {self.date[:10]} with `{self.command}`{where}."


def benchmark_command(argv: Sequence[str]) -> str:
    """`argv` of a benchmark script as the shell command that runs it from the repository's root."""
    return shlex.join(["python", f"benchmarks/{Path(argv[0]).name}", *argv[1:]])


def cpu_model() -> str | None:
    """The CPU's model name as the system reports it, None if it does not."""
    if CPU_INFO.is_file():
        for line in CPU_INFO.read_text(encoding="utf-8", errors="replace").splitlines():
            key, _, value = line.partition(":")
            if key.strip() == "model name" and value.strip():
                return value.strip()
    return platform.processor() or None


def this_machine() -> str:
    """This machine's CPU count and model, e.g. "2 CPUs (AMD EPYC)"."""
    model = cpu_model()
    return f"{os.cpu_count()} CPUs" + (f" ({model})" if model else "")


def measured_now(argv: Sequence[str] | None = None) -> Measurement:
    """This process's benchmark command (`argv`, by default `sys.argv`), now, on this machine."""
    command = benchmark_command(sys.argv if argv is None else argv)
    return Measurement(command, datetime.now(UTC).isoformat(timespec="seconds"), this_machine())


def markdown_table(rows: list[dict], columns: Sequence[str], cell: Callable[[str, object], str]) -> str:
    """`rows` as a Markdown table of `columns`, each value written by `cell(column, value)` (a
    missing value is None)."""
    lines = ["| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    lines += ["| " + " | ".join(cell(key, row.get(key)) for key in columns) + " |" for row in rows]
    return "\n".join(lines)


def formatted(formats: dict[str, str]) -> Callable[[str, object], str]:
    """A cell writer for `markdown_table`: a value in its column's format spec (`formats`, e.g.
    ".3f"), None as "-", any other value as `format` writes it."""

    def cell(key: str, value: object) -> str:
        return "-" if value is None else format(value, formats.get(key, ""))

    return cell


def write_table(
    out_dir: Path,
    stem: str,
    table: list[dict],
    columns: Sequence[str],
    text: str,
    measurement: Measurement | None = None,
) -> list[Path]:
    """A benchmark's table in `out_dir`, each file written whole: `stem`.csv (`columns` of
    `table`), `stem`.md (the Markdown `text` and the measurement's line) and `stem`.json (the
    measurement and the rows). `measurement` is by default this process's, now. Their paths."""
    measurement = measurement or measured_now()
    page = f"{text}\n\n{measurement.line()}\n"
    sidecar = {
        "format": 1,
        **asdict(measurement),
        "columns": list(columns),
        "table": [{key: row.get(key) for key in columns} for row in table],
    }
    return [
        write_csv(out_dir / f"{stem}.csv", table, list(columns)),
        write_atomically(out_dir / f"{stem}.md", lambda tmp: tmp.write_text(page, encoding="utf-8")),
        write_json(out_dir / f"{stem}.json", sidecar),
    ]
