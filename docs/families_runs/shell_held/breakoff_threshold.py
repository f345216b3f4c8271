"""How the indentation break-off depends on its size threshold (session 51).

deckgen.chips.detachment calls the first break step that frees a piece of at least ``DETACH_MIN_GRAINS`` (25)
grains the break-off, and reads the destructive force as the largest F_n up to it. Session 49 checked 10, 50 and 100
grains on 24 runs by hand and wrote the counts into the docs only. This records the break-off at 10, 25, 50 and 100
grains for every recorded run of the reduced indentation family (36 runs, ``indentation_3packings``) and of the larger
block (``indentation_block``), and fits the destructive force's t-trend at each threshold with the family's own fit
(deckgen.families.trend_table: rock x D groups).

Two steps. With ``--runs`` it reads run folders (each ``NAME/run`` with specimen.data and spec.json, and
``NAME/parsed`` from ``deckgen parse``: timeseries and broken bonds), runs the break-off search at each threshold and
writes ``breakoff_threshold.csv`` here (one row per run and threshold). Without it, it reads that CSV and prints the
counts and fits the docs quote; the 25-grain rows must reproduce the recorded family tables' break-off exactly.

    python docs/families_runs/shell_held/breakoff_threshold.py --runs /work/runs49 /work/runs50 /work/runs51 /work/runs52
    python docs/families_runs/shell_held/breakoff_threshold.py
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
import pandas as pd

HERE = Path(__file__).resolve().parent
CSV = HERE / "breakoff_threshold.csv"
#: the recorded family tables the rows belong to, by block
TABLES = {"family": HERE / "indentation_3packings" / "family_table.csv",
          "big": HERE.parent / "indentation_block" / "report" / "family_table.csv"}
#: fixed thresholds in grains, and thresholds as the first piece's bulk volume in units of the reduced t^3 (a fixed
#: grain count is a larger piece relative to t at t 15 mm than at 25 mm: 100 grains are about 3.1 t^3 at t 15 mm and
#: 0.7 t^3 at t 25 mm); labels "n<grains>" and "t3x<fraction>"
GRAINS = (10, 25, 50, 100)
T3_FRACTIONS = (0.25, 0.5, 1.0, 2.0)
THRESHOLDS = (*(f"n{k}" for k in GRAINS), *(f"t3x{f:g}" for f in T3_FRACTIONS))
KEYS = ("detachment_step", "penetration_at_failure_m", "force_normal_N_destructive", "detached_piece_grains")


def compute(roots: list[Path]) -> pd.DataFrame:
    """The break-off at each threshold for every run folder under ``roots`` that one of :data:`TABLES` records. A t^3
    threshold f is ceil(f t^3 / b) grains, b the mean bulk volume of one bonded grain of the run (its solid volume over
    the packing's solid fraction, as the chip volumes)."""
    import math

    from deckgen.chips import detachment, initial_bonds, initial_positions

    names, spacing = {}, {}
    for block in TABLES:
        for run, t_mm in recorded(block)["cut_spacing_mm"].items():
            names[run], spacing[run] = block, float(t_mm) * 1e-3
    rows = []
    for root in roots:
        for folder in sorted(p for p in root.iterdir() if p.name in names):
            run = folder / "run"
            bonds, initial = initial_bonds(run), initial_positions(run)
            phi = float(json.loads((run / "spec.json").read_text())["derived"]["packing"]["solid_fraction"])
            broken = pd.read_parquet(folder / "parsed" / "broken.parquet")
            ts = pd.read_parquet(folder / "parsed" / "timeseries.parquet")
            grains = initial[initial["id"].isin(np.unique(bonds))]
            bulk = float((4.0 / 3.0 * math.pi * grains["radius"] ** 3).mean()) / phi
            t3 = spacing[folder.name] ** 3
            plan = [(f"n{k}", k) for k in GRAINS] + [(f"t3x{f:g}", math.ceil(f * t3 / bulk)) for f in T3_FRACTIONS]
            for label, k in plan:
                d = detachment(bonds, broken, ts, min_grains=k, initial=initial, solid_fraction=phi)
                rows.append({"run": folder.name, "block": names[folder.name], "threshold": label, "min_grains": k,
                             "grain_bulk_volume_m3": bulk, "cut_spacing_m": spacing[folder.name],
                             **{key: d[key] for key in KEYS}})
            print(f"{folder.name}: done")
    return pd.DataFrame(rows)


def recorded(block: str) -> pd.DataFrame:
    """The recorded family table of a block, indexed by run name."""
    t = pd.read_csv(TABLES[block])
    return t.set_index(t["variant_case"] if "variant_case" in t.columns else t["case"])


def check_25(rows: pd.DataFrame) -> int:
    """Runs whose 25-grain row differs from the recorded table (step, F_n, penetration, piece grains); 0 expected."""
    bad = 0
    for block, g in rows[rows["threshold"] == "n25"].groupby("block"):
        rec = recorded(block).loc[g["run"], list(KEYS)].reset_index(drop=True)
        mine = g[list(KEYS)].reset_index(drop=True)
        bad += int((~np.isclose(mine.to_numpy(float), rec.to_numpy(float), rtol=1e-9, equal_nan=True)).any(axis=1).sum())
    return bad


def with_threshold(rows: pd.DataFrame, block: str, label: str) -> pd.DataFrame:
    """The block's recorded family table with the break-off columns of one threshold."""
    t = recorded(block)
    r = rows[(rows["block"] == block) & (rows["threshold"] == label)].set_index("run")
    t = t.loc[r.index].copy()
    for key in KEYS:
        t[key] = r[key]
    return t.reset_index(drop=True)


def fits(rows: pd.DataFrame) -> pd.DataFrame:
    """The destructive F_n's t-trend (family fit) per block, rock subset and threshold; beside it the same fit of the
    25-grain destructive forces on only the runs that free a piece at the threshold (what dropping runs alone does)."""
    from deckgen.families import trend_table

    out = []
    for block in TABLES:
        n25 = with_threshold(rows, block, "n25")
        for label in THRESHOLDS:
            t = with_threshold(rows, block, label)
            for rock in ("all", *sorted(t["rock"].unique())):
                sub = t if rock == "all" else t[t["rock"] == rock]
                if rock != "all" and sub["rock"].nunique() == t["rock"].nunique():
                    continue  # one rock only: the same fit as "all"
                f = trend_table("indentation_asymmetric", sub).set_index("trend").loc["fn_destructive_rises_with_t"]
                # the 25-grain forces on the runs that free a piece at this threshold: the change from dropping runs
                same_runs = n25[t["force_normal_N_destructive"].notna() & ((n25["rock"] == rock) | (rock == "all"))]
                g = trend_table("indentation_asymmetric", same_runs).set_index("trend").loc["fn_destructive_rises_with_t"]
                out.append({"block": block, "rock": rock, "threshold": label, "runs": int(f["runs"]),
                            "change_1": f["change_1"], "ci95_low": f["change_1_ci95_low"],
                            "ci95_high": f["change_1_ci95_high"], "p_value": f["p_value"],
                            "change_1_n25_same_runs": g["change_1"], "p_value_n25_same_runs": g["p_value"]})
    return pd.DataFrame(out)


def same_as_25(rows: pd.DataFrame) -> pd.DataFrame:
    """Per block and threshold: the grains asked for (range), runs with a break-off, and runs whose destructive F_n
    is the 25-grain one's (all, and at the seed's t 15 / 20 / 25 mm), and runs that free no such piece at all (per t;
    a run neither the same nor without a piece had its break-off moved later). A larger threshold can only move the break-off
    later (a piece of k grains is also one of fewer), so the destructive force can only rise with it, up to the
    whole-push peak."""
    out = []
    for block, g in rows.groupby("block"):
        ref = g[g["threshold"] == "n25"].set_index("run")["force_normal_N_destructive"]
        t_full = recorded(block)["cut_spacing_full_mm"]
        for label in THRESHOLDS:
            h = g[g["threshold"] == label].set_index("run")
            fn = h["force_normal_N_destructive"]
            same = pd.Series(np.isclose(fn, ref.loc[fn.index], rtol=1e-12), index=fn.index)
            tt = t_full.loc[fn.index].to_numpy()
            by_t = same.groupby(tt).sum()
            never = fn.isna().groupby(tt).sum()
            out.append({"block": block, "threshold": label, "min_grains": f"{h['min_grains'].min()}-{h['min_grains'].max()}",
                        "runs": len(h), "with_breakoff": int(fn.notna().sum()), "same_fn_as_25": int(same.sum()),
                        "same_at_t15/20/25": "/".join(str(int(by_t.get(t, 0))) for t in (15, 20, 25)),
                        "none_at_t15/20/25": "/".join(str(int(never.get(t, 0))) for t in (15, 20, 25))})
    return pd.DataFrame(out)


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", nargs="+", type=Path, help="roots of run folders: compute and write the CSV")
    args = ap.parse_args(argv)
    if args.runs:
        rows = compute(args.runs)
        rows.to_csv(CSV, index=False)
        print(f"wrote {CSV} ({rows['run'].nunique()} runs)")
    rows = pd.read_csv(CSV)
    print(f"25-grain rows differing from the recorded tables: {check_25(rows)} of {rows['run'].nunique()}")
    pd.set_option("display.width", 200)
    print(same_as_25(rows).to_string(index=False))
    print(fits(rows).round(3).to_string(index=False))


if __name__ == "__main__":
    main()
