"""Streaming reader for LAMMPS text dumps: ``dump custom`` (per-atom) and
``dump local`` (per-bond / per-pair entries), plain or ``.gz``.

A frame is::

    ITEM: UNITS            (optional, dump_modify units yes)
    ITEM: TIME             (optional, dump_modify time yes)
    ITEM: TIMESTEP
    ITEM: NUMBER OF ATOMS | NUMBER OF ENTRIES
    ITEM: BOX BOUNDS <flags>   (3 lines of 2, 3 or 4 numbers)
    ITEM: ATOMS <names> | ENTRIES <names>
    <N rows>

:func:`iter_frames` yields one :class:`Frame` at a time, so memory is one
frame (of the selected columns); the row count may change from frame to
frame.  A frame cut off at the end of the file raises
:class:`~deckgen.parse.common.TruncatedError` (a ParseError) naming the
line, unless ``allow_truncated_tail=True``, which ends the iteration
cleanly after the last complete frame (runs killed mid-write).  Anything
malformed before the tail is always a ParseError.

Column dtypes: the LAMMPS integer attributes (id, type, mol, proc, ix, iy,
iz) are int64, every other column float64; ``element`` (and ``type`` when
written as type labels) may be strings.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from typing import Literal

import numpy as np
import pandas as pd

from .common import (
    Line,
    ParseError,
    PathLike,
    TruncatedError,
    is_int_column,
    iter_lines,
    unique_names,
)

__all__ = ["Frame", "iter_frames", "read_dump_table"]

_STRING_OK = frozenset({"element", "type"})
_COUNT_ITEMS = {"NUMBER OF ATOMS": "atoms", "NUMBER OF ENTRIES": "entries"}
_DATA_ITEMS = {"ATOMS": "atoms", "ENTRIES": "entries"}


@dataclass
class Frame:
    """One dump snapshot."""

    timestep: int
    #: rows in this frame (atoms for dump custom, entries for dump local)
    natoms: int
    #: (3, 2) lo/hi per axis; (3, 3) lo/hi/tilt for triclinic; (3, 4) for
    #: ``BOX BOUNDS abc origin``; None if the frame has no BOX BOUNDS
    box: np.ndarray | None
    #: words after ``ITEM: BOX BOUNDS`` (e.g. ``("ss", "ss", "ss")``)
    box_flags: tuple[str, ...]
    kind: Literal["atoms", "entries"]
    #: every column name of the ITEM: ATOMS / ENTRIES line
    columns: tuple[str, ...]
    #: the selected columns
    data: pd.DataFrame
    #: 1-based line number of the frame's first ITEM line
    lineno: int
    time: float | None = None
    units: str | None = None

    def __getitem__(self, name: str) -> np.ndarray:
        return self.data[name].to_numpy()

    def __len__(self) -> int:
        return self.natoms

    def arrays(self) -> dict[str, np.ndarray]:
        """The selected columns as a dict of numpy arrays."""
        return {c: self.data[c].to_numpy() for c in self.data.columns}


class _Reader:
    """Line source with one-line lookahead and truncation bookkeeping."""

    def __init__(self, path: PathLike) -> None:
        self.path = path
        self._it = iter_lines(path)
        self.last_lineno = 0

    def next(self) -> Line | None:
        ln = next(self._it, None)
        if ln is not None:
            self.last_lineno = ln.lineno
        return ln

    def need(self, what: str, frame_line: int) -> Line:
        """Next line, which must exist and be complete."""
        ln = self.next()
        if ln is None:
            raise TruncatedError(
                self.path,
                self.last_lineno + 1,
                f"file ends inside the frame starting at line {frame_line};"
                f" expected {what}",
            )
        if not ln.complete:
            raise TruncatedError(
                self.path,
                ln.lineno,
                f"line cut off at end of file inside the frame starting at"
                f" line {frame_line}; expected {what}",
            )
        return ln


def _item(ln: Line) -> str | None:
    t = ln.text.strip()
    if t.startswith("ITEM:"):
        return t[5:].strip()
    return None


def _int(reader: _Reader, ln: Line, what: str) -> int:
    try:
        v = int(ln.text.strip())
    except ValueError:
        raise ParseError(
            reader.path, ln.lineno, f"expected {what} (an integer), got {ln.text.strip()!r}"
        ) from None
    if v < 0:
        raise ParseError(reader.path, ln.lineno, f"expected {what} >= 0, got {v}")
    return v


def _select(
    reader: _Reader, ln: Line, names: tuple[str, ...], columns: tuple[str, ...] | None
) -> list[int]:
    if columns is None:
        return list(range(len(names)))
    idx = []
    for c in columns:
        try:
            idx.append(names.index(c))
        except ValueError:
            raise ParseError(
                reader.path,
                ln.lineno,
                f"column {c!r} not in this dump; it has {' '.join(names)}",
            ) from None
    return idx


def _convert(
    reader: _Reader, name: str, tokens: list[str], first_row_line: int
) -> np.ndarray:
    if is_int_column(name):
        try:
            return np.asarray(tokens, dtype=np.int64)
        except (ValueError, OverflowError):
            pass
    try:
        return np.asarray(tokens, dtype=np.float64)
    except ValueError:
        if name.lower() in _STRING_OK:
            return np.asarray(tokens, dtype=object)
        for i, tok in enumerate(tokens):
            try:
                float(tok)
            except ValueError:
                raise ParseError(
                    reader.path,
                    first_row_line + i,
                    f"column {name!r}: {tok!r} is not a number",
                ) from None
        # numpy rejected a token that float() accepts (e.g. "1_0")
        raise ParseError(
            reader.path, first_row_line, f"column {name!r}: unreadable number"
        ) from None


def _read_frame(
    reader: _Reader, first: Line, columns: tuple[str, ...] | None
) -> Frame:
    frame_line = first.lineno
    timestep: int | None = None
    count: int | None = None
    count_kind: str | None = None
    box: np.ndarray | None = None
    box_flags: tuple[str, ...] = ()
    time: float | None = None
    units: str | None = None

    ln: Line | None = first
    while True:
        assert ln is not None
        if not ln.complete:
            raise TruncatedError(
                reader.path, ln.lineno, "line cut off at end of file (ITEM line)"
            )
        item = _item(ln)
        if item is None:
            raise ParseError(
                reader.path,
                ln.lineno,
                f"expected an 'ITEM: ...' line, got {ln.text.strip()[:60]!r}",
            )
        if item == "TIMESTEP":
            if timestep is not None:
                raise ParseError(
                    reader.path,
                    ln.lineno,
                    f"second ITEM: TIMESTEP in the frame starting at line"
                    f" {frame_line}; expected ITEM: ATOMS/ENTRIES",
                )
            v = reader.need("the timestep", frame_line)
            timestep = _int(reader, v, "the timestep")
        elif item in _COUNT_ITEMS:
            v = reader.need(f"the {item.lower()}", frame_line)
            count = _int(reader, v, f"the {item.lower()}")
            count_kind = _COUNT_ITEMS[item]
        elif item.startswith("BOX BOUNDS"):
            box_flags = tuple(item[len("BOX BOUNDS"):].split())
            rows = []
            for axis in "xyz":
                b = reader.need(f"the {axis} box bounds", frame_line)
                try:
                    rows.append([float(t) for t in b.text.split()])
                except ValueError:
                    rows.append([])
                if len(rows[-1]) not in (2, 3, 4) or len(rows[-1]) != len(rows[0]):
                    raise ParseError(
                        reader.path,
                        b.lineno,
                        f"expected 2-4 numbers of the {axis} box bounds,"
                        f" got {b.text.strip()[:60]!r}",
                    )
            box = np.asarray(rows, dtype=np.float64)
        elif item == "TIME":
            t = reader.need("the time", frame_line)
            try:
                time = float(t.text)
            except ValueError:
                raise ParseError(
                    reader.path, t.lineno, f"expected the time, got {t.text.strip()!r}"
                ) from None
        elif item == "UNITS":
            units = reader.need("the units", frame_line).text.strip()
        else:
            head, _, rest = item.partition(" ")
            if head not in _DATA_ITEMS:
                raise ParseError(
                    reader.path, ln.lineno, f"unknown dump section 'ITEM: {item}'"
                )
            kind = _DATA_ITEMS[head]
            break
        ln = reader.next()
        if ln is None:
            raise TruncatedError(
                reader.path,
                reader.last_lineno + 1,
                f"file ends inside the frame starting at line {frame_line};"
                " expected ITEM: ATOMS/ENTRIES",
            )

    # ln is the ITEM: ATOMS / ENTRIES line
    if timestep is None or count is None:
        raise ParseError(
            reader.path,
            ln.lineno,
            f"ITEM: {head} before ITEM: TIMESTEP and ITEM: NUMBER OF ..."
            f" (frame starting at line {frame_line})",
        )
    if count_kind != kind:
        raise ParseError(
            reader.path,
            ln.lineno,
            f"ITEM: {head} after ITEM: NUMBER OF {str(count_kind).upper()}",
        )
    names = tuple(rest.split())
    if not names:
        raise ParseError(
            reader.path, ln.lineno, f"ITEM: {head} line has no column names"
        )
    names = tuple(unique_names(names))
    sel = _select(reader, ln, names, columns)
    ncol = len(names)
    nsel = len(sel)
    flat: list[str] = []
    first_row_line = ln.lineno + 1
    for i in range(count):
        row = reader.need(
            f"{count} {kind} rows (got {i}) of the frame at timestep {timestep}",
            frame_line,
        )
        toks = row.text.split()
        if len(toks) != ncol:
            if toks and toks[0] == "ITEM:":
                raise ParseError(
                    reader.path,
                    row.lineno,
                    f"frame at timestep {timestep} has {i} {kind} rows,"
                    f" NUMBER OF {kind.upper()} said {count}",
                )
            raise ParseError(
                reader.path,
                row.lineno,
                f"expected {ncol} values ({' '.join(names)}), got {len(toks)}",
            )
        if nsel == ncol:
            flat.extend(toks)
        else:
            flat.extend([toks[j] for j in sel])
    data = {
        names[j]: _convert(reader, names[j], flat[k::nsel], first_row_line)
        for k, j in enumerate(sel)
    }
    df = pd.DataFrame(data)
    if not data:
        df = pd.DataFrame(index=pd.RangeIndex(count))
    return Frame(
        timestep=timestep,
        natoms=count,
        box=box,
        box_flags=box_flags,
        kind=kind,  # type: ignore[arg-type]
        columns=names,
        data=df,
        lineno=frame_line,
        time=time,
        units=units,
    )


def _norm_columns(columns: str | Iterable[str] | None) -> tuple[str, ...] | None:
    if columns is None:
        return None
    if isinstance(columns, str):
        return (columns,)
    return tuple(columns)


def iter_frames(
    path: PathLike,
    columns: str | Iterable[str] | None = None,
    *,
    allow_truncated_tail: bool = False,
) -> Iterator[Frame]:
    """Yield the frames of a LAMMPS ``dump custom`` / ``dump local`` file.

    ``columns`` picks columns by the names of the ITEM: ATOMS / ENTRIES line
    (default: all); asking for a missing one is a ParseError.
    """
    cols = _norm_columns(columns)
    reader = _Reader(path)
    while True:
        try:
            ln = reader.next()
            while ln is not None and ln.complete and not ln.text.strip():
                ln = reader.next()  # tolerate blank lines between frames
            if ln is None:
                return
            yield _read_frame(reader, ln, cols)
        except TruncatedError:
            if allow_truncated_tail:
                return
            raise


def read_dump_table(
    path: PathLike,
    columns: str | Iterable[str] | None = None,
    *,
    allow_truncated_tail: bool = False,
    step_column: str = "step",
) -> pd.DataFrame:
    """All frames as one long tidy DataFrame: ``step`` + the chosen columns.

    Streams frame by frame; only the chosen columns are kept.
    """
    cols = _norm_columns(columns)
    parts: list[pd.DataFrame] = []
    for fr in iter_frames(path, cols, allow_truncated_tail=allow_truncated_tail):
        part = fr.data
        part.insert(0, step_column, np.full(len(part), fr.timestep, dtype=np.int64))
        parts.append(part)
    if not parts:
        return pd.DataFrame(
            {step_column: pd.Series(dtype="int64"),
             **{c: pd.Series(dtype="float64") for c in (cols or ())}}
        )
    return pd.concat(parts, ignore_index=True)
