"""The 66 mm wide block against the family's 42 mm block at r 250 mm (session 28).

Reads the wide-block report (report/family_table.csv, the diagnostic runs as variants of the family cases) and the
28-run family table (../rotary_reduced_7packings/family_table.csv) and prints, for F_n, F_r and F_r/F_n: the mean and
standard deviation at r 250 mm on each block width, a Welch t-test of the difference (scipy), and, for the packings run
at both r 250 and r 1000 mm on the wide block, the change from r 250 to r 1000 mm. Each block width has its own packing
realisation for a seed, so the two widths are compared as groups, not pair by pair.

    python docs/families_runs/rotary_wide66/compare.py
"""
from __future__ import annotations

from pathlib import Path

import pandas as pd
from scipy import stats

HERE = Path(__file__).resolve().parent
COLUMNS = {"F_n N": "force_normal_N_mean_steady", "F_r N": "force_rolling_N_mean_steady",
           "F_r/F_n": "rolling_to_normal_ratio_1"}


def compare(wide_csv: Path = HERE / "report" / "family_table.csv",
            narrow_csv: Path = HERE.parent / "rotary_reduced_7packings" / "family_table.csv") -> pd.DataFrame:
    """One row per quantity: r 250 mm on each width (mean, sd, n), Welch's t-test, and the wide block's r 1000/r 250."""
    wide, narrow = pd.read_csv(wide_csv), pd.read_csv(narrow_csv)
    w250, n250 = (t[t["rotary_radius_full_mm"] == 250] for t in (wide, narrow))
    w1000 = wide[wide["rotary_radius_full_mm"] == 1000].set_index("packing_seed")
    both = w250.set_index("packing_seed").loc[w1000.index]
    rows = []
    for name, col in COLUMNS.items():
        test = stats.ttest_ind(w250[col], n250[col], equal_var=False)
        rows.append({"quantity": name,
                     "wide_r250_mean": w250[col].mean(), "wide_r250_sd": w250[col].std(), "wide_r250_n": len(w250),
                     "narrow_r250_mean": n250[col].mean(), "narrow_r250_sd": n250[col].std(), "narrow_r250_n": len(n250),
                     "welch_t": test.statistic, "welch_p": test.pvalue,
                     "wide_r1000_over_r250_same_packing": (w1000[col] / both[col]).round(3).tolist(),
                     "packings_r1000": w1000.index.tolist()})
    return pd.DataFrame(rows)


if __name__ == "__main__":
    with pd.option_context("display.width", 200, "display.max_columns", 20):
        print(compare().round(3).to_string(index=False))
