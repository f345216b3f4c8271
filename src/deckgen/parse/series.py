"""Reader for the whitespace time-series files LAMMPS fixes write.

Two layouts, both read line by line:

``fix print ... file F title "# step time_s fx_N"``
    one ``#`` title line with the column names, then numeric rows.
``fix ave/time ... file F`` (scalar mode)
    ``# Time-averaged data for fix ID`` and ``# TimeStep c_x v_y ...``;
    the last comment line before the data gives the names.
``fix ave/time ... mode vector`` / ``fix ave/chunk``
    three comment lines; the second is ``# TimeStep Number-of-rows`` (or
    ``# Timestep Number-of-chunks Total-count``), the third names the row
    columns.  Data come in blocks: ``<step> <nrows> ...`` then ``nrows``
    rows.  The result is long: the step column + the row columns.

Names are the title's words without the ``#``.  ``step``/``TimeStep`` (and
``Row``, ``Chunk``) columns are int64, all others float64.  A non-numeric
token or a row with the wrong number of values raises
:class:`~deckgen.parse.common.ParseError` with ``file:line``.  A last line
cut off at end of file (no newline) raises
:class:`~deckgen.parse.common.TruncatedError` unless
``allow_truncated_tail=True``, which drops it.
"""

from __future__ import annotations

from collections.abc import Sequence

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

__all__ = ["read_series"]


def _is_block_header(words: list[str]) -> bool:
    return (
        len(words) >= 2
        and words[0].lower() == "timestep"
        and any(w.lower().startswith("number-of") for w in words[1:])
    )


class _Columns:
    def __init__(self, names: Sequence[str]) -> None:
        self.names = unique_names(list(names))
        self.values: list[list[int | float]] = [[] for _ in self.names]
        self.int_ok = [is_int_column(n) for n in self.names]

    def add(self, path: PathLike, ln: Line, toks: Sequence[str]) -> None:
        if len(toks) != len(self.names):
            raise ParseError(
                path,
                ln.lineno,
                f"expected {len(self.names)} values ({' '.join(self.names)}),"
                f" got {len(toks)}",
            )
        row: list[int | float] = []
        for j, tok in enumerate(toks):
            try:
                if self.int_ok[j]:
                    try:
                        row.append(int(tok))
                        continue
                    except ValueError:
                        self.int_ok[j] = False
                row.append(float(tok))
            except ValueError:
                raise ParseError(
                    path,
                    ln.lineno,
                    f"column {self.names[j]!r}: {tok!r} is not a number",
                ) from None
        for col, v in zip(self.values, row):
            col.append(v)

    def frame(self) -> pd.DataFrame:
        return pd.DataFrame(
            {
                n: pd.Series(v, dtype="int64" if ok else "float64")
                for n, v, ok in zip(self.names, self.values, self.int_ok)
            }
        )


def read_series(
    path: PathLike,
    *,
    names: Sequence[str] | None = None,
    allow_truncated_tail: bool = False,
) -> pd.DataFrame:
    """Read a ``fix print`` / ``fix ave/time`` file into a DataFrame.

    ``names`` overrides the names of the title line (needed for a file
    without one).
    """
    comments: list[tuple[int, list[str]]] = []
    cols: _Columns | None = None
    block_mode = False
    block_left = 0  # rows still expected in the current block
    block_step: str | None = None
    block_rows: list[tuple[Line, list[str]]] = []
    block_line = 0

    def setup(first: Line) -> None:
        nonlocal cols, block_mode
        if names is not None:
            cols = _Columns(names)
            return
        if not comments:
            raise ParseError(
                path,
                first.lineno,
                "expected a '# name name ...' title line before the first data row",
            )
        if len(comments) >= 2 and _is_block_header(comments[-2][1]):
            block_mode = True
            cols = _Columns([comments[-2][1][0], *comments[-1][1]])
        else:
            cols = _Columns(comments[-1][1])

    for ln in iter_lines(path):
        text = ln.text.strip()
        if not ln.complete:
            if allow_truncated_tail:
                break
            raise TruncatedError(
                path, ln.lineno, f"last line cut off at end of file: {text[:60]!r}"
            )
        if not text:
            continue
        if text.startswith("#"):
            if cols is None:
                comments.append((ln.lineno, text.lstrip("#").split()))
            continue
        if cols is None:
            setup(ln)
            assert cols is not None
        toks = text.split()
        if not block_mode:
            cols.add(path, ln, toks)
            continue
        if block_left == 0:  # a block header "<step> <nrows> [...]"
            try:
                block_step = str(int(toks[0]))
                block_left = int(toks[1])
            except (ValueError, IndexError):
                raise ParseError(
                    path,
                    ln.lineno,
                    f"expected a block header '<{cols.names[0]}> <number of rows>',"
                    f" got {text[:60]!r}",
                ) from None
            block_rows = []
            block_line = ln.lineno
            continue
        block_rows.append((ln, [block_step, *toks]))  # type: ignore[list-item]
        block_left -= 1
        if block_left == 0:
            for bl, bt in block_rows:
                cols.add(path, bl, bt)
            block_rows = []

    if block_left:
        if not allow_truncated_tail:
            raise TruncatedError(
                path,
                block_line,
                f"file ends inside the block starting at line {block_line}"
                f" ({block_left} rows missing)",
            )
    if cols is None:
        if names is not None:
            return _Columns(names).frame()
        if not comments:
            raise ParseError(
                path, 1, "empty series file: expected a '# name name ...' title line"
            )
        setup(Line(comments[-1][0], "", True))
        assert cols is not None
    return cols.frame()
