"""Jinja2 rendering of engine decks.

Templates live in ``templates/<engine>/`` at the repository root (a project-local folder named
by ``DECKGEN_TEMPLATES`` is searched first). Logic stays out of templates: every value a
template prints passes one of the filters below, which accept only finite numbers or
whitelisted tokens. So nothing from a case file can reach a deck as free text.
"""

from __future__ import annotations

import math
import os
import re
from pathlib import Path
from typing import Any, Iterable

import jinja2
import numpy as np

TOKEN = re.compile(r"^[A-Za-z_][A-Za-z0-9_\-./]{0,127}$")
# tokens that may appear in a deck (file names are checked separately: relative, no '..')


class DeckError(ValueError):
    """A value that may not be written into a deck."""


def repo_root() -> Path:
    return Path(__file__).resolve().parents[2]


def template_dirs() -> list[Path]:
    dirs = []
    local = os.environ.get("DECKGEN_TEMPLATES")
    if local:
        dirs.append(Path(local))
    dirs.append(repo_root() / "templates")
    return dirs


def f_num(value: Any) -> str:
    """A finite real number, printed with 10 significant digits."""
    if isinstance(value, (bool, np.bool_)):
        raise DeckError(f"expected a number, got a boolean {value!r}")
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        v = float(value)
        if not math.isfinite(v):
            raise DeckError(f"non-finite number {v!r} cannot go into a deck")
        s = f"{v:.10g}"
        return s
    raise DeckError(f"expected a number, got {type(value).__name__} {value!r}")


def f_int(value: Any) -> str:
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        if isinstance(value, (float, np.floating)) and float(value).is_integer():
            return str(int(value))
        raise DeckError(f"expected an integer, got {value!r}")
    return str(int(value))


def f_tok(value: Any) -> str:
    """A whitelisted token: identifier-like, no spaces, quotes, $, &, ;, or shell syntax."""
    if not isinstance(value, str) or not TOKEN.match(value) or ".." in value:
        raise DeckError(f"not an allowed token for a deck: {value!r}")
    return value


def f_path(value: Any) -> str:
    """A relative file name inside the run folder."""
    s = str(value)
    if s.startswith("/") or ".." in Path(s).parts or not TOKEN.match(s):
        raise DeckError(f"deck paths must be relative names inside the run folder: {value!r}")
    return s


COMMENT = re.compile(r"^[A-Za-z0-9 _,.()/*^+\-=:%<>\[\]|']*$")


def f_comment(value: Any) -> str:
    """Comment text written by deckgen itself (never case strings): one line, no $ or quotes."""
    s = str(value)
    if not COMMENT.match(s):
        raise DeckError(f"comment text has characters not allowed in a deck: {value!r}")
    return s


def f_nums(values: Iterable[Any]) -> str:
    return " ".join(f_num(v) for v in values)


def environment() -> jinja2.Environment:
    env = jinja2.Environment(
        loader=jinja2.FileSystemLoader([str(d) for d in template_dirs()]),
        undefined=jinja2.StrictUndefined,
        keep_trailing_newline=True,
        trim_blocks=True,
        lstrip_blocks=True,
        autoescape=False,
    )
    env.filters.update(num=f_num, int=f_int, tok=f_tok, path=f_path, nums=f_nums, comment=f_comment)
    return env


def render(template: str, context: dict[str, Any]) -> str:
    return environment().get_template(template).render(**context)
