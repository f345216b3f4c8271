"""Regenerate the golden decks: ``python tests/data/golden/regenerate.py [--packings]``.

For each tiny case in tests/data/cases, the packing fixture (packed.data, packing.json) is made
by the real engine only with --packings (or when missing), then the case is rendered against it
and in.deck and spec.json are stored under tests/data/golden/<case>/. Run it after an
intentional change of a template or of the deck numbers, and review the diff.
"""

from __future__ import annotations

import argparse
import shutil
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
CASES = HERE.parent / "cases"
NAMES = ["tiny_ucs", "tiny_bts", "tiny_cut", "tiny_rotary"]


def install_fixture(case, name: str, cache: Path) -> None:
    """Put the committed packing of ``name`` where render_case looks for ``case``'s packing."""
    from deckgen.packing import packing_dir

    target = packing_dir(case, cache)
    target.mkdir(parents=True, exist_ok=True)
    for f in ("packed.data", "packing.json"):
        shutil.copy(HERE / name / "packing" / f, target / f)


def render_golden(name: str, out: Path, cache: Path) -> None:
    from deckgen.deck import render_case
    from deckgen.spec import load_case

    case = load_case(CASES / f"{name}.yaml")
    install_fixture(case, name, cache)
    render_case(case, out, cache=cache, progress=False, command=["false"])


def main() -> int:
    from deckgen.packing import ensure_packing
    from deckgen.spec import load_case

    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--packings", action="store_true", help="re-make the packing fixtures with the engine")
    args = ap.parse_args()
    for name in NAMES:
        pack = HERE / name / "packing"
        if args.packings or not (pack / "packed.data").is_file():
            with tempfile.TemporaryDirectory() as tmp:
                folder = ensure_packing(load_case(CASES / f"{name}.yaml"), Path(tmp), progress=False)
                pack.mkdir(parents=True, exist_ok=True)
                for f in ("packed.data", "packing.json"):
                    shutil.copy(folder / f, pack / f)
        with tempfile.TemporaryDirectory() as tmp:
            out = Path(tmp) / "run"
            render_golden(name, out, Path(tmp) / "cache")
            for f in ("in.deck", "spec.json"):
                shutil.copy(out / f, HERE / name / f)
        print(f"{name}: golden deck written")
    return 0


if __name__ == "__main__":
    sys.exit(main())
