"""Helpers shared by the test modules (pytest puts this folder on sys.path: ``from helpers import load_script``)."""
from __future__ import annotations

import importlib.util
from pathlib import Path


def load_script(path: Path, name: str | None = None):
    """Import a script that is not in a package (tests/data/golden/regenerate.py, docs/families_runs/**/*.py) as a
    module under ``name`` (default: the file's stem)."""
    spec = importlib.util.spec_from_file_location(name or Path(path).stem, path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod
