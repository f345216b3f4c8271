"""Time of the indentation break-off search: the backward scan against the plain one, in one session.

    .venv/bin/python bench/detachment.py FOLDER [FOLDER ...] [--repeat 3] [--min-grains 25]

Each FOLDER holds a recorded run as the session scripts leave it: ``run/`` (the engine folder with
``specimen.data``) and ``parsed/`` (``deckgen parse FOLDER/run --out FOLDER/parsed``, with ``broken.parquet`` or
``broken.csv``). For each folder it finds the first break step that frees a piece of ``--min-grains`` grains with
``deckgen.chips.first_detachment_step`` (final graph labelled once, bonds put back step by step) and with
``deckgen.chips._first_detachment_scan`` (the graph relabelled after every break step), alternating the two
``--repeat`` times, checks they give the same step and prints the medians and their ratio. The machine is shared and
noisy: read the ratio of one invocation, not absolute times across days.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import pandas as pd

from deckgen.chips import DETACH_MIN_GRAINS, _first_detachment_scan, first_detachment_step, initial_bonds


def broken_table(folder: Path) -> pd.DataFrame:
    """The parsed broken-bond table of a recorded run folder."""
    for name in ("broken.parquet", "broken.csv"):
        path = folder / "parsed" / name
        if path.is_file():
            return pd.read_parquet(path) if path.suffix == ".parquet" else pd.read_csv(path)
    raise SystemExit(f"{folder}: no parsed/broken.parquet or parsed/broken.csv (fix: deckgen parse {folder}/run "
                     f"--out {folder}/parsed)")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("folders", nargs="+", type=Path)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--min-grains", type=int, default=DETACH_MIN_GRAINS)
    args = ap.parse_args(argv)
    if args.repeat < 1:
        ap.error("--repeat must be at least 1")
    ratios = []
    for folder in args.folders:
        bonds = initial_bonds(folder / "run")
        if bonds is None:
            raise SystemExit(f"{folder}/run: no specimen.data and no step-0 bond sample: initial bonds unknown")
        br = broken_table(folder)
        pairs, steps = br[["id1", "id2"]].to_numpy(), br["step"].to_numpy()
        times: dict[str, list[float]] = {"backward": [], "plain": []}
        found = {}
        for _ in range(args.repeat):
            for name, fn in (("backward", first_detachment_step), ("plain", _first_detachment_scan)):
                t0 = time.perf_counter()
                found[name] = fn(bonds, pairs, steps, args.min_grains)
                times[name].append(time.perf_counter() - t0)
        if found["backward"] != found["plain"]:
            print(f"{folder}: the two scans disagree: backward {found['backward']}, plain {found['plain']}")
            return 1
        mb, mp = statistics.median(times["backward"]), statistics.median(times["plain"])
        ratios.append(mp / mb)
        print(f"{folder.name}: {len(bonds)} bonds, {len(br)} broken at {br['step'].nunique()} steps, break-off step "
              f"{found['plain']}; median backward {mb:.3f} s, plain {mp:.3f} s, plain/backward x{mp / mb:.0f}")
    print(f"{len(ratios)} runs: plain/backward x{min(ratios):.0f}-x{max(ratios):.0f} (median x{statistics.median(ratios):.0f})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
