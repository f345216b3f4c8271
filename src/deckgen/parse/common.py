"""Shared pieces of the engine-output parsers: gz-aware opening, line
streaming with 1-based line numbers, and the ParseError family.

Every parser in :mod:`deckgen.parse` reads its file line by line through
:func:`iter_lines`, so memory stays bounded by one record (a thermo row, a
dump frame, a series row) whatever the file size.  Bad content always ends
in a :class:`ParseError` whose message starts with ``<file>:<line>:``; a
missing file is the plain :class:`FileNotFoundError` of ``open``.
"""

from __future__ import annotations

import gzip
import os
import zlib
from collections.abc import Iterator
from pathlib import Path
from typing import NamedTuple, TextIO

__all__ = [
    "INT_COLUMNS",
    "Line",
    "ParseError",
    "TruncatedError",
    "iter_lines",
    "open_text",
]

PathLike = str | os.PathLike[str]


class ParseError(ValueError):
    """Bad content in an engine output file.

    ``str(err)`` is ``"<path>:<lineno>: <msg>"`` (``"<path>: <msg>"`` when no
    line applies); the parts stay available as ``path``, ``lineno``, ``msg``.
    """

    def __init__(self, path: PathLike, lineno: int | None, msg: str) -> None:
        self.path = os.fspath(path)
        self.lineno = lineno
        self.msg = msg
        where = f"{self.path}:{lineno}" if lineno is not None else self.path
        super().__init__(f"{where}: {msg}")

    def __reduce__(self):  # keep pickling (multiprocessing) working
        return (type(self), (self.path, self.lineno, self.msg))


class TruncatedError(ParseError):
    """The file ends inside a record (engine killed mid-write, gz stream cut).

    A subclass of :class:`ParseError`; parsers that accept
    ``allow_truncated_tail=True`` catch exactly this one and stop cleanly.
    """


def is_gzip_path(path: PathLike) -> bool:
    return os.fspath(path).lower().endswith(".gz")


def open_text(path: PathLike) -> TextIO:
    """Open *path* for reading text; ``*.gz`` (by suffix) through gzip.

    Universal newlines, UTF-8 with undecodable bytes replaced (they then fail
    as numbers with a ParseError instead of a UnicodeDecodeError).  A missing
    file raises FileNotFoundError.
    """
    p = Path(path)
    if is_gzip_path(p):
        return gzip.open(p, "rt", encoding="utf-8", errors="replace")
    return open(p, encoding="utf-8", errors="replace")


class Line(NamedTuple):
    """One line of a file: 1-based number, text without its newline, and
    whether the newline was there (``False`` only for a last line cut off at
    end of file)."""

    lineno: int
    text: str
    complete: bool


def iter_lines(path: PathLike) -> Iterator[Line]:
    """Yield :class:`Line` records of *path*, one at a time.

    A gz stream that is corrupt raises :class:`ParseError`; one that just
    stops (no end-of-stream marker: writer killed) raises
    :class:`TruncatedError` after the lines that could be read.
    """
    lineno = 0
    with open_text(path) as fh:
        try:
            for raw in fh:
                lineno += 1
                if raw.endswith("\n"):
                    yield Line(lineno, raw[:-1], True)
                else:
                    yield Line(lineno, raw, False)
        except EOFError as exc:  # gzip: "Compressed file ended before ..."
            raise TruncatedError(
                path, lineno + 1, f"compressed stream ends early ({exc})"
            ) from None
        except (gzip.BadGzipFile, zlib.error) as exc:
            raise ParseError(
                path, lineno + 1, f"corrupt gzip data ({exc})"
            ) from None
        except OSError as exc:
            # gzip raises plain OSError for some damaged headers; anything
            # else (EIO etc.) is not a content problem and propagates.
            if is_gzip_path(path) and "gzip" in str(exc).lower():
                raise ParseError(
                    path, lineno + 1, f"corrupt gzip data ({exc})"
                ) from None
            raise


#: Column names (lower-cased) that LAMMPS writes as integers: thermo
#: keywords, dump custom attributes, fix ave/time|chunk bookkeeping columns.
#: Only these become int64 columns; every other numeric column is float64,
#: even when all its values happen to print as integers ("0", "980").
INT_COLUMNS = frozenset(
    {
        # thermo
        "step", "elapsed", "elaplong", "atoms", "bonds", "angles",
        "dihedrals", "impropers", "nbuild", "ndanger",
        # dump custom
        "id", "type", "mol", "proc", "procp1", "ix", "iy", "iz",
        # fix print / ave/time / ave/chunk
        "timestep", "row", "chunk",
    }
)


def is_int_column(name: str) -> bool:
    return name.lower() in INT_COLUMNS


def parse_number(token: str) -> int | float:
    """``int`` if the token is an integer literal, else ``float`` (accepts
    ``nan``, ``-nan``, ``inf`` as LAMMPS prints them); ValueError otherwise."""
    try:
        return int(token)
    except ValueError:
        return float(token)


def unique_names(cols: tuple[str, ...] | list[str]) -> list[str]:
    """Column names made unique by suffixing repeats: a, a.1, a.2."""
    seen: dict[str, int] = {}
    out = []
    for c in cols:
        if c in seen:
            seen[c] += 1
            out.append(f"{c}.{seen[c]}")
        else:
            seen[c] = 0
            out.append(c)
    return out
