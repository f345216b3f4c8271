"""The first piece off and the removed rock of the reduced indentation family against seed 000's chip statements
(session 50).

Seed 000 sec. 4: "All the tests were completed by chip separation, whose dimensions (height, depth) were multiple
times higher of the assumed cut spacing. The volume of rock fragments after the mining process ... was dependent on
the value of cut spacing and mechanical properties of samples. A higher volume of rock fragments was observed for
sandstone samples."

This reads a recorded indentation ``family_table.csv`` (default: the 36 runs of ``indentation_3packings``) and gives,
per run, the first piece's extents over the reduced cut spacing t (x along the disc's edge, y from the free face, z
along the push; measured at the grains' initial places, deckgen.chips.detachment) and its bulk volume over t^3; then
the counts and fits the docs quote: sandstone against concrete in the 18 matched (D, t, packing) pairs, and OLS
fits of each volume on the seed's t with rock x D group effects (the family trends' groups), with the change from
t 15 to 25 mm as the mean of the fitted values at both ends.

    python docs/families_runs/shell_held/indentation_pieces.py [family_table.csv]
"""
from __future__ import annotations

import argparse
from pathlib import Path

import pandas as pd
import statsmodels.formula.api as smf

HERE = Path(__file__).resolve().parent
TABLE = HERE / "indentation_3packings" / "family_table.csv"
PAIR = ["disc_diameter_full_mm", "cut_spacing_full_mm", "packing_seed"]
VOLUMES = ("detached_piece_volume_m3", "removed_volume_m3", "largest_chip_volume_m3")


def per_run(table: pd.DataFrame) -> pd.DataFrame:
    """One row per run: the first piece's extents over the reduced t, its largest axis and volume over t^3."""
    t_red = table["cut_spacing_mm"] * 1e-3
    out = table[["case", "rock", *PAIR, "detached_piece_grains", "largest_chip_grains", *VOLUMES]].copy()
    ext = table[[f"detached_piece_extent_{a}_m" for a in "xyz"]]
    for a in "xyz":
        out[f"extent_{a}_over_t_1"] = table[f"detached_piece_extent_{a}_m"] / t_red
    out["largest_extent_over_t_1"] = ext.max(axis=1) / t_red
    out["largest_axis"] = ext.to_numpy().argmax(axis=1)
    out["largest_axis"] = out["largest_axis"].map(dict(enumerate("xyz")))
    out["piece_volume_over_t3_1"] = table["detached_piece_volume_m3"] / t_red**3
    return out


#: the family's reduced block (x length, y width, z height) in mm; the free face is y = -width / 2
BLOCK_MM = (100 / 3, 25.0, 20.0)
#: a face within this of a piece's zone (its grains' spheres at their initial places) counts as touched
TOUCH_MM = 0.25
#: the base is held by freezing the grains whose centres lie within 2 r_max (1.98 mm here) of it (the deck's fix_zmin
#: region), so a free piece's spheres reach down to about 1 mm only: a piece whose zone comes within the held layer's
#: thickness of the base counts as reaching it
BASE_MM = 2.0


def touches(table: pd.DataFrame, block_mm: tuple[float, float, float] = BLOCK_MM) -> pd.DataFrame:
    """Which faces of the block each run's first piece touches: the free face (y min), the top (z max, pushed), an
    x end (either; free faces), the held base layer (z min, :data:`BASE_MM`) and the fixed back face (y max)."""
    length, width, height = block_mm
    lo = {a: table[f"detached_piece_min_{a}_m"] * 1e3 for a in "xyz"}
    hi = {a: table[f"detached_piece_max_{a}_m"] * 1e3 for a in "xyz"}
    return pd.DataFrame({"free_face": lo["y"] <= -width / 2 + TOUCH_MM, "top": hi["z"] >= height - TOUCH_MM,
                         "x_end": (lo["x"] <= TOUCH_MM) | (hi["x"] >= length - TOUCH_MM),
                         "base": lo["z"] <= BASE_MM, "back": hi["y"] >= width / 2 - TOUCH_MM})


def pairs_above(table: pd.DataFrame, column: str) -> tuple[int, int, float]:
    """Matched (D, t, packing) pairs where sandstone's ``column`` is above concrete's: count, pairs, median ratio."""
    p = table.pivot_table(index=PAIR, columns="rock", values=column)
    ratio = p["sandstone"] / p["concrete"]
    return int((ratio > 1).sum()), int(len(p)), float(ratio.median())


def t_fit(table: pd.DataFrame, column: str) -> dict[str, float]:
    """OLS of ``column`` on the seed's t with rock x D group effects: slope per mm of t, its 95 % interval, p and the
    change from t 15 to 25 mm (mean fitted value at 25 over that at 15, minus 1)."""
    f = smf.ols(f"{column} ~ cut_spacing_full_mm + C(rock) * C(disc_diameter_full_mm)", data=table).fit()
    lo, hi = f.conf_int().loc["cut_spacing_full_mm"]
    m15 = f.predict(table.assign(cut_spacing_full_mm=15)).mean()
    m25 = f.predict(table.assign(cut_spacing_full_mm=25)).mean()
    return {"slope_per_mm": float(f.params["cut_spacing_full_mm"]), "ci95_low": float(lo), "ci95_high": float(hi),
            "p_value": float(f.pvalues["cut_spacing_full_mm"]), "change_1": float(m25 / m15 - 1), "runs": int(f.nobs)}


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("table", nargs="?", type=Path, default=TABLE)
    table = pd.read_csv(ap.parse_args(argv).table)
    runs = per_run(table)
    pd.set_option("display.width", 200)
    print(runs.drop(columns=list(VOLUMES)).round(2).to_string(index=False))
    print(f"\nfirst piece: median largest extent / t {runs['largest_extent_over_t_1'].median():.2f}; medians x, y, z / t "
          + ", ".join(f"{runs[f'extent_{a}_over_t_1'].median():.2f}" for a in "xyz")
          + f"; largest along x in {int((runs['largest_axis'] == 'x').sum())} of {len(runs)}")
    faces = touches(table).assign(t=table["cut_spacing_full_mm"])
    print("first pieces touching each face of the block, by t:\n" + faces.groupby("t").sum().to_string())
    for col in ("detached_piece_volume_m3", "removed_volume_m3"):
        n, of, med = pairs_above(table, col)
        print(f"sandstone above concrete, {col}: {n} of {of} pairs (median ratio {med:.2f})")
    for col in VOLUMES:
        f = t_fit(table, col)
        print(f"{col} with t: {f['change_1']:+.0%} from 15 to 25 mm, slope {f['slope_per_mm']:.3g} per mm "
              f"(95 % {f['ci95_low']:.3g} to {f['ci95_high']:.3g}), p {f['p_value']:.3g}, {f['runs']} runs")


if __name__ == "__main__":
    main()
