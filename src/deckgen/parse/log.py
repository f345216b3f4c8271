"""Streaming parser for LAMMPS log files (``log.lammps`` and ``-log`` files).

A small line-driven state machine, in the spirit of LAMMPS's own
``python/lammps/formats.py`` but written for deckgen:

``idle``
    ``Per MPI rank memory ...`` (older builds: ``Memory usage per processor``)
    starts a run -> ``header``.
``header``
    The next non-empty, non-WARNING line holds the thermo column names
    (``Step Time KinEng c_tbond ...``) -> ``thermo``.
``thermo``
    Lines whose first token is a number are thermo rows; each must carry one
    value per column.  ``WARNING`` lines are collected and the block goes on;
    ``ERROR`` ends it (aborted run); ``Loop time of ...`` ends it (completed
    run) -> ``idle``.  Other text lines (fix messages) are skipped.

Everywhere: ``ERROR``/``WARNING`` lines are collected with their line
numbers, ``Loop time of X on P procs for N steps with M atoms`` and the
``Performance:`` line after it are attached to the run, NaN/inf thermo
values are flagged.

A thermo line cut off at end of file (engine killed mid-write: no newline)
is dropped and reported as ``truncated``; a complete thermo row with the
wrong number of values raises :class:`~deckgen.parse.common.ParseError`
naming file and line.  ``thermo_style multi``/``yaml`` blocks are not
tabulated (noted in ``LogHealth.notes``).

Note for deck writers: ``fix print`` without ``screen no`` echoes its lines
into the log, inside thermo blocks; numeric ones then look like malformed
thermo rows.  Decks must write fix print output to a file with ``screen no``
(or parse with ``strict=False``).
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import NamedTuple

import pandas as pd

from .common import (
    Line,
    ParseError,
    PathLike,
    is_int_column,
    iter_lines,
    parse_number,
    unique_names,
)

__all__ = [
    "LogHealth",
    "LogMessage",
    "LogResult",
    "RunInfo",
    "ThermoRow",
    "check_log",
    "iter_thermo_rows",
    "read_log",
    "read_thermo",
]

_RUN_START = ("Per MPI rank memory", "Memory usage per processor")
_LOOP_RE = re.compile(
    r"^Loop time of\s+(?P<sec>\S+)\s+on\s+(?P<procs>\d+)\s+procs?\s+"
    r"for\s+(?P<steps>\d+)\s+steps\s+with\s+(?P<atoms>\d+)\s+atoms"
)
_ERROR_RE = re.compile(r"^ERROR(?: on proc (?P<proc>\d+))?\s*:")
_WARNING_RE = re.compile(r"^WARNING(?: on proc \d+)?\s*:")
_PERF_ITEM_RE = re.compile(r"^\s*(?P<val>[-+0-9.eE]+|nan|inf)\s+(?P<unit>\S+)\s*$")
_ATOMSTEP_RE = re.compile(r"^(?P<prefix>[kMGT]?)atom-step/s$")
_PREFIX = {"": 1.0, "k": 1e3, "M": 1e6, "G": 1e9, "T": 1e12}
_LOST_ATOMS_RE = re.compile(r"lost atoms", re.IGNORECASE)


class LogMessage(NamedTuple):
    """An ``ERROR``/``WARNING`` line: 1-based line number, the line itself,
    and for errors the ``Last input line: ...`` that LAMMPS prints after it
    (empty if none)."""

    lineno: int
    text: str
    context: str = ""


class ThermoRow(NamedTuple):
    """One thermo output row. ``run_index`` counts thermo blocks from 0."""

    run_index: int
    lineno: int
    columns: tuple[str, ...]
    values: tuple[int | float, ...]

    def as_dict(self) -> dict[str, int | float]:
        return dict(zip(self.columns, self.values))


@dataclass
class RunInfo:
    """One ``run``/``minimize`` thermo block of the log."""

    index: int
    header_line: int
    columns: tuple[str, ...]
    nrows: int = 0
    first_step: int | None = None
    last_step: int | None = None
    completed: bool = False
    #: from ``Loop time of X on P procs for N steps with M atoms``
    loop_line: int | None = None
    loop_seconds: float | None = None
    nprocs: int | None = None
    nsteps: int | None = None
    natoms: int | None = None
    #: ``Performance:`` line as {unit: value}, e.g. {"timesteps/s": 68.2,
    #: "Matom-step/s": 2.3}; empty when LAMMPS printed none (e.g. units si)
    performance: dict[str, float] = field(default_factory=dict)
    supported: bool = True

    @property
    def particle_steps_per_s(self) -> float | None:
        """atoms x steps / loop seconds (from the Loop time line)."""
        if not self.loop_seconds or self.nsteps is None or self.natoms is None:
            return None
        return self.nsteps * self.natoms / self.loop_seconds

    @property
    def perf_atom_steps_per_s(self) -> float | None:
        """atom-steps/s as LAMMPS's own ``Performance:`` line states it."""
        for unit, val in self.performance.items():
            m = _ATOMSTEP_RE.match(unit)
            if m:
                return val * _PREFIX[m.group("prefix")]
        return None


@dataclass
class LogHealth:
    """What a runner needs to decide whether an engine run went well."""

    path: str
    errors: list[LogMessage] = field(default_factory=list)
    warnings: list[LogMessage] = field(default_factory=list)
    lost_atoms: bool = False
    nan: bool = False
    #: first line with a NaN/inf thermo value, and that value's column
    nan_line: int | None = None
    nan_column: str | None = None
    runs: list[RunInfo] = field(default_factory=list)
    #: log ends inside a thermo block (or with a thermo line cut mid-line)
    truncated: bool = False
    #: ``Total wall time`` reached (LAMMPS exited normally)
    finished: bool = False
    #: thermo lines skipped with strict=False, and other remarks
    notes: list[str] = field(default_factory=list)

    # -- aggregates ---------------------------------------------------------
    @property
    def started_runs(self) -> int:
        return len(self.runs)

    @property
    def completed_runs(self) -> int:
        return sum(1 for r in self.runs if r.completed)

    @property
    def total_steps(self) -> int:
        return sum(r.nsteps or 0 for r in self.runs if r.completed)

    @property
    def atoms(self) -> int | None:
        """Atom count of the last ``Loop time`` line."""
        for r in reversed(self.runs):
            if r.natoms is not None:
                return r.natoms
        return None

    @property
    def last_step(self) -> int | None:
        for r in reversed(self.runs):
            if r.last_step is not None:
                return r.last_step
        return None

    @property
    def loop_seconds(self) -> float:
        return sum(r.loop_seconds or 0.0 for r in self.runs if r.completed)

    @property
    def particle_steps_per_s(self) -> float | None:
        """sum(steps x atoms) / sum(loop seconds) over completed runs."""
        work = sum(
            (r.nsteps or 0) * (r.natoms or 0) for r in self.runs if r.completed
        )
        secs = self.loop_seconds
        if secs <= 0.0 or work == 0:
            return None
        return work / secs

    @property
    def ok(self) -> bool:
        return (
            not self.errors
            and not self.nan
            and not self.lost_atoms
            and not self.truncated
            and self.started_runs > 0
            and self.completed_runs == self.started_runs
        )

    def failure(self) -> str | None:
        """One line saying why the run is not ok, quoting the engine's own
        error line with ``file:line``; ``None`` when :attr:`ok`."""
        if self.errors:
            e = self.errors[0]
            ctx = f" [{e.context}]" if e.context else ""
            return f"{self.path}:{e.lineno}: {e.text}{ctx}"
        if self.lost_atoms:
            w = next(m for m in self.warnings if _LOST_ATOMS_RE.search(m.text))
            return f"{self.path}:{w.lineno}: {w.text}"
        if self.nan:
            return (
                f"{self.path}:{self.nan_line}: non-finite thermo value"
                f" in column {self.nan_column!r}"
            )
        if not self.runs:
            return f"{self.path}: no thermo block (no run started)"
        if self.truncated or self.completed_runs != self.started_runs:
            r = self.runs[-1]
            where = r.last_step if r.last_step is not None else "start"
            return (
                f"{self.path}: run {r.index} did not complete"
                f" (log ends after step {where}; engine killed?)"
            )
        return None


@dataclass
class LogResult:
    health: LogHealth
    #: one DataFrame per thermo block: header columns + ``run_index``
    thermo: list[pd.DataFrame]


class _LogScanner:
    """The state machine; feed it lines, it returns thermo rows."""

    IDLE, HEADER, THERMO, UNSUPPORTED = range(4)

    def __init__(self, path: PathLike, strict: bool = True) -> None:
        self.path = path
        self.strict = strict
        self.state = self.IDLE
        self.health = LogHealth(path=str(path))
        self.run: RunInfo | None = None
        self._pending_error: int | None = None  # index awaiting "Last input line"
        self._last_loop_run: RunInfo | None = None

    # -- helpers -------------------------------------------------------------
    def _message(self, ln: Line, text: str) -> bool:
        """Collect ERROR/WARNING lines; True if the line was one."""
        if _ERROR_RE.match(text):
            self.health.errors.append(LogMessage(ln.lineno, text))
            self._pending_error = len(self.health.errors) - 1
            if _LOST_ATOMS_RE.search(text):
                self.health.lost_atoms = True
            return True
        if _WARNING_RE.match(text):
            self.health.warnings.append(LogMessage(ln.lineno, text))
            if _LOST_ATOMS_RE.search(text):
                self.health.lost_atoms = True
            return True
        return False

    def _start_run(self, ln: Line) -> None:
        if self.run is not None and self.state in (self.THERMO, self.HEADER):
            self.health.notes.append(
                f"line {ln.lineno}: new run starts before 'Loop time' of run"
                f" {self.run.index}"
            )
        self.state = self.HEADER
        self.run = None

    def _loop(self, ln: Line, m: re.Match[str]) -> None:
        run = self.run
        if run is None or self.state not in (self.THERMO, self.UNSUPPORTED):
            # Loop line without a thermo block: a run with thermo output off
            run = RunInfo(
                index=len(self.health.runs), header_line=ln.lineno, columns=()
            )
            self.health.runs.append(run)
        try:
            run.loop_seconds = float(m.group("sec"))
        except ValueError:
            raise ParseError(
                self.path, ln.lineno, f"bad seconds in 'Loop time' line: {ln.text!r}"
            ) from None
        run.loop_line = ln.lineno
        run.nprocs = int(m.group("procs"))
        run.nsteps = int(m.group("steps"))
        run.natoms = int(m.group("atoms"))
        run.completed = True
        self._last_loop_run = run
        self.run = None
        self.state = self.IDLE

    def _performance(self, ln: Line, text: str) -> None:
        run = self._last_loop_run
        if run is None:
            return
        for item in text.split(":", 1)[1].split(","):
            m = _PERF_ITEM_RE.match(item)
            if m:
                try:
                    run.performance[m.group("unit")] = float(m.group("val"))
                except ValueError:
                    self.health.notes.append(
                        f"line {ln.lineno}: unreadable Performance item {item!r}"
                    )

    def _header(self, ln: Line, text: str) -> None:
        tokens = tuple(text.split())
        first = tokens[0]
        run = RunInfo(
            index=len(self.health.runs), header_line=ln.lineno, columns=tokens
        )
        self.health.runs.append(run)
        self.run = run
        if first.startswith("-") or first.endswith(":") or _is_number(first):
            # thermo_style multi ("---- Step 0 ----") or yaml ("---")
            run.supported = False
            run.columns = ()
            self.health.notes.append(
                f"line {ln.lineno}: thermo block not in one-line format"
                " (thermo_style multi/yaml?) - not tabulated"
            )
            self.state = self.UNSUPPORTED
        else:
            self.state = self.THERMO

    def _row(self, ln: Line, tokens: list[str]) -> ThermoRow | None:
        run = self.run
        assert run is not None
        if not ln.complete:  # cut mid-line at end of file: not a row
            self.health.truncated = True
            self.health.notes.append(
                f"line {ln.lineno}: thermo line cut off at end of file, dropped"
            )
            return None
        ncol = len(run.columns)
        if len(tokens) != ncol:
            msg = (
                f"thermo row of run {run.index} has {len(tokens)} values,"
                f" expected {ncol} ({' '.join(run.columns)})"
            )
            if self.strict:
                raise ParseError(self.path, ln.lineno, msg)
            self.health.notes.append(f"line {ln.lineno}: {msg} - skipped")
            return None
        values: list[int | float] = []
        for tok, col in zip(tokens, run.columns):
            try:
                v = parse_number(tok)
            except ValueError:
                msg = f"thermo value {tok!r} in column {col!r} is not a number"
                if self.strict:
                    raise ParseError(self.path, ln.lineno, msg) from None
                self.health.notes.append(f"line {ln.lineno}: {msg} - skipped")
                return None
            if isinstance(v, float) and not math.isfinite(v) and not self.health.nan:
                self.health.nan = True
                self.health.nan_line = ln.lineno
                self.health.nan_column = col
            values.append(v)
        step = values[0] if run.columns[0].lower() == "step" else None
        if isinstance(step, int):
            if run.first_step is None:
                run.first_step = step
            run.last_step = step
        run.nrows += 1
        return ThermoRow(run.index, ln.lineno, run.columns, tuple(values))

    # -- driver --------------------------------------------------------------
    def feed(self, ln: Line) -> ThermoRow | None:
        text = ln.text.strip()
        if not text:
            return None
        if self._pending_error is not None:
            idx, self._pending_error = self._pending_error, None
            if text.startswith("Last input line:"):
                e = self.health.errors[idx]
                self.health.errors[idx] = e._replace(context=text)
                return None
        if self._message(ln, text):
            if text.startswith("ERROR") and self.state != self.IDLE:
                self.state = self.IDLE  # run aborted; block stays incomplete
                self.run = None
            return None
        if text.startswith(_RUN_START):
            self._start_run(ln)
            return None
        m = _LOOP_RE.match(text)
        if m:
            self._loop(ln, m)
            return None
        if text.startswith("Performance:"):
            self._performance(ln, text)
            return None
        if text.startswith("Total wall time"):
            self.health.finished = True
            return None
        if self.state == self.HEADER:
            self._header(ln, text)
            return None
        if self.state == self.THERMO:
            tokens = text.split()
            if _is_number(tokens[0]):
                return self._row(ln, tokens)
            return None  # interleaved message from a fix etc.
        return None

    def finish(self) -> None:
        if self.state in (self.HEADER, self.THERMO, self.UNSUPPORTED):
            self.health.truncated = True


def _is_number(tok: str) -> bool:
    try:
        float(tok)
    except ValueError:
        return False
    return True


def _rows(sc: _LogScanner) -> Iterator[ThermoRow]:
    for ln in iter_lines(sc.path):
        row = sc.feed(ln)
        if row is not None:
            yield row
    sc.finish()


def iter_thermo_rows(path: PathLike, *, strict: bool = True) -> Iterator[ThermoRow]:
    """Yield the thermo rows of a log one at a time (bounded memory)."""
    yield from _rows(_LogScanner(path, strict=strict))


def read_log(path: PathLike, *, strict: bool = True) -> LogResult:
    """Parse a whole log: health summary and one DataFrame per thermo block.

    Each DataFrame has the header's columns plus a ``run_index`` column;
    integer keywords (Step, Elapsed, Atoms, ...) are int64, the rest
    float64.  Blocks without one-line thermo output get an empty DataFrame.
    """
    cols_by_run: dict[int, dict[str, list]] = {}
    sc = _LogScanner(path, strict=strict)
    for row in _rows(sc):
        data = cols_by_run.get(row.run_index)
        if data is None:
            data = {c: [] for c in unique_names(row.columns)}
            cols_by_run[row.run_index] = data
        for key, v in zip(data, row.values):
            data[key].append(v)
    frames: list[pd.DataFrame] = []
    for run in sc.health.runs:
        data = cols_by_run.get(run.index)
        if data is None:
            df = pd.DataFrame(
                {c: pd.Series(dtype="float64") for c in unique_names(run.columns)}
            )
        else:
            df = pd.DataFrame(
                {name: _column(name, vals) for name, vals in data.items()}
            )
        df["run_index"] = pd.Series(
            [run.index] * len(df), dtype="int64", index=df.index
        )
        frames.append(df)
    return LogResult(health=sc.health, thermo=frames)


def read_thermo(path: PathLike, *, strict: bool = True) -> list[pd.DataFrame]:
    """One DataFrame per run (thermo block); see :func:`read_log`."""
    return read_log(path, strict=strict).thermo


def check_log(path: PathLike, *, strict: bool = True) -> LogHealth:
    """Scan a log without keeping thermo rows and report its health.

    ``health.ok`` is False on any ERROR line, lost atoms, a NaN/inf thermo
    value, a truncated log or an unfinished run; ``health.failure()`` then
    quotes the engine's own line.
    """
    sc = _LogScanner(path, strict=strict)
    for _row in _rows(sc):
        pass
    return sc.health


def _column(name: str, vals: list) -> pd.Series:
    if is_int_column(name) and all(type(v) is int for v in vals):
        return pd.Series(vals, dtype="int64")
    return pd.Series(vals, dtype="float64")
