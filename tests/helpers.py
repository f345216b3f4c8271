"""Helpers shared by the test modules (pytest puts this folder on sys.path: ``from helpers import load_script``)."""
from __future__ import annotations

from deckgen.scriptload import load_script  # noqa: F401  (tests/data/golden/regenerate.py, docs/families_runs/**/*.py)
