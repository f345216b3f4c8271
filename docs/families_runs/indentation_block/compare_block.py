"""The reduced indentation cases on a larger block against the same cases on the family's block (session 50).

The concrete D 150 and 160 mm family cases (session 50) and the sandstone D 150 (session 51) and D 160 mm ones
(session 52), t 15/20/25 mm on packings 12345, 202, 303, were run on a block 50 x 25 x 30 mm
(``*_big.yaml`` here: x and z x1.5) besides the family's 33.3 x 25 x 20 mm. This reads the two recorded family tables
(``report/family_table.csv`` of the big runs, made with ``deckgen.families report --variants``, and
``shell_held/indentation_3packings/family_table.csv``) and gives, per case, both blocks' peak and destructive F_n,
penetration at failure and first piece (grains, volume, extents, and whether its zone touches a face of its block),
then the big/small ratios (geometric means with a t interval over the cases) and the destructive F_n's change
with t on each block (OLS with the packing as group), per rock and D; and, where both rocks ran, sandstone against
concrete on each block in the matched (D, t, packing) cases (seed 000: "a higher volume of rock fragments was observed
for sandstone samples"), and, per rock, D 160 against D 150 mm in the matched (t, packing) cases (seed 000: the
destructive force rises with D).

The packings of the two blocks share no grain position (the larger block is packed anew from the same seed), so a
ratio mixes the block's effect with a packing's scatter.

    python docs/families_runs/indentation_block/compare_block.py
"""
from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np
import pandas as pd
import statsmodels.formula.api as smf
from scipy import stats

from deckgen.scriptload import load_script

HERE = Path(__file__).resolve().parent
BIG = HERE / "report" / "family_table.csv"
SMALL = HERE.parent / "shell_held" / "indentation_3packings" / "family_table.csv"
#: block size (x length, y width, z height) in mm, by the block's label
BLOCKS = {"small": (100 / 3, 25.0, 20.0), "big": (50.0, 25.0, 30.0)}
PIECES = load_script(HERE.parent / "shell_held" / "indentation_pieces.py")
QUANTITIES = ("force_normal_N_peak", "force_normal_N_destructive", "penetration_at_failure_m", "detached_piece_grains",
              "detached_piece_volume_m3", "removed_volume_m3")


def paired(big: pd.DataFrame, small: pd.DataFrame) -> pd.DataFrame:
    """One row per case: both blocks' quantities (``_big``, ``_small``) and which faces the pieces touch."""
    b = big.set_index("case")  # a variant report's ``case`` is the family case (the run's name is ``variant_case``)
    s = small.set_index("case").loc[b.index]
    out = pd.DataFrame({"cut_spacing_full_mm": b["cut_spacing_full_mm"], "packing_seed": b["packing_seed"]})
    for q in QUANTITIES:
        out[f"{q}_big"], out[f"{q}_small"] = b[q], s[q]
    for block, t in (("big", b), ("small", s)):
        tt = PIECES.touches(t.reset_index(), BLOCKS[block])
        tt.index = t.index
        for c in tt.columns:
            out[f"touches_{c}_{block}"] = tt[c]
    return out.reset_index()


def family_rows(small: pd.DataFrame, big: pd.DataFrame) -> pd.DataFrame:
    """The family block's runs of the cases in ``big`` (its ``case`` column), in that order."""
    return small.set_index("case").loc[big["case"]].reset_index()


def ratio(p: pd.DataFrame, q: str) -> dict[str, float]:
    """Geometric mean of big/small over the cases with its t 95 % interval, and how many are above 1."""
    r = np.log(p[f"{q}_big"] / p[f"{q}_small"]).dropna()  # a run without a break-off has no destructive force
    n = len(r)
    half = stats.t.ppf(0.975, n - 1) * r.std(ddof=1) / math.sqrt(n)
    return {"geometric_mean": float(np.exp(r.mean())), "ci95_low": float(np.exp(r.mean() - half)),
            "ci95_high": float(np.exp(r.mean() + half)), "above_1": int((r > 0).sum()), "cases": n}


def _d_term(table: pd.DataFrame) -> str:
    """The disc diameter and the rock as group terms of a fit, each when the runs have more than one."""
    return "".join(f" + C({c})" for c in ("disc_diameter_full_mm", "rock") if table[c].nunique() > 1)


def t_change(table: pd.DataFrame, y: str) -> dict[str, float]:
    """OLS of ``y`` on the seed's t with the packing (and D and the rock, when there are two) as group: slope per mm of t, p, and the change from t 15 to 25 mm
    (mean fitted values; NaN where the fitted mean at 15 mm is not positive, so that a ratio has no scale)."""
    f = smf.ols(f"{y} ~ cut_spacing_full_mm + C(packing_seed){_d_term(table)}", data=table).fit()
    m15 = f.predict(table.assign(cut_spacing_full_mm=15)).mean()
    m25 = f.predict(table.assign(cut_spacing_full_mm=25)).mean()
    return {"slope_per_mm": float(f.params["cut_spacing_full_mm"]), "p_value": float(f.pvalues["cut_spacing_full_mm"]),
            "change_1": float(m25 / m15 - 1) if m15 > 0 else float("nan"), "runs": int(f.nobs)}


def family_fits(table: pd.DataFrame) -> pd.DataFrame:
    """The family's own trend fits (deckgen.families.trend_table: group effects rock x D, here one group) of the
    peak and destructive F_n with t: runs, change from t 15 to 25 mm with its 95 % interval, p."""
    from deckgen.families import trend_table

    fit = trend_table("indentation_asymmetric", table).set_index("trend")
    return fit.loc[["fn_rises_with_t", "fn_destructive_rises_with_t"],
                   ["runs", "change_1", "change_1_ci95_low", "change_1_ci95_high", "p_value"]]


def block_t_interaction(big: pd.DataFrame, nine: pd.DataFrame, y: str, log: bool = False) -> float:
    """p of the block x t interaction: does ``y`` (its log with ``log``) change with t differently on the two blocks
    (OLS over both blocks' runs, y ~ t * block, with D and the rock as groups when there are two)?"""
    both = pd.concat([nine.assign(block="small"), big.assign(block="big")], ignore_index=True)
    both["y"] = np.log(both[y]) if log else both[y]
    f = smf.ols(f"y ~ cut_spacing_full_mm * C(block){_d_term(both)}", data=both).fit()
    return float(f.pvalues["cut_spacing_full_mm:C(block)[T.small]"])


def subsets(big: pd.DataFrame) -> dict[str, pd.DataFrame]:
    """The big-block runs by rock and disc diameter, each rock over both D (where it has two), and all of them."""
    out = {f"{rock} D {d:g} mm": g for (rock, d), g in big.groupby(["rock", "disc_diameter_full_mm"])}
    for rock, g in big.groupby("rock"):
        if g["disc_diameter_full_mm"].nunique() > 1:
            out[f"{rock}, both D"] = g
    if big["rock"].nunique() > 1:
        out["all"] = big
    return out


#: the factors that name a case of the family, and the quantities compared between matched cases
CASE_FACTORS = ("rock", "disc_diameter_full_mm", "cut_spacing_full_mm", "packing_seed")
PAIR_QUANTITIES = ("removed_volume_m3", "detached_piece_volume_m3", "force_normal_N_destructive", "force_normal_N_peak")


def matched_ratios(table: pd.DataFrame, factor: str, high, low) -> pd.DataFrame:
    """``factor`` = ``high`` over ``low`` in the cases that ran at both and agree in every other factor: per quantity
    the cases, how many are higher at ``high``, and the geometric mean ratio with its t 95 % interval."""
    key = [c for c in CASE_FACTORS if c != factor]
    h = table[table[factor] == high].set_index(key)
    lo = table[table[factor] == low].set_index(key)
    both = h.index.intersection(lo.index)
    rows = []
    for q in PAIR_QUANTITIES:
        r = np.log(h.loc[both, q] / lo.loc[both, q]).dropna()
        n = len(r)
        half = stats.t.ppf(0.975, n - 1) * r.std(ddof=1) / math.sqrt(n) if n > 1 else float("nan")
        rows.append({"quantity": q, "cases": n, "higher": int((r > 0).sum()),
                     "geometric_mean": float(np.exp(r.mean())), "ci95_low": float(np.exp(r.mean() - half)),
                     "ci95_high": float(np.exp(r.mean() + half))})
    return pd.DataFrame(rows)


def rock_pairs(table: pd.DataFrame) -> pd.DataFrame:
    """Sandstone over concrete in the (D, t, packing) cases both rocks ran (``sandstone_higher``: cases higher in
    sandstone)."""
    return matched_ratios(table, "rock", "sandstone", "concrete").rename(columns={"higher": "sandstone_higher"})


def d_pairs(table: pd.DataFrame) -> pd.DataFrame:
    """D 160 over D 150 mm in the (rock, t, packing) cases run with both discs (``d160_higher``: cases higher at
    D 160 mm; seed 000: the destructive force rises with D)."""
    return matched_ratios(table, "disc_diameter_full_mm", 160, 150).rename(columns={"higher": "d160_higher"})


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.parse_args(argv)
    big_all, small = pd.read_csv(BIG), pd.read_csv(SMALL)
    for label, big in subsets(big_all).items():
        print(f"\n===== {label}: {len(big)} big-block runs =====")
        report(big, small)
    if big_all["rock"].nunique() > 1:
        both = big_all.loc[big_all["disc_diameter_full_mm"].isin(
            big_all.loc[big_all["rock"] == "sandstone", "disc_diameter_full_mm"])]
        nine = family_rows(small, both)
        for name, t in (("small", nine), ("big", both)):
            print(f"\n===== sandstone / concrete, {name} block (cases both rocks ran on the big block) =====")
            print(rock_pairs(t).round(3).to_string(index=False))
    for rock, g in big_all.groupby("rock"):
        if g["disc_diameter_full_mm"].nunique() > 1:
            nine = family_rows(small, g)
            for name, t in (("small", nine), ("big", g)):
                print(f"\n===== {rock}, D 160 / D 150 mm, {name} block (cases run with both discs on the big block) =====")
                print(d_pairs(t).round(3).to_string(index=False))


def report(big: pd.DataFrame, small: pd.DataFrame) -> None:
    """Print the comparison of these big-block runs with the same cases on the family's block."""
    p = paired(big, small)
    pd.set_option("display.width", 250)
    show = ["case"] + [f"{q}_{b}" for q in QUANTITIES[:4] for b in ("small", "big")]
    print(p[show].round(4).to_string(index=False))
    print()
    for q in QUANTITIES:
        r = ratio(p, q)
        print(f"{q}: big/small x{r['geometric_mean']:.2f} (95 % {r['ci95_low']:.2f}-{r['ci95_high']:.2f}), "
              f"above 1 in {r['above_1']} of {r['cases']}")
    for block in ("small", "big"):
        print(f"{block} block, first pieces touching: " + ", ".join(
            f"{c} {int(p[f'touches_{c}_{block}'].sum())}" for c in ("free_face", "top", "x_end", "base", "back")))
    nine = family_rows(small, p)
    for name, t in (("small", nine), ("big", big)):
        print(f"{name} block, family trend fits (rock x D groups):\n{family_fits(t).round(3).to_string()}")
        print(f"{name} block, mean abs(F_s)/F_n at the destructive force "
              f"{t['lateral_to_normal_ratio_destructive_1'].mean():.2f}; destructive F_n = whole-push peak in "
              f"{int((t['force_normal_N_destructive'] >= t['force_normal_N_peak']).sum())} of {len(t)}")
    still = big[PIECES.touches(big, BLOCKS["big"])["x_end"].to_numpy()]
    print(f"big block without its run(s) whose piece reaches an x end ({', '.join(still['variant_case'])}):\n"
          + family_fits(big.drop(still.index)).round(3).to_string())
    print(f"block x t interaction p: destructive F_n {block_t_interaction(big, nine, 'force_normal_N_destructive'):.2f}, "
          f"log first-piece volume {block_t_interaction(big, nine, 'detached_piece_volume_m3', log=True):.3f}")
    for name, t in (("small", nine), ("big", big)):
        for y in ("force_normal_N_destructive", "force_normal_N_peak", "detached_piece_volume_m3"):
            c = t_change(t, y)
            means = t.groupby("cut_spacing_full_mm")[y].mean()
            print(f"{name} block, {y} with t: {c['change_1']:+.0%}, slope {c['slope_per_mm']:.3g} per mm "
                  f"(p {c['p_value']:.3g}, {c['runs']} runs); means at t 15/20/25: "
                  + " / ".join(f"{v:.4g}" for v in means))


if __name__ == "__main__":
    main()
