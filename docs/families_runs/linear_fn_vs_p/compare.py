"""F_n and the penetration on the reduced linear block (session 31).

The reduced linear family's mean F_n does not rise with p (S 100 mm, three packings: 240 N at p 1.9 mm, 221 N at
p 7.6 mm; seed 001 +76 %, the CSM model x2.4). This compares three configurations of the S 100 mm cases at p 1.9 and
7.6 mm (full-scale values; reduced 0.95 and 3.8 mm) on the family's three packings (12345, 202, 303):

- ``family``: the family cases (neighbour grooves at +-12.5 mm, block 26 x 33 x 12 mm), from the 48-run report; the
  sems of packings 202 and 303 from their session-26 runs re-parsed in session 31 (``family_session26_sem``: the same
  means), packing 12345 (session 22, run folders gone) has none;
- ``unrel``: the same cases without the neighbour grooves (an unrelieved cut), ``unrel/``;
- ``shell0p5``: the family cases with a shell twice as dense (``cutter.shell_spacing`` 0.5), ``shell0p5/`` (session 32
  added S 25, 51 and 76 mm: ``--spacing``);
- ``shell0p35``: the same with ``shell_spacing`` 0.35 (p 1.9 mm, packing 12345 only), ``shell0p35/``;
- ``block45``: the family cases on a block 45 mm long (start, travel and window unchanged; p 1.9 mm, packing 12345
  only), ``block45/``.

Prints one row per run (F_n, F_r with their standard errors, F_r/F_n, broken fraction, grains inside the cutter
at the end, the volume of chips and debris over the groove's, grains, wall) and one row per
configuration: the ratio p 7.6 / p 1.9 of the packing means of F_n and F_r with its standard error, each packing's own
ratio, and the CSM model's ratio for the same cases (:mod:`deckgen.gap.fast` at the cutting card's targets, softened as
the cases are) as the yardstick. The standard error of a packing mean is the larger of the packings' scatter
(std / sqrt(n)) and the runs' own sems (sqrt(sum sem^2) / n; a run without a sem takes the median relative sem of the
others); the ratio's adds the two means' relative errors in quadrature. Verdict (rule written before the runs,
session 31 predictions): "rises" if the ratio is >= 1.3 and 2 s.e. above 1, "flat" if 1 lies within 2 s.e.

    python docs/families_runs/linear_fn_vs_p/compare.py
    python docs/families_runs/linear_fn_vs_p/compare.py --climb <parsed folder> ...   # F_n along the travel, per run
    python docs/families_runs/linear_fn_vs_p/compare.py --spacing   # session 32: shell0p5 at S 25-100 mm vs the family
"""
from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import numpy as np
import pandas as pd

from deckgen.results import steady_mask

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[2]
FAMILY48 = HERE.parent / "linear_reduced_bpm_granite_replicates_48" / "family_table.csv"
FAMILY_SEM = HERE / "family_session26_sem" / "family_table.csv"
CONFIGS = ("family", "unrel", "shell0p5", "shell0p35", "block45")
PENETRATIONS = (1.9, 7.6)  # full-scale mm
PACKINGS = (12345, 202, 303)
FORCES = {"F_n": "force_normal_N", "F_r": "force_rolling_N"}
#: the cutting card's targets (cases/materials/cutting/colorado_red_granite.yaml) and the cases' softening
CARD_UCS_MPA, CARD_BTS_MPA, SOFTENING = 110.6, 13.83, 14.521


def table(config: str) -> pd.DataFrame:
    """Every run of one configuration at p 1.9 and 7.6 mm, at every spacing it was run at."""
    if config == "family":
        t = pd.read_csv(FAMILY48)
        sem = pd.read_csv(FAMILY_SEM).set_index("case")
        t = t.set_index("case")
        for col in (f"{c}_sem_steady" for c in FORCES.values()):
            t[col] = sem[col].reindex(t.index)
        t = t.reset_index()
    else:
        path = HERE / config / "family_table.csv"
        if not path.is_file():
            raise SystemExit(f"{path}: no report yet (fix: run the {config} diagnostics and report them, docs/families.md, section F_n and the penetration)")
        t = pd.read_csv(path)
    return t[t["penetration_full_mm"].isin(PENETRATIONS)]


def runs(config: str, spacing: float = 100) -> pd.DataFrame:
    """The runs of one configuration at spacing S (full-scale mm) at p 1.9 and 7.6 mm, indexed by
    (penetration_full_mm, packing_seed)."""
    t = table(config)
    t = t[t["spacing_full_mm"] == spacing]
    return t.set_index(["penetration_full_mm", "packing_seed"]).sort_index()


def mean_and_se(values: pd.Series, sems: pd.Series) -> tuple[float, float]:
    """Mean over packings and its standard error: the larger of the scatter's std/sqrt(n) and sqrt(sum sem^2)/n, a
    missing sem taken as the median relative sem of the others."""
    v = values.to_numpy(float)
    s = sems.to_numpy(float)
    rel = s / np.abs(v)
    if np.isfinite(rel).any():
        s = np.where(np.isfinite(s), s, np.nanmedian(rel) * np.abs(v))
    n = len(v)
    scatter = v.std(ddof=1) / math.sqrt(n) if n > 1 else float("nan")
    own = math.sqrt(float(np.sum(s**2))) / n if np.isfinite(s).all() else float("nan")
    return float(v.mean()), float(np.nanmax([scatter, own]))


def ratio_and_se(lo: tuple[float, float], hi: tuple[float, float]) -> tuple[float, float]:
    """The ratio hi / lo of two (mean, s.e.) pairs and its s.e. (the relative errors added in quadrature)."""
    (m0, e0), (m1, e1) = lo, hi
    return m1 / m0, abs(m1 / m0) * math.hypot(e0 / m0, e1 / m1)


def verdict(ratio: float, se: float) -> str:
    if ratio >= 1.3 and ratio - 2 * se > 1:
        return "rises"
    if abs(ratio - 1) <= 2 * se:
        return "flat"
    return "falls" if ratio < 1 else "rises (< 1.3)"


def csm_ratio(config: str, spacing: float = 100) -> float:
    """The CSM model's F_n(p 7.6) / F_n(p 1.9) for the configuration's packing-12345 cases at spacing S."""
    from deckgen.gap.data import flat_case
    from deckgen.gap.fast import predict_row
    from deckgen.spec import load_case

    fn = []
    for p in ("p1p9", "p7p6"):
        f = (ROOT / "cases" / "linear_ccs" / "reduced" / f"lin_red_s{spacing:g}_{p}.yaml" if config == "family"
             else HERE / f"lin_red_s{spacing:g}_{p}_{config}.yaml")
        row = flat_case(load_case(f))
        row["material.targets.ucs_MPa"] = CARD_UCS_MPA / SOFTENING
        row["material.targets.bts_MPa"] = CARD_BTS_MPA / SOFTENING
        fn.append(predict_row(row)["force_normal_N_mean_steady"])
    return fn[1] / fn[0]


def per_run(configs: tuple[str, ...] = CONFIGS, spacing: float = 100) -> pd.DataFrame:
    """One row per run at spacing S; ``F_n/family`` is its F_n over the family run of the same S, packing and p."""
    rows = []
    family = runs("family", spacing)["force_normal_N_mean_steady"]
    for c in configs:
        t = runs(c, spacing)
        for (p, k), r in t.iterrows():
            rows.append({"config": c, "p_full_mm": p, "packing": k, "grains": int(r["n_grains"]),
                         "wall_min": r["wall_s"] / 60,
                         **{f"{q} N": r[f"{col}_mean_steady"] for q, col in FORCES.items()},
                         "F_n/family": r["force_normal_N_mean_steady"] / family[p, k],
                         **{f"{q} sem": r[f"{col}_sem_steady"] for q, col in FORCES.items()},
                         "F_r/F_n": r["rolling_to_normal_ratio_1"], "broken": r["broken_fraction_1"],
                         "bonds_broken": int(r["bonds_broken"]), "inside": r["grains_inside_cutter_final"],
                         # (chips + debris) volume over the groove's: SE_kinematic / SE_chips = Q_chips / Q_kinematic
                         "removed/groove": r["specific_energy_kinematic_J_m3"] / r["specific_energy_chips_J_m3"]})
    return pd.DataFrame(rows)


def ratios(configs: tuple[str, ...] = CONFIGS, spacing: float = 100) -> pd.DataFrame:
    """Per configuration and force at spacing S: packing means at p 1.9 and 7.6 mm with s.e., their ratio with s.e. and
    verdict, each packing's own ratio, and the CSM model's F_n ratio."""
    rows = []
    for c in configs:
        t = runs(c, spacing)
        if not all(p in t.index.get_level_values(0) for p in PENETRATIONS):
            continue  # a configuration run at one penetration only
        for q, col in FORCES.items():
            lo = t.loc[PENETRATIONS[0]]
            hi = t.loc[PENETRATIONS[1]]
            m0, e0 = mean_and_se(lo[f"{col}_mean_steady"], lo[f"{col}_sem_steady"])
            m1, e1 = mean_and_se(hi[f"{col}_mean_steady"], hi[f"{col}_sem_steady"])
            ratio, se = ratio_and_se((m0, e0), (m1, e1))
            own = (hi[f"{col}_mean_steady"] / lo[f"{col}_mean_steady"]).reindex(list(PACKINGS))
            rows.append({"config": c, "force": q, "mean p1.9 N": m0, "se p1.9": e0, "mean p7.6 N": m1, "se p7.6": e1,
                         "ratio 7.6/1.9": ratio, "se": se, "verdict": verdict(ratio, se),
                         **{f"k{k}": v for k, v in own.items()},
                         "CSM ratio": csm_ratio(c, spacing) if q == "F_n" else float("nan")})
    return pd.DataFrame(rows)


#: the spacings of the family (full-scale mm)
SPACINGS = (25, 51, 76, 100)


def by_spacing(configs: tuple[str, ...] = ("family", "shell0p5")) -> pd.DataFrame:
    """Per configuration, force and p: the packing mean (with s.e., :func:`mean_and_se`) at each spacing the
    configuration was run at, and the ratio S 100 / S 25 with its s.e. and :func:`verdict` (session 32: does F_n still
    rise with S once the shell stops leaking grains into the tip?)."""
    rows = []
    for c in configs:
        t = table(c)
        for q, col in FORCES.items():
            for p in PENETRATIONS:
                row: dict = {"config": c, "force": q, "p_full_mm": p}
                stats = {}
                for s in SPACINGS:
                    at = t[(t["spacing_full_mm"] == s) & (t["penetration_full_mm"] == p)]
                    if len(at):
                        stats[s] = mean_and_se(at[f"{col}_mean_steady"], at[f"{col}_sem_steady"])
                        row[f"S{s} N"], row[f"se S{s}"] = stats[s]
                if SPACINGS[0] in stats and SPACINGS[-1] in stats:
                    row["ratio S100/S25"], row["se"] = ratio_and_se(stats[SPACINGS[0]], stats[SPACINGS[-1]])
                    row["verdict"] = verdict(row["ratio S100/S25"], row["se"])
                rows.append(row)
    return pd.DataFrame(rows)


def matched_trends(config: str = "shell0p5") -> pd.DataFrame:
    """The family's linear trends (:func:`deckgen.families.trend_table`) fitted on a configuration's runs and on the
    family runs of the same cases (same S, p and packing), side by side."""
    from deckgen.families import trend_table

    var = pd.read_csv(HERE / config / "family_table.csv")
    fam = table("family")
    fam = fam[fam["case"].isin(var["variant_case"].str.removesuffix(f"_{config}"))]
    rows = []
    for name, t in (("family", fam), (config, var)):
        fit = trend_table("linear_ccs", t)
        for _, r in fit.iterrows():
            rows.append({"config": name, "trend": r["trend"], "runs": r["runs"], "change": r["change_1"],
                         "ci95 low": r["change_1_ci95_low"], "ci95 high": r["change_1_ci95_high"],
                         "p_value": r["p_value"], "seed": r["seed_change_1"]})
    return pd.DataFrame(rows)


#: fractions of the travel :func:`climb` averages F_n over (the family window is 0.77-0.99)
CLIMB_BINS = ((0.4, 0.6), (0.6, 0.8), (0.8, 1.0))


def climb(parsed: list[Path]) -> pd.DataFrame:
    """Mean F_n of each run over :data:`CLIMB_BINS` of the travel and the last bin over the first: how much the force
    still climbs along the travel (a run-in or the fixed end face ahead)."""
    rows = []
    for d in map(Path, parsed):
        s = json.loads((d / "summary.json").read_text())
        ts = pd.read_parquet(d / "timeseries.parquet", columns=["time_s", "force_normal_N"])
        means = [ts.loc[steady_mask(ts["time_s"], s["cut_duration_s"], w), "force_normal_N"].mean() for w in CLIMB_BINS]
        rows.append({"run": s["case"], **{f"F_n {a:g}-{b:g}": m for (a, b), m in zip(CLIMB_BINS, means)},
                     "last/first": means[-1] / means[0]})
    return pd.DataFrame(rows)


def main() -> None:
    pd.set_option("display.width", 200)
    if len(sys.argv) > 1 and sys.argv[1] == "--spacing":
        for sp in SPACINGS[:-1]:
            print(per_run(("shell0p5",), sp).round(3).to_string(index=False))
        print()
        print(by_spacing().round(3).to_string(index=False))
        print()
        print(matched_trends().round(4).to_string(index=False))
        return
    if len(sys.argv) > 2 and sys.argv[1] == "--climb":
        print(climb([Path(a) for a in sys.argv[2:]]).round(3).to_string(index=False))
        return
    have = tuple(c for c in CONFIGS if c == "family" or (HERE / c / "family_table.csv").is_file())
    print(per_run(have).round(3).to_string(index=False))
    print()
    print(ratios(have).round(3).to_string(index=False))


if __name__ == "__main__":
    main()
