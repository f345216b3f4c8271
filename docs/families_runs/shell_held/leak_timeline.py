"""When grains get into the cutter's tip, frame by frame (session 34).

For each run folder given (a rendered and run cutting case: ``run/spec.json`` and ``run/atoms.dump.gz``, and
``final.dump.gz`` if the deck wrote one), streams the per-atom dump and prints one row per frame: the step, the travel
fraction, the grains (type 1) whose centres lie inside the true cutter body (:func:`deckgen.results.grains_inside_cutter`,
the check behind ``grains_inside_cutter_final``), and as a check of that rebuilt body the fraction of the shell's own
spheres (type 2) whose centres it holds (they sit their radius inside the surface, so 1.0 unless the shell moved other
than the deck's rigid motion: below 1.0 on the straight-path decks before session 34, whose shell spheres drifted
sideways; see ``compare.py`` here). Frames are read one at a time (:func:`deckgen.parse.dump.iter_frames`).

    python docs/families_runs/shell_held/leak_timeline.py RUN_DIR [RUN_DIR ...] [--csv OUT.csv]

RUN_DIR is the folder holding spec.json and the dumps (``deckgen render --out RUN_DIR``) or its parent with ``run/``.
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
import pandas as pd

from deckgen.parse.dump import iter_frames
from deckgen.results import grains_inside_cutter


def _run_dir(path: Path) -> Path:
    return path / "run" if (path / "run" / "spec.json").is_file() else path


def timeline(run: Path) -> pd.DataFrame:
    """One row per dump frame of ``run``: step, time_s, travel_fraction_1, grains_inside, shell_inside_fraction_1."""
    run = _run_dir(Path(run))
    spec_path = run / "spec.json"
    if not spec_path.is_file():
        raise SystemExit(f"{run}: no spec.json (fix: give a folder made by deckgen render)")
    spec = json.loads(spec_path.read_text())
    if "dt_s" not in spec["derived"]:
        raise SystemExit(f"{spec_path}: derived.dt_s missing (fix: render the case again with this deckgen)")
    dt = float(spec["derived"]["dt_s"])
    duration = float(spec["derived"]["cutter"]["duration"])
    rows = []
    for name in ("atoms.dump.gz", "final.dump.gz"):
        path = run / name
        if not path.is_file():
            continue
        for fr in iter_frames(path, ["type", "x", "y", "z"], allow_truncated_tail=True):
            d = fr.data
            t = fr.timestep * dt
            xyz = {k: d.loc[d["type"] == k, ["x", "y", "z"]].to_numpy(float) for k in (1, 2)}
            grains = grains_inside_cutter(xyz[1], spec, t)
            shell = grains_inside_cutter(xyz[2], spec, t) if len(xyz[2]) else None
            rows.append({"case": spec["case"]["name"], "source": name, "step": fr.timestep, "time_s": t,
                         "travel_fraction_1": min(t / duration, 1.0), "grains_inside": grains,
                         "shell_inside_fraction_1": shell / len(xyz[2]) if shell is not None else np.nan})
    if not rows:
        raise SystemExit(f"{run}: no atoms.dump.gz (fix: run the deck first: deckgen run {run})")
    out = pd.DataFrame(rows)
    return out.drop_duplicates("step", keep="last").reset_index(drop=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("runs", nargs="+", type=Path)
    ap.add_argument("--csv", type=Path, help="write all rows to this CSV as well")
    a = ap.parse_args()
    table = pd.concat([timeline(r) for r in a.runs], ignore_index=True)
    with pd.option_context("display.width", 200, "display.max_rows", 500):
        print(table.round(4).to_string(index=False))
    if a.csv:
        table.to_csv(a.csv, index=False)


if __name__ == "__main__":
    main()
