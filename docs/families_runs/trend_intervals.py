"""Every recorded family report's trends with the 95 % interval of their change, beside the seed's change (session 25).

A trend that is "not resolved" (p > 0.05) can still say something: if the interval of its change excludes the seed's
change, the reduced runs rule out the seed's size, not only fail to find a slope. This re-fits the trends of each
recorded ``family_table.csv`` under docs/families_runs (deckgen.families.trend_table, the same fit the reports use)
and writes ``trend_intervals.csv`` here: report folder, trend, runs, change along the pooled line and its 95 %
interval, the seed's change and whether it lies inside (``seed_change_in_ci95``). ``slope_as_recorded`` checks the
re-fit against the report's own trends.csv (False where the report predates a change of the trend's filter; empty for a
trend defined after the report was written).

    python docs/families_runs/trend_intervals.py
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import pandas as pd

from deckgen.families import trend_table

HERE = Path(__file__).resolve().parent
COLS = ["report", "family", "trend", "runs", "groups", "change_1", "change_1_ci95_low", "change_1_ci95_high",
        "seed_change_1", "seed_change_in_ci95", "p_value", "sign_as_seed", "slope_as_recorded"]


def intervals(root: Path = HERE) -> pd.DataFrame:
    rows = []
    for rec in sorted(root.rglob("trends.csv")):
        table_path = rec.parent / "family_table.csv"
        if not table_path.is_file():
            continue
        recorded = pd.read_csv(rec)
        family = str(recorded["family"].iloc[0])
        fit = trend_table(family, pd.read_csv(table_path))
        fit = fit[fit["runs"] >= 3]
        old = recorded.set_index("trend")["slope"]
        for r in fit.itertuples():
            as_rec = bool(np.isclose(r.slope, old[r.trend], rtol=1e-6, atol=1e-12)) if r.trend in old.index else None
            rows.append({"report": str(rec.parent.relative_to(root)), "family": family, "trend": r.trend, "runs": r.runs,
                         "groups": r.groups, "change_1": r.change_1, "change_1_ci95_low": r.change_1_ci95_low,
                         "change_1_ci95_high": r.change_1_ci95_high, "seed_change_1": r.seed_change_1,
                         "seed_change_in_ci95": r.seed_change_in_ci95, "p_value": r.p_value,
                         "sign_as_seed": r.sign_as_seed, "slope_as_recorded": as_rec})
    out = pd.DataFrame(rows, columns=COLS)
    num = ["change_1", "change_1_ci95_low", "change_1_ci95_high", "seed_change_1", "p_value"]
    out[num] = out[num].astype(float).round(4)
    return out


def main() -> None:
    argparse.ArgumentParser(description=__doc__.split("\n")[0]).parse_args()
    t = intervals()
    t.to_csv(HERE / "trend_intervals.csv", index=False)
    with pd.option_context("display.width", 250, "display.max_columns", 30, "display.max_rows", 500):
        print(t.to_string(index=False))


if __name__ == "__main__":
    main()
