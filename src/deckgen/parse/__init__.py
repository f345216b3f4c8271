"""Streaming parsers for engine (LAMMPS) output: logs, dumps, series files.

All readers stream line by line (a dump one frame at a time), open ``*.gz``
transparently, and report bad content as :class:`ParseError` (a
``ValueError``) whose message starts with ``<file>:<line>:``.
"""

from .common import ParseError, TruncatedError, open_text
from .dump import Frame, iter_frames, read_dump_table
from .log import (
    LogHealth,
    LogMessage,
    LogResult,
    RunInfo,
    ThermoRow,
    check_log,
    iter_thermo_rows,
    read_log,
    read_thermo,
)
from .series import read_series

__all__ = [
    "Frame",
    "LogHealth",
    "LogMessage",
    "LogResult",
    "ParseError",
    "RunInfo",
    "ThermoRow",
    "TruncatedError",
    "check_log",
    "iter_frames",
    "iter_thermo_rows",
    "open_text",
    "read_dump_table",
    "read_log",
    "read_series",
    "read_thermo",
]
