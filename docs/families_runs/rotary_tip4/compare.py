"""The disc tip four times as wide against the family tip, on the same grains (session 29).

Reads the tip4 report (report/family_table.csv: the diagnostic runs as variants of the family cases) and the
session-28 66 mm block report (../rotary_wide66/report/family_table.csv). The tip4 cases are the wide66 cases with the
tip 6.25 mm instead of 1.5625 mm (hub 12.2 mm instead of 7.5 mm) and nothing else: the packing seed and the block are
the same, so the grains and bonds are identical and each tip4 run pairs with the wide66 run of the same packing and r.

Prints one row per (packing, r) with F_n, F_r, F_s and F_r/F_n for both tips and the tip4/narrow ratio, and one row per
packing and tip with r 250 mm over r 1000 mm of F_n, F_r and abs(F_s): the ratio the groove offset is tested on (it is
1.60 tip widths at r 250 mm with the family tip and 0.40 with tip4, as at full scale).

    python docs/families_runs/rotary_tip4/compare.py
    python docs/families_runs/rotary_tip4/compare.py --bins <parsed folder> ...   # F_n along the travel, per run
    python docs/families_runs/rotary_tip4/compare.py --block40   # the same ratios for tip4 on the 40 mm block
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pandas as pd

from deckgen.results import mean_standard_error, steady_mask

HERE = Path(__file__).resolve().parent
COLUMNS = {"F_n N": "force_normal_N_mean_steady", "F_r N": "force_rolling_N_mean_steady",
           "F_s N": "force_side_N_mean_steady", "F_r/F_n": "rolling_to_normal_ratio_1"}
KEYS = ["packing_seed", "rotary_radius_full_mm"]
#: fractions of the travel: the run-in, then the steady window 0.3-1.0 in four equal bins
TRAVEL_BINS = ((0.1, 0.3), (0.3, 0.475), (0.475, 0.65), (0.65, 0.825), (0.825, 1.0))
#: the forces :func:`travel_bins` bins (name: timeseries.csv column)
BIN_FORCES = {"F_n N": "force_normal_N", "F_r N": "force_rolling_N"}
#: the tip4 runs on the 40 mm block (session 30): new packings of the same seeds, so no pairing with the 26 mm block runs
BLOCK40 = HERE.parent / "rotary_tip4_block40" / "report" / "family_table.csv"


def paired(tip4_csv: Path = HERE / "report" / "family_table.csv",
           narrow_csv: Path = HERE.parent / "rotary_wide66" / "report" / "family_table.csv") -> pd.DataFrame:
    """One row per tip4 run (packing, r): each quantity for the family tip (``narrow``; NaN where the 66 mm block has no
    narrow-tip run of that packing and r: packing 404 at r 1000 mm), tip4 and their ratio (``tip4/narrow``)."""
    tip4 = pd.read_csv(tip4_csv).set_index(KEYS)
    narrow = pd.read_csv(narrow_csv).set_index(KEYS).reindex(tip4.index)
    ran = narrow["n_grains"].notna()
    if (tip4.loc[ran, "n_grains"] != narrow.loc[ran, "n_grains"]).any() or \
            (tip4.loc[ran, "n_bonds_initial"] != narrow.loc[ran, "n_bonds_initial"]).any():
        raise ValueError("the tip4 and wide66 runs of a packing must share their grains and bonds")
    out = pd.DataFrame(index=tip4.index)
    for name, col in COLUMNS.items():
        out[f"{name} narrow"], out[f"{name} tip4"] = narrow[col], tip4[col]
        out[f"{name} tip4/narrow"] = tip4[col] / narrow[col]
    out["wall_s narrow"], out["wall_s tip4"] = narrow["wall_s"], tip4["wall_s"]
    return out.sort_index()


def report_forces(csv: Path, label: str) -> pd.DataFrame:
    """The forces of one report (family_table.csv) as columns ``<quantity> <label>``, indexed by (packing, r): the
    form :func:`radius_ratios` reads, for a report with no narrow-tip twin (the 40 mm block, ``../rotary_tip4_block40``)."""
    t = pd.read_csv(csv).set_index(KEYS).sort_index()
    out = {f"{name} {label}": t[col] for name, col in COLUMNS.items()} | {f"wall_s {label}": t["wall_s"]}
    # the standard errors of the steady means, where the report has them (summaries parsed since session 30)
    sem = {name: col.removesuffix("_mean_steady") + "_sem_steady" for name, col in COLUMNS.items()}
    out |= {f"{name} sem {label}": t[col] for name, col in sem.items() if col in t}
    return pd.DataFrame(out)


def radius_ratios(table: pd.DataFrame | None = None, tips: tuple[str, ...] = ("narrow", "tip4")) -> pd.DataFrame:
    """r 250 mm over r 1000 mm of F_n, F_r and abs(F_s), per packing and tip (where that tip ran at both radii); with
    the standard errors of the two means (``<F> sem <tip>`` columns) also the ratio's, ``<F> r250/r1000 se``
    (first-order propagation: ratio * sqrt(rel. error at r 250 ** 2 + rel. error at r 1000 ** 2))."""
    t = paired() if table is None else table
    rows = []
    for seed in sorted(t.index.get_level_values(0).unique()):
        for tip in tips:
            try:
                at250, at1000 = t.loc[(seed, 250)], t.loc[(seed, 1000)]
            except KeyError:
                continue
            if pd.isna([at250[f"F_n N {tip}"], at1000[f"F_n N {tip}"]]).any():
                continue
            rows.append({"packing_seed": seed, "tip": tip,
                         "F_n r250/r1000": at250[f"F_n N {tip}"] / at1000[f"F_n N {tip}"],
                         "F_r r250/r1000": at250[f"F_r N {tip}"] / at1000[f"F_r N {tip}"],
                         "abs(F_s) r250/r1000": abs(at250[f"F_s N {tip}"] / at1000[f"F_s N {tip}"])})
            for f in ("F_n", "F_r"):
                if f"{f} N sem {tip}" in t:
                    rel = [at[f"{f} N sem {tip}"] / at[f"{f} N {tip}"] for at in (at250, at1000)]
                    rows[-1][f"{f} r250/r1000 se"] = rows[-1][f"{f} r250/r1000"] * float(np.hypot(*rel))
    return pd.DataFrame(rows)


def travel_bins(parsed: list[Path], window: tuple[float, float] = (0.3, 1.0)) -> pd.DataFrame:
    """Mean F_n and F_r (N) of each parsed run folder (``deckgen parse`` output: timeseries.csv, summary.json) over the
    fractions of the travel in :data:`TRAVEL_BINS` (each as a steady window of ``deckgen parse``), one row per run.

    ``<F> sem/mean`` is the standard error of the mean over ``window`` (the steady window) relative to that mean, from
    the series' integrated autocorrelation time (:func:`deckgen.results.mean_standard_error`); ``tau mm`` is that time
    as travel of the cutter (F_n's), ``n_eff`` the number of independent samples it leaves in the window."""
    rows = []
    for p in map(Path, parsed):
        s = json.loads((p / "summary.json").read_text())
        ts = pd.read_csv(p / "timeseries.csv", usecols=["time_s", "cutter_advance_m", *BIN_FORCES.values()])
        bins = {(a, b): steady_mask(ts["time_s"], s["cut_duration_s"], (a, b)) for a, b in TRAVEL_BINS}
        steady = ts[steady_mask(ts["time_s"], s["cut_duration_s"], window)]
        row = {"case": s["case"]}
        for name, col in BIN_FORCES.items():
            row.update({f"{name} {a:g}-{b:g}": ts.loc[mask, col].mean() for (a, b), mask in bins.items()})
            err = mean_standard_error(steady[col])
            row[f"{name} sem/mean"] = err["sem"] / steady[col].mean()
            if name == "F_n N":
                step_mm = 1e3 * float(np.median(np.diff(steady["cutter_advance_m"])))
                row["tau mm"], row["n_eff"] = err["tau_rows"] * step_mm, err["n_eff"]
        rows.append(row)
    return pd.DataFrame(rows)


if __name__ == "__main__":
    with pd.option_context("display.width", 220, "display.max_columns", 30):
        if sys.argv[1:2] == ["--bins"]:
            print(travel_bins(sys.argv[2:]).round(2).to_string(index=False))
        elif sys.argv[1:2] == ["--block40"]:
            t = report_forces(BLOCK40, "tip4b40")
            print(t.round(3).to_string())
            print()
            print(radius_ratios(t, ("tip4b40",)).round(3).to_string(index=False))
        else:
            t = paired()
            print(t.round(3).to_string())
            print()
            print(radius_ratios(t).round(3).to_string(index=False))
