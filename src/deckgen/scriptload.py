"""Import a Python file that is not in a package as a module.

The analysis scripts under ``docs/families_runs`` load their neighbours (``compare.py`` and the like) and the tests load
those scripts; this is the one place that does it.
"""
from __future__ import annotations

import importlib.util
from pathlib import Path
from types import ModuleType


def load_script(path: str | Path, name: str | None = None) -> ModuleType:
    """The file at ``path`` imported as a module named ``name`` (default: the file's stem); FileNotFoundError naming the
    path if it is missing."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no such script")
    spec = importlib.util.spec_from_file_location(name or path.stem, path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod
