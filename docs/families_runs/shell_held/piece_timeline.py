"""When does a piece of the block break off, and what does F_n do then (session 42)?

For one linear cutting run: along the cut, the pieces the bond graph falls into (``deckgen.chips.bond_components``
with the bonds broken up to each step: the body is the largest component, a piece any other of at least
``--min-grains`` grains), the mean F_n since the previous grid step and the contact patch's centre as a fraction of
the block length (the disc centre's x from the series plus half the half chord, as ``families.patch_travel_fraction``
takes it). The broken-bond record times every break to 100 steps, so the pieces do not need the dumps; at the dumped
steps the largest piece's extent and centre come from the grain positions and the contact census
(``deckgen.contacts``) says which grains the disc presses on.

    python docs/families_runs/shell_held/piece_timeline.py X [--out CSV] [--grid 200] [--min-grains 10]

``X`` holds ``X/run`` (rendered and run) and ``X/parsed`` (``deckgen parse``). Prints the first step at which the
largest piece reaches 10, 25, 50 grains and its full size, with the patch position then, and F_n over the patch
windows 0.1-0.3 ... 0.4-0.6 of ``compare.window_table``.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np
import pandas as pd


def _bond_record(run_dir: Path, parsed: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The run's initial bonds and its broken-bond record (steps, id pairs)."""
    from deckgen.chips import initial_bonds

    bonds = initial_bonds(run_dir)
    if bonds is None:
        raise SystemExit(f"{run_dir}: no specimen.data: the initial bonds are unknown")
    broken = pd.read_parquet(parsed / "broken.parquet")
    return bonds, broken["step"].to_numpy(np.int64), broken[["id1", "id2"]].to_numpy(np.int64)


def timeline(run_dir: Path, parsed: Path, grid: int = 200, min_grains: int = 10) -> pd.DataFrame:
    from deckgen.chips import bond_components
    from deckgen.families import half_chord_mm

    case = json.loads((run_dir / "spec.json").read_text())["case"]
    length_m = case["specimen"]["length_mm"] * 1e-3
    summary = json.loads((parsed / "summary.json").read_text())
    half_chord_m = half_chord_mm(summary["cutter_radius_m"] * 1e3, case["kinematics"]["penetration_mm"]) * 1e-3
    ts = pd.read_parquet(parsed / "timeseries.parquet", columns=["step", "time_s", "cutter_x_m", "force_normal_N"])
    bonds, br_steps, br_pairs = _bond_record(run_dir, parsed)
    ids = np.unique(bonds)  # bonded grains; a grain without bonds is its own component either way
    steps = ts["step"].to_numpy(np.int64)
    # grid points are series rows (the disc's x and F_n of the same row), evenly spread over the run
    grid_rows = np.unique(np.linspace(0, len(steps) - 1, grid + 1).round().astype(np.int64))
    rows = []
    for prev, i in zip(grid_rows[:-1], grid_rows[1:]):
        s = steps[i]
        label, sizes, body = bond_components(bonds, br_pairs[br_steps <= s], ids)
        pieces = np.sort(np.delete(sizes, body))[::-1]
        rows.append({"step": int(s), "time_s": float(ts["time_s"].iloc[i]),
                     "patch_centre_1": (ts["cutter_x_m"].iloc[i] + half_chord_m / 2) / length_m,
                     # the rows after the previous grid point, up to this one
                     "force_normal_N_mean": float(ts["force_normal_N"].iloc[prev + 1:i + 1].mean()),
                     "bonds_broken": int((br_steps <= s).sum()),
                     "largest_piece_grains": int(pieces[0]) if len(pieces) else 0,
                     "largest_pieces": " ".join(str(int(n)) for n in pieces[:4]),  # grains of the four largest
                     "pieces": int((pieces >= min_grains).sum()),
                     "grains_in_pieces": int(pieces[pieces >= min_grains].sum())})
    return pd.DataFrame(rows)


def piece_at_dumps(run_dir: Path, parsed: Path) -> pd.DataFrame:
    """At each dumped step: the largest piece's grains, the mean, extent, smallest and largest of its grain centres
    (mm) and the contact census."""
    from deckgen.chips import bond_components
    from deckgen.contacts import census_of_parsed
    from deckgen.parse.dump import iter_frames

    bonds, br_steps, br_pairs = _bond_record(run_dir, parsed)
    rows = []
    for fr in iter_frames(run_dir / "atoms.dump.gz", ["id", "type", "radius", "x", "y", "z"]):
        rock = fr.data[fr.data["type"] == 1]
        label, sizes, body = bond_components(bonds, br_pairs[br_steps <= fr.timestep], rock["id"].to_numpy(np.int64))
        order = np.argsort(sizes)[::-1]
        big = next((int(c) for c in order if c != body), None)
        row = {"step": fr.timestep, "largest_piece_grains": int(sizes[big]) if big is not None else 0}
        if big is not None:
            xyz = rock.loc[label == big, ["x", "y", "z"]].to_numpy(float) * 1e3
            for k, ax in enumerate("xyz"):  # of the grain centres
                row[f"piece_centre_{ax}_mm"] = float(xyz[:, k].mean())
                row[f"piece_extent_{ax}_mm"] = float(np.ptp(xyz[:, k]))
                row[f"piece_min_{ax}_mm"], row[f"piece_max_{ax}_mm"] = float(xyz[:, k].min()), float(xyz[:, k].max())
        rows.append(row)
    census = census_of_parsed(run_dir, parsed)[["step", "grains_touching", "grains_touching_body", "grains_touching_chip",
                                                "grains_touching_debris", "force_z_hertz_N", "force_z_hertz_chip_N",
                                                "detached_share_z_1"]]
    return pd.DataFrame(rows).merge(census, on="step", how="left")


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("run", type=Path, help="folder X with X/run and X/parsed")
    p.add_argument("--out", type=Path, help="write the timeline CSV here (and *_dumps.csv beside it)")
    p.add_argument("--grid", type=int, default=200, help="grid steps along the cut")
    p.add_argument("--min-grains", type=int, default=10, help="smallest piece counted in pieces / grains_in_pieces")
    args = p.parse_args(argv)
    run_dir, parsed = args.run / "run", args.run / "parsed"
    for f in (run_dir / "spec.json", parsed / "summary.json", parsed / "timeseries.parquet", parsed / "broken.parquet"):
        if not f.is_file():
            raise SystemExit(f"{f}: missing (fix: deckgen render/run into X/run and deckgen parse X/run --out X/parsed)")
    t = timeline(run_dir, parsed, args.grid, args.min_grains)
    d = piece_at_dumps(run_dir, parsed)
    if args.out:
        t.to_csv(args.out, index=False, float_format="%.6g")
        d.to_csv(args.out.with_name(args.out.stem + "_dumps.csv"), index=False, float_format="%.6g")
    final = int(t["largest_piece_grains"].iloc[-1])
    for n in sorted({10, 25, 50, final}):
        hit = t[t["largest_piece_grains"] >= n]
        if len(hit):
            r = hit.iloc[0]
            print(f"largest piece >= {n} grains first at step {int(r['step'])}, patch centre {r['patch_centre_1']:.3f} "
                  f"of the block, {int(r['bonds_broken'])} bonds broken")
    w = _compare().window_table([parsed])
    if len(w):  # a run too short for the patch windows has none
        print(w[["patch_lo_1", "force_normal_N_mean_steady", "force_normal_N_sem_steady"]].round(1).to_string(index=False))
    with pd.option_context("display.width", 200, "display.max_columns", 30):
        print(d.round(2).to_string(index=False))
    return 0


def _compare():
    from deckgen.scriptload import load_script

    return load_script(Path(__file__).resolve().parent / "compare.py", "shell_held_compare")


if __name__ == "__main__":
    sys.exit(main())
