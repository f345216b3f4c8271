"""Table of the smooth-cone cuts at the seed's speed (x1) beside the same cuts at x4 (session 23).

For each x1 run folder (with parsed/ from `deckgen parse <run> --out <run>/parsed`) one row: the sliding whole-cycle
mean of |F| (the family's ODC trend metric), the plain steady mean, the spread of one-cycle means over their start
(every window of 1/22.5 s inside the steady window: one cycle at 22.5 Hz, three at 67.5 Hz, the same 22.2 mm of
travel for the straight cut), contact fraction and broken bonds; then the x4 run of the same family case from
smoothcone_family/family_table.csv (session 11) and the ratios to the straight cut of each speed.

Usage: python x1_table.py <x1 run dir>... [--x4 ../odc_smooth/smoothcone_family/family_table.csv] --out x1_table.csv
"""
import argparse
import json
import sys
from pathlib import Path

import numpy as np
import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "odc_smooth"))
from cycle_spread import spread  # noqa: E402  (the one-cycle window means, slid over the steady window)

PERIOD_S = 1.0 / 22.5  # one cycle of the slowest x1 oscillation
FAMILY_CASE = {"odc_red_s10_long_smoothcone_x1": "odc_red_s10_long_smoothcone",
               "odc_red_s16_long_smoothcone_x1": "odc_red_s16_long_smoothcone",
               "odc_red_s103_long_smoothcone_x1": "odc_red_s103_long_smoothcone"}


def row(run: Path) -> dict:
    s = json.loads((run / "parsed" / "summary.json").read_text())
    w = spread(run, PERIOD_S)
    return {"case": s["case"], "family_case": FAMILY_CASE.get(s["case"], ""),
            "velocity_ratio_nu_1": s["velocity_ratio_nu_1"], "omega_rad_s": s["omega_rad_s"],
            "cutter_speed_m_s": s["cutter_speed_m_s"],
            "force_magnitude_N_mean_cycles_sliding": s["force_magnitude_N_mean_cycles_sliding"],
            "force_magnitude_N_mean_steady": s["force_magnitude_N_mean_steady"],
            "force_magnitude_N_window_mean_min": float(w["min"]), "force_magnitude_N_window_mean_max": float(w["max"]),
            "contact_fraction_steady_1": s["contact_fraction_steady_1"], "bonds_broken": s["bonds_broken"],
            "broken_fraction_1": s["broken_fraction_1"], "n_grains": s["n_grains"], "wall_s": s["wall_s"],
            "grains_inside_cutter_final": s["grains_inside_cutter_final"]}


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("runs", nargs="+", type=Path)
    p.add_argument("--x4", type=Path, default=Path(__file__).parent.parent / "odc_smooth/smoothcone_family/family_table.csv")
    p.add_argument("--out", type=Path, required=True)
    a = p.parse_args()
    tab = pd.DataFrame([row(r) for r in a.runs])
    x4 = pd.read_csv(a.x4).set_index("case")
    for col in ("force_magnitude_N_mean_cycles_sliding", "force_magnitude_N_mean_steady", "contact_fraction_steady_1"):
        tab[f"x4_{col}"] = [x4[col].get(c, np.nan) for c in tab["family_case"]]
    straight = tab["velocity_ratio_nu_1"].isna()
    for pre in ("", "x4_"):
        col = f"{pre}force_magnitude_N_mean_cycles_sliding"
        ref = tab.loc[straight, col].iloc[0] if straight.any() else np.nan
        tab[f"{pre}ratio_to_straight_1"] = tab[col] / ref
    tab.to_csv(a.out, index=False)
    with pd.option_context("display.width", 200, "display.max_columns", 30):
        print(tab.drop(columns=["family_case", "omega_rad_s"]).round(3).T)


if __name__ == "__main__":
    main()
