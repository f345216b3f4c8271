"""Recorded runs against the same cases on the fixed deck, where the cutter's shell is held in y (session 34).

Until session 34 the straight, indentation and untilted eccentric branches of ``templates/lammps/cutting.lmp.j2`` moved
the shell with ``fix move variable v_dx NULL v_dz v_vx NULL v_vz``. LAMMPS integrates a component whose displacement
and velocity are both NULL from the force on each atom, so every shell sphere was free to drift sideways under the
rock's push (the rotary and tilted branches gave all six variables and were right). The runs here are recorded family
cases (and session 32's finer-shell and session 31's unrelieved diagnostics) rendered again after the fix and run
unchanged otherwise: the same grains and bonds as the recorded run (checked), so each pair differs only in the deck's y
motion of the shell. Session 35 added 16 linear family cases (22 in ``linear``), the unrelieved pairs and the 45 mm
block at p 1.9 and 7.6 mm (``linear_block45``, no recorded p 7.6 mm run to pair with) and a 24 mm high block
(``linear_h24``, new). Session 36 brought ``linear`` to 43 cases and added the contact census, the windows and the
S 100 mm debris-removal runs (``linear_debris``); session 37 the last five cases (48) and the whole packing-12345
family with run.debris_removal_every; session 38 the grain-size pairs by block width (``GRAIN_PAIRS``) and the family
cases with the side faces held (``linear_yfix``); session 39 the grain-size pair on the 20 mm block with its side
faces held (``linear_w20_yfix``, ``linear_w20_fine_yfix``); session 40 the 33 mm block with a band of fine grains along
the cut and its coarse reference (``linear_unrel_band``, ``linear_unrel_s016``), and each window's standard error
within the run (``window_table``; ``pair_window_ratio_errors``); session 41 the band pair, its coarse reference and
the r 0.3 mm shell pair on packings 202 and 303 (``packing_replicates``, ``packing_spread``); session 42 the same
three pairs on packing 404, added to the recorded reports and CSVs by ``add_packing.py`` (the earlier run folders are
gone), and ``piece_timeline.py``, when a piece breaks off a run against its F_n; session 43 the band pair and its coarse
reference on packing 505 (``add_packing.py``) and ``groove_fill.py``, the rock the disc's groove holds along the cut.

    python docs/families_runs/shell_held/compare.py
    python docs/families_runs/shell_held/compare.py --windows docs/families_runs/shell_held/linear_windows.csv <parsed>...
    python docs/families_runs/shell_held/compare.py --debris-windows docs/families_runs/shell_held/linear_debris_windows.csv \
        <parsed of the packing-12345 debris-removal runs>...
    python docs/families_runs/shell_held/compare.py --yfix-windows docs/families_runs/shell_held/linear_yfix_windows.csv \
        <parsed of the side-faces-held runs>...
    python docs/families_runs/shell_held/compare.py --contacts docs/families_runs/shell_held/linear_contacts.csv <X>...
    python docs/families_runs/shell_held/compare.py --pair-windows docs/families_runs/shell_held/linear_grain_pair_windows.csv \
        <parsed of the 33 mm unrelieved, narrow and 20 mm runs>...

(``--windows``, ``--debris-windows``, ``--yfix-windows`` and ``--pair-windows`` overwrite their CSV with the runs passed
alone.)

Prints, per kind, one row per case (recorded, held, held / recorded) and the geometric mean of held / recorded with
its 95 % interval (``../rotary_shell0p5/compare.py``'s ``gain_row``); then, where both shells ran on the fixed deck,
the finer shell's gain over the default one; F_n at p 7.6 / 1.9 mm with and without the neighbour grooves; seed 001's
eq. 7 form and the family's trends on the held runs beside the recorded runs of the same cases.
"""
from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Callable

import pandas as pd

HERE = Path(__file__).resolve().parent
RUNS = HERE.parent
#: kind -> (recorded report (old deck), report of the held-shell runs, key column, metrics)
KINDS = {
    "linear": (RUNS / "linear_reduced_bpm_granite_replicates_48", HERE / "linear", "case",
               ("force_normal_N_mean_steady", "force_rolling_N_mean_steady", "rolling_to_normal_ratio_1")),
    "linear shell0p5": (RUNS / "linear_fn_vs_p" / "shell0p5", HERE / "linear_shell0p5", "variant_case",
                        ("force_normal_N_mean_steady", "force_rolling_N_mean_steady", "rolling_to_normal_ratio_1")),
    "linear unrelieved": (RUNS / "linear_fn_vs_p" / "unrel", HERE / "linear_unrel", "variant_case",
                          ("force_normal_N_mean_steady", "force_rolling_N_mean_steady", "rolling_to_normal_ratio_1")),
    "indentation": (RUNS / "indentation_reduced", HERE / "indentation", "case",
                    ("force_normal_N_peak", "force_side_N_peak", "lateral_to_normal_ratio_1")),
}
EXTRA = ("grains_inside_cutter_final", "bonds_broken", "broken_fraction_1", "wall_s")
#: steady windows of :func:`window_table`: the contact-patch centre between lo and lo + 0.2 of the block length (the
#: family cases average over lo = 0.4, seed 001's middle of the block, which ends where the travel ends)
PATCH_WINDOWS = (0.1, 0.2, 0.3, 0.4)
#: the held linear runs' F_n and F_r over each of PATCH_WINDOWS (written by ``--windows``)
WINDOWS_CSV = HERE / "linear_windows.csv"
#: the debris-removal runs of the packing-12345 family over the same windows, keyed by their family case (``--windows``
#: on their parsed folders writes them as ``*_debris``; ``--debris-windows`` strips the suffix)
DEBRIS_WINDOWS_CSV = HERE / "linear_debris_windows.csv"
#: the side-faces-held runs over the same windows, keyed by their family case (``--yfix-windows``)
YFIX_WINDOWS_CSV = HERE / "linear_yfix_windows.csv"
#: the grain-size pairs on unrelieved blocks (S 100 mm, p 1.9 and 7.6 mm), keyed by (block width mm, side faces free or
#: held, packing seed): per grain size (``coarse`` r 0.7-1.0 mm; ``fine`` r 0.35-0.5 mm throughout; ``band`` r 0.35-0.5
#: mm in packing.fine_zone along the cut, coarse elsewhere) the case-name tail after ``lin_red_s100_p{1p9,7p6}`` and the
#: report (``--variants``; one family case takes one variant per report, so one report per grain size). 10 mm: session
#: 37 (the fine pair stopped for time); 20 mm free: session 38 (the fine pair stopped: the block splits a side off); 20 mm
#: with the y faces held (``_yfix``): session 39, the fine runs stopped at the end of the patch window 0.2-0.4 (compare
#: them over the windows, :func:`pair_window_ratios`, not over their case window), and the coarse pair on packing 202
#: as well (no fine pair; its runs are in the same report); 33 mm free: session 40, the band pair and its coarse
#: reference with the same r 0.16 mm shell (``_s016``; session 35's ``_unrel`` runs have the r 0.3 mm shell), on
#: packings 12345 and 202 (one report per grain size holds both), 303 (session 41), 404 (session 42; not a family
#: packing: add_packing.py), 505 (session 43, no r 0.3 mm pair), 606 (session 44, the band pair; its coarse reference
#: session 46; no r 0.3 mm pair), 707 (session 45, no r 0.3 mm pair), 808 (session 46, the band pair; its coarse reference session 47; no r 0.3 mm pair)
#: and 909 (session 48, the band pair, the ninth packing that tests session 47's stretch readings, then its coarse
#: reference; no r 0.3 mm pair)
GRAIN_PAIRS = {
    (10, "free", 12345): {"coarse": ("_narrow", HERE / "linear_narrow"),
                          "fine": ("_narrow_fine", HERE / "linear_narrow_fine")},
    (20, "free", 12345): {"coarse": ("_w20", HERE / "linear_w20"), "fine": ("_w20_fine", HERE / "linear_w20_fine")},
    (20, "held", 12345): {"coarse": ("_w20_yfix", HERE / "linear_w20_yfix"),
                          "fine": ("_w20_fine_yfix", HERE / "linear_w20_fine_yfix")},
    (20, "held", 202): {"coarse": ("_k202_w20_yfix", HERE / "linear_w20_yfix")},
    (33, "free", 12345): {"coarse": ("_unrel_s016", HERE / "linear_unrel_s016"),
                          "band": ("_unrel_band", HERE / "linear_unrel_band")},
    (33, "free", 202): {"coarse": ("_k202_unrel_s016", HERE / "linear_unrel_s016"),
                        "band": ("_k202_unrel_band", HERE / "linear_unrel_band")},
    (33, "free", 303): {"coarse": ("_k303_unrel_s016", HERE / "linear_unrel_s016"),
                        "band": ("_k303_unrel_band", HERE / "linear_unrel_band")},
    (33, "free", 404): {"coarse": ("_k404_unrel_s016", HERE / "linear_unrel_s016"),
                        "band": ("_k404_unrel_band", HERE / "linear_unrel_band")},
    (33, "free", 505): {"coarse": ("_k505_unrel_s016", HERE / "linear_unrel_s016"),
                        "band": ("_k505_unrel_band", HERE / "linear_unrel_band")},
    (33, "free", 606): {"coarse": ("_k606_unrel_s016", HERE / "linear_unrel_s016"),
                        "band": ("_k606_unrel_band", HERE / "linear_unrel_band")},
    (33, "free", 707): {"coarse": ("_k707_unrel_s016", HERE / "linear_unrel_s016"),
                        "band": ("_k707_unrel_band", HERE / "linear_unrel_band")},
    (33, "free", 808): {"coarse": ("_k808_unrel_s016", HERE / "linear_unrel_s016"),
                        "band": ("_k808_unrel_band", HERE / "linear_unrel_band")},
    (33, "free", 909): {"coarse": ("_k909_unrel_s016", HERE / "linear_unrel_s016"),
                        "band": ("_k909_unrel_band", HERE / "linear_unrel_band")}}
#: the 33 mm block's coarse pair with session 31's r 0.3 mm shell (``*_unrel.yaml``, run on the fixed deck in sessions
#: 35, 41 and 42), per :data:`GRAIN_PAIRS` key: the shell-radius reference of :func:`packing_replicates`
SHELL03_TAILS = {(33, "free", 12345): "_unrel", (33, "free", 202): "_k202_unrel", (33, "free", 303): "_k303_unrel",
                 (33, "free", 404): "_k404_unrel"}
#: the grain-size pairs' runs and the 33 mm unrelieved block's (r 0.3 mm shell, packings 12345, 202, 303 and 404) over
#: PATCH_WINDOWS (``--pair-windows``)
PAIR_WINDOWS_CSV = HERE / "linear_grain_pair_windows.csv"
#: ``deckgen.contacts`` census of every dumped step of the held linear runs (written by ``--contacts``)
CONTACTS_CSV = HERE / "linear_contacts.csv"
#: report (``--variants``) of the family cases run with run.debris_removal_every (S 100 mm on packings 12345 and 202 in
#: session 36; the whole packing-12345 family in session 37)
DEBRIS_DIR = HERE / "linear_debris"
#: report (``--variants``) of the family cases run with specimen.fixed_faces zmin, xmax, ymin, ymax (session 38)
YFIX_DIR = HERE / "linear_yfix"


def load_gain_row():
    """``gain_row`` of ../rotary_shell0p5/compare.py (geometric mean of paired ratios with its 95 % t interval)."""
    from deckgen.scriptload import load_script

    return load_script(RUNS / "rotary_shell0p5" / "compare.py", "rotary_shell0p5_compare").gain_row


def _has(kind: str) -> bool:
    """Whether the held-shell report of ``kind`` exists."""
    return (KINDS[kind][1] / "family_table.csv").is_file()


def _case(base: str, packing: int, tail: str = "") -> str:
    """The case name of ``base`` (e.g. ``lin_red_s100_p1p9``) on ``packing``: the default packing 12345 has no suffix."""
    return f"{base}{'' if packing == 12345 else f'_k{packing}'}{tail}"


def _value(t: pd.DataFrame, name: str, col: str) -> float:
    """``t.loc[name, col]``, NaN where the case was not re-run."""
    return t.loc[name, col] if name in t.index else float("nan")


def _same_grains_and_bonds(a: pd.DataFrame, b: pd.DataFrame) -> bool:
    """Whether every row of ``a`` has the grain and initial bond counts of the row of ``b`` with the same index (the
    two runs of a pair were rendered from one packing and one bond set)."""
    b = b.reindex(a.index)
    return bool(((a["n_grains"] == b["n_grains"]) & (a["n_bonds_initial"] == b["n_bonds_initial"])).all())


def _held_linear() -> pd.DataFrame:
    """The report table of the held linear family runs (``linear``)."""
    return pd.read_csv(KINDS["linear"][1] / "family_table.csv")


def _same_case_tables(kind: str, min_p_full_mm: float = 0.0) -> tuple[pd.DataFrame, pd.DataFrame]:
    """(recorded, held) report tables of ``kind``, the recorded one cut to the held cases; only cases with a full-scale
    p above ``min_p_full_mm`` (the indentation family has no p: leave 0)."""
    old_dir, new_dir, key, _ = KINDS[kind]
    new = pd.read_csv(new_dir / "family_table.csv")
    if min_p_full_mm:
        new = new[new["penetration_full_mm"] > min_p_full_mm]
    old = pd.read_csv(old_dir / "family_table.csv")
    return old[old[key].isin(new[key])], new


def pairs(kind: str) -> pd.DataFrame:
    """One row per case of ``kind`` run on the held shell: each metric recorded / held and held / recorded (side
    forces as they are: a signed peak), grains inside, bonds broken and wall minutes. Raises unless each pair shares
    its grains and bonds, or when a held run of a packing the old deck ran has no recorded run; held runs of a packing
    the old deck never ran (404 of the unrelieved block, session 42) are left out."""
    old_dir, new_dir, key, metrics = KINDS[kind]
    new_path = new_dir / "family_table.csv"
    if not new_path.is_file():
        raise SystemExit(f"{new_path}: no report yet (fix: run the held-shell re-runs, docs/families.md, section "
                         "\"The cutter shell held in y\")")
    new = pd.read_csv(new_path).set_index(key)
    recorded = pd.read_csv(old_dir / "family_table.csv")
    if "packing_seed" in new and "packing_seed" in recorded:
        # runs of a packing the old deck never ran (session 42's 404) are not re-runs: they have nothing to pair with
        new = new[new["packing_seed"].isin(recorded["packing_seed"])]
    old = recorded.set_index(key).reindex(new.index)
    if old["n_grains"].isna().any():
        raise ValueError(f"{old_dir}: no recorded run for {list(new.index[old['n_grains'].isna()])}")
    if not _same_grains_and_bonds(new, old):
        raise ValueError(f"{kind}: a held-shell run does not share its grains and bonds with the recorded run")
    out = pd.DataFrame(index=new.index)
    if "packing_seed" in new:
        out["packing_seed"] = new["packing_seed"]
    for m in metrics:
        out[f"{m} recorded"], out[f"{m} held"] = old[m], new[m]
        out[f"{m} held/recorded"] = new[m] / old[m]
    for m in EXTRA:
        out[f"{m} recorded"], out[f"{m} held"] = old[m], new[m]
    return out


def summary(kind: str) -> pd.DataFrame:
    """Geometric mean of held / recorded per metric (95 % t interval, p of log ratio = 0) over the cases of ``kind``."""
    gain_row = load_gain_row()
    t = pairs(kind)
    rows = []
    for m in KINDS[kind][3]:
        r = t[f"{m} held/recorded"]
        if (r > 0).all() and len(r) > 1:
            rows.append(gain_row(f"{kind}: {m}", r))
    return pd.DataFrame(rows)


def shell_gain() -> pd.DataFrame:
    """On the fixed deck: the finer shell's F_n, F_r and grains inside beside the default shell's, per packing, and
    fine / default (the shell dependence that is left once the shell cannot drift)."""
    coarse, fine = pairs("linear"), pairs("linear shell0p5")
    coarse = coarse.loc[[c.removesuffix("_shell0p5") for c in fine.index]].set_index("packing_seed")
    fine = fine.set_index("packing_seed")
    out = pd.DataFrame(index=fine.index)
    for m in ("force_normal_N_mean_steady", "force_rolling_N_mean_steady"):
        out[f"{m} default"], out[f"{m} fine"] = coarse[f"{m} held"], fine[f"{m} held"]
        out[f"{m} fine/default"] = fine[f"{m} held"] / coarse[f"{m} held"]
        out[f"{m} fine/default recorded"] = fine[f"{m} recorded"] / coarse[f"{m} recorded"]
    out["inside default"], out["inside fine"] = coarse["grains_inside_cutter_final held"], fine["grains_inside_cutter_final held"]
    return out


def linear_ratios() -> pd.DataFrame:
    """Per packing, the linear family's two trends as ratios of held runs (and of the recorded runs of the same cases):
    F_n at S 100 / S 25 mm (p 1.9 mm) and F_r/F_n at p 7.6 / 1.9 mm (S 100 mm). NaN where a case was not re-run."""
    t = pairs("linear")
    rows = []
    for k in sorted(set(t["packing_seed"])):
        row = {"packing_seed": k}
        for which in ("recorded", "held"):
            fn, frfn = f"force_normal_N_mean_steady {which}", f"rolling_to_normal_ratio_1 {which}"
            row[f"F_n S100/S25 p1.9 {which}"] = (_value(t, _case("lin_red_s100_p1p9", k), fn)
                                                  / _value(t, _case("lin_red_s25_p1p9", k), fn))
            row[f"F_r/F_n p7.6/p1.9 S100 {which}"] = (_value(t, _case("lin_red_s100_p7p6", k), frfn)
                                                       / _value(t, _case("lin_red_s100_p1p9", k), frfn))
        rows.append(row)
    return pd.DataFrame(rows).set_index("packing_seed")


def trends_same_cases(kind: str = "linear") -> pd.DataFrame:
    """The family's trends (``deckgen.families.trend_table``, the report's own fit) on the held runs of ``kind`` and on
    the recorded runs of the same cases, side by side: runs, change over the seed's range with its 95 % interval, p."""
    from deckgen.families import trend_table

    family = {"linear": "linear_ccs", "indentation": "indentation_asymmetric"}[kind]
    old, new = _same_case_tables(kind)
    cols = ["runs", "groups", "change_1", "change_1_ci95_low", "change_1_ci95_high", "p_value", "seed_change_1"]
    out = []
    for which, table in (("recorded", old), ("held", new)):
        t = trend_table(family, table).set_index("trend")[cols]
        out.append(t.add_prefix(f"{which} "))
    return pd.concat(out, axis=1)


def regression_same_cases(min_p_full_mm: float = 0.0) -> pd.DataFrame:
    """Seed 001's eq. 7 form (``deckgen.families.family_regression``: Y = b0 + b1 S + b2 p, reduced mm) fitted on the
    held linear runs and on the recorded runs of the same cases: estimate, standard error, p and R^2 per term. Only
    cases with a full-scale p above ``min_p_full_mm`` (2.0 drops the p 1.9 mm cells, half a grain deep at reduced
    scale)."""
    from deckgen.families import family_regression

    old, new = _same_case_tables("linear", min_p_full_mm)
    cols = ["estimate", "std_error", "p_value", "r_squared", "n_runs"]
    out = []
    for which, table in (("recorded", old), ("held", new)):
        r = family_regression("linear_ccs", table).set_index(["response", "term"])[cols]
        out.append(r.add_prefix(f"{which} "))
    return pd.concat(out, axis=1)


#: a chip of at least this many grains (about 4 % of a family block's ~2400 grains) counts as a large piece broken off
LARGE_CHIP_GRAINS = 100


def large_chip_fit() -> pd.DataFrame:
    """On the 48 held linear runs (free side faces): how many leave a chip of at least :data:`LARGE_CHIP_GRAINS`
    grains, per full-scale p, and seed 001's eq. 7 form for F_n with and without that indicator as a third term
    (OLS; estimate and p per term): whether the runs that break a large piece off make F_n fall with p."""
    import statsmodels.formula.api as smf

    t = _held_linear().assign(S=lambda d: d["spacing_mm"], p=lambda d: d["penetration_mm"],
                              Fn=lambda d: d["force_normal_N_mean_steady"],
                              large=lambda d: (d["largest_chip_grains"] >= LARGE_CHIP_GRAINS).astype(int))
    rows = [{"model": f"large chips at p {p:g} mm", "term": "runs", "estimate": float(g["large"].sum()),
             "p_value": float("nan")} for p, g in t.groupby("penetration_full_mm")]
    for formula in ("Fn ~ S + p", "Fn ~ S + p + large", "large ~ S + p"):
        fit = smf.ols(formula, t).fit()
        rows += [{"model": formula, "term": k, "estimate": float(fit.params[k]), "p_value": float(fit.pvalues[k])}
                 for k in fit.params.index]
    return pd.DataFrame(rows).set_index(["model", "term"])


def fn_p_ratio() -> pd.DataFrame:
    """F_n at p 7.6 / p 1.9 mm at S 100 mm per packing, with the neighbour grooves (the family cases) and without them
    (session 31's unrelieved diagnostics), recorded and held: session 31 read the grooves as what flattens the rise."""
    grooved, unrel = pairs("linear"), pairs("linear unrelieved")
    m = "force_normal_N_mean_steady"
    rows = []
    for k in sorted(set(unrel["packing_seed"])):
        row = {"packing_seed": k}
        for label, t, tail in (("grooved", grooved, ""), ("unrelieved", unrel, "_unrel")):
            for which in ("recorded", "held"):
                lo, hi = (_value(t, _case(f"lin_red_s100_p{p}", k, tail), f"{m} {which}") for p in ("1p9", "7p6"))
                row[f"{label} {which} p1.9 N"], row[f"{label} {which} p7.6 N"] = lo, hi
                row[f"{label} {which} p7.6/p1.9"] = hi / lo
        rows.append(row)
    return pd.DataFrame(rows).set_index("packing_seed")


def window_table(parsed: list[Path]) -> pd.DataFrame:
    """F_n and F_r of each held linear run averaged over every window of :data:`PATCH_WINDOWS` (``families.middle_window``
    from the run's own block, disc, penetration and travel; ``results.steady_mask`` on its parsed series): one row per
    run and window. ``parsed`` are ``deckgen parse`` folders with the run folder beside them as ``../run``."""
    from deckgen.families import middle_window, patch_travel_fraction
    from deckgen.results import mean_standard_error, steady_mask

    rows = []
    for d in map(Path, parsed):
        spec_path = d.parent / "run" / "spec.json"
        if not (d / "summary.json").is_file() or not spec_path.is_file():
            raise SystemExit(f"{d}: needs summary.json and ../run/spec.json (fix: pass the parsed folder of a run "
                             "made by `deckgen render CASE --out X/run` and `deckgen parse X/run --out X/parsed`)")
        s = json.loads((d / "summary.json").read_text())
        case = json.loads(spec_path.read_text())["case"]
        k = case["kinematics"]
        ts = pd.read_parquet(d / "timeseries.parquet", columns=["time_s", "force_normal_N", "force_rolling_N"])
        for lo in PATCH_WINDOWS:
            # a run whose travel was cut short (session 39's fine 20 mm runs) has no row for a window it does not
            # finish; middle_window would clip it to the travel's end and average a part of it
            geometry = (case["specimen"]["length_mm"], 1e3 * s["cutter_radius_m"], k["penetration_mm"],
                        k["start_clearance_mm"], k["travel_mm"])
            if patch_travel_fraction(*geometry, lo + 0.2) > 1.0 + 1e-9:
                continue
            w = middle_window(*geometry, lo, lo + 0.2)
            m = steady_mask(ts["time_s"], s["cut_duration_s"], w)
            fn = ts.loc[m, "force_normal_N"]
            rows.append({"case": s["case"], "patch_lo_1": lo, "window_start_1": w[0], "window_end_1": w[1],
                         "rows": int(m.sum()), "force_normal_N_mean_steady": fn.mean(),
                         "force_rolling_N_mean_steady": ts.loc[m, "force_rolling_N"].mean(),
                         # the scatter within the run (rows are correlated: results.mean_standard_error), not between runs
                         "force_normal_N_sem_steady": mean_standard_error(fn)["sem"]})
    return pd.DataFrame(rows)


def window_fits(windows: pd.DataFrame | None = None) -> pd.DataFrame:
    """Per window of :data:`PATCH_WINDOWS`: seed 001's eq. 7 on the held linear runs' windowed F_n and F_r (S and p
    terms: estimate, p, R^2) and F_n at p 7.6 / 1.9 mm (S 100 mm) as the geometric mean over the packings that ran
    both. Whether the fall of F_n with p belongs to the case's window (the disc's last ~5 mm, near the fixed far end)
    or to the whole cut."""
    import numpy as np

    from deckgen.families import family_regression

    w = pd.read_csv(WINDOWS_CSV) if windows is None else windows
    base = _held_linear()
    rows = []
    for lo, g in w.groupby("patch_lo_1"):
        t = base.drop(columns=["force_normal_N_mean_steady", "force_rolling_N_mean_steady"]).merge(
            g[["case", "force_normal_N_mean_steady", "force_rolling_N_mean_steady"]], on="case")
        fit = family_regression("linear_ccs", t).set_index(["response", "term"])
        row = {"patch_lo_1": lo, "runs": len(t)}
        for resp, short in (("force_normal_N_mean_steady", "F_n"), ("force_rolling_N_mean_steady", "F_r")):
            for term, name in (("spacing_mm", "S"), ("penetration_mm", "p")):
                row[f"{short} {name} N/mm"] = fit.loc[(resp, term), "estimate"]
                row[f"{short} {name} p"] = fit.loc[(resp, term), "p_value"]
            row[f"{short} R2"] = fit.loc[(resp, term), "r_squared"]
        fn = t.set_index("case")["force_normal_N_mean_steady"]
        ratios = [fn[_case("lin_red_s100_p7p6", k)] / fn[_case("lin_red_s100_p1p9", k)]
                  for k in sorted(set(t["packing_seed"]))
                  if _case("lin_red_s100_p7p6", k) in fn and _case("lin_red_s100_p1p9", k) in fn]
        row["F_n p7.6/p1.9 S100"] = float(np.exp(np.mean(np.log(ratios)))) if ratios else float("nan")
        row["packings"] = len(ratios)
        rows.append(row)
    return pd.DataFrame(rows).set_index("patch_lo_1")


def contact_table(runs: list[Path]) -> pd.DataFrame:
    """``deckgen.contacts.census_of_parsed`` of each run folder pair ``X/run``, ``X/parsed`` given as ``X``: one row per
    run and dumped step, with the case and the fraction of the cut's duration."""
    from deckgen.contacts import census_of_parsed

    parts = []
    for d in map(Path, runs):
        s = json.loads((d / "parsed" / "summary.json").read_text())
        t = census_of_parsed(d / "run", d / "parsed")
        t.insert(0, "case", s["case"])
        t.insert(2, "cut_fraction_1", t["time_s"] / s["cut_duration_s"])
        parts.append(t)
    return pd.concat(parts, ignore_index=True)


def contact_means(contacts: pd.DataFrame | None = None, from_fraction: float = 0.5) -> pd.DataFrame:
    """Per run of the census (index: its case name): means over its dumped steps from ``from_fraction`` of the cut on
    where the disc touches the rock (series F_z > 0): grains touching the disc (all, body, debris), the share of the
    rebuilt normal load that chips and debris carry, the series F_z at those steps and the rebuilt / series ratio."""
    c = pd.read_csv(CONTACTS_CSV) if contacts is None else contacts
    c = c[(c["cut_fraction_1"] >= from_fraction) & (c["force_z_series_N"] > 0)]
    g = c.groupby("case")
    return pd.DataFrame({
        "frames": g.size(), "grains_touching": g["grains_touching"].mean(),
        "grains_touching_body": g["grains_touching_body"].mean(),
        "grains_touching_debris": g["grains_touching_debris"].mean(),
        "detached_share_z_1": g["detached_share_z_1"].mean(),
        "force_z_series_N": g["force_z_series_N"].mean(),
        "hertz_to_series_1": g["force_z_hertz_N"].sum() / g["force_z_series_N"].sum()})


def contact_runs(contacts: pd.DataFrame | None = None, from_fraction: float = 0.5) -> pd.DataFrame:
    """:func:`contact_means` of the held linear family runs, with S, p and the packing of the held family table."""
    out = contact_means(contacts, from_fraction)
    fam = _held_linear().set_index("case")
    fam = fam[["spacing_mm", "penetration_mm", "penetration_full_mm", "packing_seed", "force_normal_N_mean_steady"]]
    return fam.join(out, how="inner").reset_index()


def contact_fits(contacts: pd.DataFrame | None = None) -> pd.DataFrame:
    """On the held linear family runs (:func:`contact_runs`): OLS of the grains touching the disc and of the debris
    share on S and p, and seed 001's eq. 7 form on the F_z of the same steps with and without the number of grains
    touching as a third term (statsmodels): whether the fall of F_n with p goes with fewer grains under the disc."""
    import statsmodels.formula.api as smf

    t = contact_runs(contacts).rename(columns={"spacing_mm": "S", "penetration_mm": "p"})
    rows = []
    for label, formula in (("grains touching ~ S + p", "grains_touching ~ S + p"),
                           ("debris touching ~ S + p", "grains_touching_debris ~ S + p"),
                           ("detached share ~ S + p", "detached_share_z_1 ~ S + p"),
                           ("F_z ~ S + p", "force_z_series_N ~ S + p"),
                           ("F_z ~ S + p + touching", "force_z_series_N ~ S + p + grains_touching")):
        fit = smf.ols(formula, data=t).fit()
        for term in fit.params.index:
            rows.append({"model": label, "term": term, "estimate": fit.params[term], "std_error": fit.bse[term],
                         "p_value": fit.pvalues[term], "r_squared": fit.rsquared, "n_runs": int(fit.nobs)})
    return pd.DataFrame(rows)


def _paired_variant_rows(report: Path, labels: tuple[str, str], factors: tuple[str, ...],
                         metrics: tuple[tuple[str, str], ...], extra: Callable[[dict, pd.Series, pd.Series], None],
                         census: tuple[tuple[str, str], ...]) -> pd.DataFrame:
    """Every case of the variant report ``report`` beside its held family run, one row per case: the case's packing
    seed and ``factors``, each of ``metrics`` ((column, short name)) for the two ``labels`` (family run, variant
    run) and their ratio variant / family, what ``extra(row, family_row, variant_row)`` adds, and the contact census means of
    ``census`` ((column, short name)) for both runs where the census holds them. Raises unless each variant run shares
    its grains and bonds with its family run."""
    fam = _held_linear().set_index("case")
    var = pd.read_csv(report / "family_table.csv").set_index("case")
    if not _same_grains_and_bonds(var, fam):
        raise ValueError(f"{report}: a variant run does not share its grains and bonds with its held family run")
    means = contact_means() if CONTACTS_CSV.is_file() else pd.DataFrame()
    lf, lv = labels
    rows = []
    for case, v in var.iterrows():
        f = fam.loc[case]
        row = {"case": case, "packing_seed": int(v["packing_seed"]), **{k: v[k] for k in factors}}
        for m, short in metrics:
            row[f"{short} {lf}"], row[f"{short} {lv}"] = f[m], v[m]
            row[f"{short} {lv}/{lf}"] = v[m] / f[m]
        extra(row, f, v)
        for col, short in census:
            for which, name in ((lf, case), (lv, v["variant_case"])):
                row[f"{short} {which}"] = means.loc[name, col] if name in means.index else float("nan")
        rows.append(row)
    return pd.DataFrame(rows).set_index("case")


#: the force and damage metrics both paired tables report ((family-table column, short name))
_PAIR_METRICS = (("force_normal_N_mean_steady", "F_n N"), ("force_rolling_N_mean_steady", "F_r N"),
                 ("rolling_to_normal_ratio_1", "F_r/F_n"), ("bonds_broken", "bonds broken"))


def debris_effect() -> pd.DataFrame:
    """Every case of report ``linear_debris`` (S 100 mm at p 1.9 and 7.6 mm on packings 12345 and 202, session 36; the
    whole packing-12345 family, session 37): each held family run beside the same case with
    run.debris_removal_every 2000: F_n, F_r,
    F_r/F_n, bonds broken, grains deleted and, from the contact census where it holds the runs, the share of the disc's
    normal load that chips and debris carry and the grains touching the disc; debris run / family run. Raises unless
    each debris run shares its grains and bonds with its family run."""
    def deleted_and_inside(row: dict, f: pd.Series, d: pd.Series) -> None:
        row["grains deleted"] = d["n_grains_deleted_debris"]
        row["inside debris"] = d["grains_inside_cutter_final"]

    return _paired_variant_rows(DEBRIS_DIR, ("family", "debris"), ("penetration_full_mm",), _PAIR_METRICS,
                                deleted_and_inside,
                                (("detached_share_z_1", "detached share"), ("grains_touching", "touching")))


def _s100_p_ratio(effect: pd.DataFrame, labels: tuple[str, str]) -> pd.DataFrame:
    """Per packing of an effect table (:func:`debris_effect`, :func:`yfix_effect`): F_n and F_r/F_n at p 7.6 / p 1.9 mm
    (S 100 mm) for each of the two ``labels`` (its column suffixes); packings without both depths are left out."""
    t = effect[[c.startswith("lin_red_s100_") for c in effect.index]]
    rows = []
    for k, g in t.groupby("packing_seed"):
        g = g.set_index("penetration_full_mm")
        if not {1.9, 7.6} <= set(g.index):
            continue
        row = {"packing_seed": k}
        for which in labels:
            row[f"F_n p7.6/p1.9 {which}"] = g.loc[7.6, f"F_n N {which}"] / g.loc[1.9, f"F_n N {which}"]
            row[f"F_r/F_n p7.6/p1.9 {which}"] = g.loc[7.6, f"F_r/F_n {which}"] / g.loc[1.9, f"F_r/F_n {which}"]
        rows.append(row)
    return pd.DataFrame(rows).set_index("packing_seed")


def debris_p_ratio() -> pd.DataFrame:
    """Per packing: F_n and F_r/F_n at p 7.6 / p 1.9 mm (S 100 mm), family runs and debris-removal runs."""
    return _s100_p_ratio(debris_effect(), ("family", "debris"))


def _variant_family_tables(report: Path = DEBRIS_DIR, packing: int = 12345) -> tuple[pd.DataFrame, pd.DataFrame]:
    """(held family runs, variant runs) of the linear family cases of ``packing`` that ran as the variants of report
    ``report`` (``linear_debris``: run.debris_removal_every; ``linear_yfix``: side faces held), the family table cut to
    the same cases; the variant table keyed by the family case, as the family's trend and regression code reads it.
    Raises unless each variant run has one held family run and shares its grains and bonds."""
    var = pd.read_csv(report / "family_table.csv")
    var = var[var["packing_seed"] == packing]
    fam = _held_linear()
    fam = fam[fam["case"].isin(var["case"])]
    if len(fam) != len(var) or var["case"].duplicated().any():
        raise ValueError(f"{report}: each variant run needs one held family run; without one: "
                         f"{sorted(set(var['case']) - set(fam['case']))}, twice: "
                         f"{sorted(set(var.loc[var['case'].duplicated(), 'case']))}")
    if not _same_grains_and_bonds(var.set_index("case"), fam.set_index("case")):
        raise ValueError(f"{report}: a variant run does not share its grains and bonds with its held family run")
    return fam, var


def variant_family_fits(report: Path = DEBRIS_DIR, label: str = "debris", packing: int = 12345) -> pd.DataFrame:
    """Seed 001's eq. 7 form (``deckgen.families.family_regression``) on the variant runs of ``report`` on ``packing``
    (columns prefixed ``label``) and on the held family runs of the same cases (``family``), side by side (estimate,
    p, R^2 per response and term)."""
    from deckgen.families import family_regression

    cols = ["estimate", "std_error", "p_value", "r_squared", "n_runs"]
    fam, var = _variant_family_tables(report, packing)
    out = [family_regression("linear_ccs", t).set_index(["response", "term"])[cols].add_prefix(f"{which} ")
           for which, t in (("family", fam), (label, var))]
    return pd.concat(out, axis=1)


def variant_family_trends(report: Path = DEBRIS_DIR, label: str = "debris", packing: int = 12345) -> pd.DataFrame:
    """The family's trends (``deckgen.families.trend_table``) on the variant runs of ``report`` on ``packing`` and on
    the held family runs of the same cases, side by side."""
    from deckgen.families import trend_table

    cols = ["runs", "change_1", "change_1_ci95_low", "change_1_ci95_high", "p_value", "seed_change_1"]
    fam, var = _variant_family_tables(report, packing)
    out = [trend_table("linear_ccs", t).set_index("trend")[cols].add_prefix(f"{which} ")
           for which, t in (("family", fam), (label, var))]
    return pd.concat(out, axis=1)


def variant_family_grid(report: Path = DEBRIS_DIR, label: str = "debris", packing: int = 12345,
                        metric: str = "force_normal_N_mean_steady") -> pd.DataFrame:
    """``metric`` of the variant runs of ``report`` on ``packing`` as a table: full-scale p down, S across (columns
    ``<label> S..``), and beside it the held family run's value (``family S..``)."""
    fam, var = _variant_family_tables(report, packing)
    grids = [t.pivot_table(index="penetration_full_mm", columns="spacing_full_mm", values=metric).add_prefix(
        f"{which} S") for which, t in ((label, var), ("family", fam))]
    return pd.concat(grids, axis=1)


def debris_family_fits(packing: int = 12345) -> pd.DataFrame:
    """:func:`variant_family_fits` of the debris-removal runs (report ``linear_debris``): whether F_n still falls with p
    and rises with S once the loose grains leave the cut."""
    return variant_family_fits(DEBRIS_DIR, "debris", packing)


def debris_family_trends(packing: int = 12345) -> pd.DataFrame:
    """:func:`variant_family_trends` of the debris-removal runs."""
    return variant_family_trends(DEBRIS_DIR, "debris", packing)


def debris_family_grid(packing: int = 12345, metric: str = "force_normal_N_mean_steady") -> pd.DataFrame:
    """:func:`variant_family_grid` of the debris-removal runs."""
    return variant_family_grid(DEBRIS_DIR, "debris", packing, metric)


def yfix_effect() -> pd.DataFrame:
    """Every case of report ``linear_yfix`` (session 38: the family cases with specimen.fixed_faces zmin, xmax, ymin,
    ymax, seed 001's boundary) beside its held family run (free side faces): F_n, F_r, F_r/F_n, bonds broken, the
    largest chip (grains, y and z extent in mm), grains inside and, from the contact census where it holds the runs,
    the grains touching the disc and the share of its normal load that chips and debris carry; held sides / free
    sides. Raises unless each pair shares its grains and bonds."""
    def chips_and_inside(row: dict, f: pd.Series, v: pd.Series) -> None:
        for ax in "yz":
            for which, t in (("free", f), ("held", v)):
                row[f"largest chip {ax} mm {which}"] = t[f"largest_chip_extent_{ax}_m"] * 1e3
        row["inside free"], row["inside held"] = f["grains_inside_cutter_final"], v["grains_inside_cutter_final"]

    return _paired_variant_rows(YFIX_DIR, ("free", "held"), ("spacing_full_mm", "penetration_full_mm"),
                                (*_PAIR_METRICS, ("largest_chip_grains", "largest chip")), chips_and_inside,
                                (("grains_touching", "touching"), ("detached_share_z_1", "detached share")))


def yfix_p_ratio() -> pd.DataFrame:
    """Per packing: F_n and F_r/F_n at p 7.6 / p 1.9 mm (S 100 mm), free and held side faces."""
    return _s100_p_ratio(yfix_effect(), ("free", "held"))


def idle_dumps(cases: list[str], from_fraction: float = 0.5) -> pd.DataFrame:
    """Per case of the contact census (names as they ran, e.g. ``*_debris``): at how many of its dumped steps from
    ``from_fraction`` of the cut on the rebuilt normal force is 0 (the disc touches no grain), and of how many."""
    raw = pd.read_csv(CONTACTS_CSV)
    half = raw[raw["case"].isin(cases) & (raw["cut_fraction_1"] >= from_fraction)]
    g = half.groupby("case")["force_z_hertz_N"]
    return pd.DataFrame({"idle": g.apply(lambda x: int((x == 0).sum())), "dumps": g.size()})


def grain_pairs() -> pd.DataFrame:
    """The grain-size pairs of :data:`GRAIN_PAIRS`: session 31's unrelieved S 100 mm cut at p 1.9 and 7.6 mm on blocks
    26 x W x 12 mm with coarse (r 0.7-1.0 mm) and fine (r 0.35-0.5 mm) grains, or (33 mm) a band of fine grains along the
    cut, all with the r 0.16 mm shell. Per block
    width W and grain size, per p: F_n, F_r, F_r/F_n, grains, bonds broken and their fraction, grains inside, wall
    minutes, the largest chip (grains, y and z extent in mm) and, from the contact census where it holds the runs, the
    grains touching the disc and the share of its normal load that chips and debris carry; with p 7.6 / p 1.9 mm ratios;
    only the reports that exist (session 37's 10 mm fine pair, ~65 min per run, was stopped for time). F_n and F_r
    are over each run's own case window, which for the held 20 mm fine runs (shortened travel) is the patch window
    0.2-0.4 of the block, not the others' 0.4-0.6. Index (width_mm, sides, packing, grains)."""
    means = contact_means() if CONTACTS_CSV.is_file() else pd.DataFrame()
    rows = []
    for (width, sides, packing), sizes in GRAIN_PAIRS.items():
        for size, (tail, report) in sizes.items():
            if not (report / "family_table.csv").is_file():
                continue
            t = pd.read_csv(report / "family_table.csv").set_index("variant_case")
            if not {f"lin_red_s100_p{p}{tail}" for p in ("1p9", "7p6")} <= set(t.index):
                continue  # a report without this pair's runs (yet)
            row = {"width_mm": width, "sides": sides, "packing": packing, "grains": size}
            for p in ("1p9", "7p6"):
                name = f"lin_red_s100_p{p}{tail}"
                r = t.loc[name]
                for m, short in (("force_normal_N_mean_steady", "F_n N"), ("force_rolling_N_mean_steady", "F_r N"),
                                 ("rolling_to_normal_ratio_1", "F_r/F_n"), ("n_grains", "grains"),
                                 ("bonds_broken", "bonds broken"), ("broken_fraction_1", "broken fraction"),
                                 ("grains_inside_cutter_final", "inside")):
                    row[f"{short} p{p}"] = r[m]
                row[f"wall min p{p}"] = r["wall_s"] / 60.0
                # the largest chip: a side of the block split off (session 38) spans the half-width and the height
                row[f"largest chip grains p{p}"] = r["largest_chip_grains"]
                for ax in "yz":
                    row[f"largest chip {ax} mm p{p}"] = r[f"largest_chip_extent_{ax}_m"] * 1e3
                for col, short in (("grains_touching", "touching"), ("detached_share_z_1", "detached share")):
                    row[f"{short} p{p}"] = means.loc[name, col] if name in means.index else float("nan")
            row["F_n p7.6/p1.9"] = row["F_n N p7p6"] / row["F_n N p1p9"]
            row["F_r/F_n p7.6/p1.9"] = row["F_r/F_n p7p6"] / row["F_r/F_n p1p9"]
            rows.append(row)
    return pd.DataFrame(rows).set_index(["width_mm", "sides", "packing", "grains"])


def grain_pair_windows(windows: pd.DataFrame | None = None) -> pd.DataFrame:
    """F_n (N) of the grain-size pairs' runs and of the 33 mm unrelieved block's over the windows of
    :data:`PATCH_WINDOWS` (rows: case; columns: the window's contact-patch start as a fraction of the block, ``lo``):
    whether F_n before a side of the block splits off follows the 33 mm block's, and where along the cut it drops."""
    w = pd.read_csv(PAIR_WINDOWS_CSV) if windows is None else windows
    return w.pivot(index="case", columns="patch_lo_1", values="force_normal_N_mean_steady")  # raises on a case twice


def pair_window_ratios(windows: pd.DataFrame | None = None) -> pd.DataFrame:
    """F_n at p 7.6 mm over F_n at p 1.9 mm, window by window, for every pair of :func:`grain_pair_windows` (rows: the
    case-name tail after ``lin_red_s100_p{1p9,7p6}``, e.g. ``_w20_fine_yfix``; ``_unrel`` is the 33 mm block): the
    change of F_n with p over the same stretch of the cut, the like-for-like comparison for runs whose case windows
    differ (session 39's shortened fine runs). NaN where either run does not finish the window."""
    w = grain_pair_windows(windows)
    tails = sorted({c.removeprefix("lin_red_s100_p1p9").removeprefix("lin_red_s100_p7p6") for c in w.index})
    rows = {t: w.loc[f"lin_red_s100_p7p6{t}"] / w.loc[f"lin_red_s100_p1p9{t}"] for t in tails
            if f"lin_red_s100_p7p6{t}" in w.index and f"lin_red_s100_p1p9{t}" in w.index}
    return pd.DataFrame(rows).T.rename_axis("pair")


def pair_window_ratio_errors(windows: pd.DataFrame | None = None) -> pd.DataFrame:
    """The standard error of each ratio of :func:`pair_window_ratios`: the two runs' relative standard errors of F_n
    over the window (``force_normal_N_sem_steady``, ``results.mean_standard_error``) combined in quadrature, times the
    ratio. It measures the scatter within the two runs, not between packings or runs."""
    import numpy as np

    w = pd.read_csv(PAIR_WINDOWS_CSV) if windows is None else windows
    rel = (w.assign(rel=w["force_normal_N_sem_steady"] / w["force_normal_N_mean_steady"])
           .pivot(index="case", columns="patch_lo_1", values="rel"))
    ratios = pair_window_ratios(w)
    rows = {t: ratios.loc[t] * np.hypot(rel.loc[f"lin_red_s100_p7p6{t}"], rel.loc[f"lin_red_s100_p1p9{t}"])
            for t in ratios.index}
    return pd.DataFrame(rows).T.rename_axis("pair")


def packing_replicates(width: int = 33, sides: str = "free", window: float = 0.4) -> pd.DataFrame:
    """The band pair and its coarse reference on every packing of :data:`GRAIN_PAIRS` at this block width and sides
    that has the band pair in the pair windows: per packing (index) F_n p 7.6 / 1.9 mm over ``window`` (the
    contact-patch start; 0.4 is the case window) for ``band`` and ``coarse`` (NaN where the coarse pair was not run)
    with their within-run standard errors
    (:func:`pair_window_ratio_errors`), ``band/coarse``, the band's ratio over its same-packing reference's, and (33 mm
    block, where its pair windows exist, else NaN) ``coarse r0.3`` with its error, the coarse pair with the r 0.3 mm
    shell (:data:`SHELL03_TAILS`), and ``coarse/coarse r0.3``, the shell radius's effect on the ratio."""
    w = pd.read_csv(PAIR_WINDOWS_CSV)
    ratios, errors = pair_window_ratios(w), pair_window_ratio_errors(w)
    rows = []
    for key, sizes in GRAIN_PAIRS.items():
        packing = key[2]
        if key[:2] != (width, sides) or "band" not in sizes or sizes["band"][0] not in ratios.index:
            continue  # no band pair here, or not run (yet)
        row = {"packing": packing}

        def put(col: str, t: str | None) -> None:  # the pair's ratio and error, NaN where it was not run
            has = t in ratios.index  # 505, 606, 707, 808, 909: no r 0.3 mm pair
            row[col] = ratios.loc[t, window] if has else float("nan")
            row[f"{col} s.e."] = errors.loc[t, window] if has else float("nan")

        put("band", sizes["band"][0])
        put("coarse", sizes.get("coarse", (None,))[0])
        row["band/coarse"] = row["band"] / row["coarse"]
        put("coarse r0.3", SHELL03_TAILS.get(key))
        row["coarse/coarse r0.3"] = row["coarse"] / row["coarse r0.3"]
        rows.append(row)
    return pd.DataFrame(rows).set_index("packing")


def packing_spread(width: int = 33, sides: str = "free", window: float = 0.4,
                   packings: tuple[int, ...] | None = None) -> pd.DataFrame:
    """Across the packings of :func:`packing_replicates` (rows ``band``, ``coarse``, ``band/coarse``, ``coarse r0.3``
    and ``coarse/coarse r0.3``, each over the packings that have it, at least two): their number, the
    geometric mean of the ratio and its 95 % interval from the spread between packings (Student t on the log ratios,
    n - 1 degrees of freedom), the standard deviation of the log ratio between packings, the root mean square of the
    within-run relative error (s.e. / ratio, the two combined in quadrature for band/coarse; a first-order log error),
    and a 95 % interval of the geometric mean from those within-run errors alone (normal, sqrt(sum of squares) / n on the
    log scale; with two packings the t interval has one degree of freedom and is wide). A between-packing spread
    well above the within-run error says one run's window mean is not a measure of the case. ``packings``: only these
    (default: every packing run)."""
    import numpy as np
    from scipy import stats

    t = packing_replicates(width, sides, window)
    if packings is not None:
        t = t.loc[list(packings)]
    rel = {size: t[f"{size} s.e."] / t[size] for size in ("band", "coarse", "coarse r0.3")}
    rel["band/coarse"] = np.hypot(rel["band"], rel["coarse"])
    rel["coarse/coarse r0.3"] = np.hypot(rel["coarse"], rel["coarse r0.3"])
    rows = []
    for col in ("band", "coarse", "band/coarse", "coarse r0.3", "coarse/coarse r0.3"):
        ok = t[col].notna()  # no r 0.3 mm shell pair on 505 / 606 / 707 / 808 / 909 (sessions 43-48)
        if ok.sum() < 2:
            continue
        lg = np.log(t.loc[ok, col].to_numpy(dtype=float))
        n = len(lg)
        sd = lg.std(ddof=1) if n > 1 else float("nan")
        half = stats.t.ppf(0.975, n - 1) * sd / np.sqrt(n) if n > 1 else float("nan")
        rc = rel[col][ok]
        within = stats.norm.ppf(0.975) * float(np.sqrt((rc ** 2).sum())) / n
        rows.append({"ratio": col, "packings": n, "geometric mean": np.exp(lg.mean()),
                     "95% low": np.exp(lg.mean() - half), "95% high": np.exp(lg.mean() + half),
                     "log sd between packings": sd, "log s.e. within runs (rms)": float(np.sqrt((rc ** 2).mean())),
                     "95% low within": np.exp(lg.mean() - within), "95% high within": np.exp(lg.mean() + within)})
    return pd.DataFrame(rows).set_index("ratio")


def _only_packings(t: pd.DataFrame, packings: tuple[int, ...] | None, who: str, width: int, sides: str) -> pd.DataFrame:
    """The rows of a per-packing table ``t`` (indexed by packing like :func:`packing_replicates`, whose rows are the
    packings with a recorded band pair) for ``packings`` (all where None); a packing not in ``t`` is refused with the
    recorded ones named."""
    if packings is None:
        return t
    missing = sorted(set(packings) - set(t.index))
    if missing:
        raise ValueError(f"{who}: no band pair recorded on packings {missing} at width {width} mm, {sides} sides "
                         f"(recorded: {sorted(t.index)})")
    return t.loc[list(packings)]


def band_over_coarse_unpaired(width: int = 33, sides: str = "free", window: float = 0.4,
                              packings: tuple[int, ...] | None = None) -> dict[str, float | int]:
    """Band over coarse as two independent samples (session 46): the geometric mean of the band's case-window ratios
    over that of the coarse reference's, each over the packings of :func:`packing_replicates` (those with a band pair)
    that have it, at least two of each, with a Welch t 95 % interval and p on the
    log ratios, and a Mann-Whitney p. The band and coarse packings of one seed share the seed, not the grains (their
    first radii are the same draws, but how many are drawn depends on the volume the band changes, so every later draw
    comes from another point of the random stream; on the rendered 606 and 707 no coarse grain lies within 5 um of a band
    grain of its seed, and the median nearest one is as far as another seed's), so the per-packing band/coarse of :func:`packing_spread` pairs two independent draws: its
    paired interval is valid but its pairing is arbitrary, and a packing without one of the two is left out there and
    kept here."""
    import numpy as np
    from scipy import stats

    t = _only_packings(packing_replicates(width, sides, window), packings, "band_over_coarse_unpaired", width, sides)
    b, c = np.log(t["band"].dropna().to_numpy(float)), np.log(t["coarse"].dropna().to_numpy(float))
    if min(len(b), len(c)) < 2:
        raise ValueError(f"band_over_coarse_unpaired: needs at least two packings of each (band {len(b)}, coarse "
                         f"{len(c)})")
    welch = stats.ttest_ind(b, c, equal_var=False)
    ci = welch.confidence_interval(0.95)
    return {"band packings": len(b), "coarse packings": len(c), "band/coarse": float(np.exp(b.mean() - c.mean())),
            "95% low": float(np.exp(ci.low)), "95% high": float(np.exp(ci.high)), "welch dof": float(welch.df),
            "welch p": float(welch.pvalue),
            "mann-whitney p": float(stats.mannwhitneyu(b, c, alternative="two-sided").pvalue)}


def full_engagement_patch(length_mm: float, radius_mm: float, penetration_mm: float) -> float:
    """Contact-patch position (fraction of the block length, as in :data:`PATCH_WINDOWS`) from which the disc's whole
    contact arc lies inside the block: the arc runs from below the disc centre to a half chord ahead of it, and the patch
    centre is half a half chord ahead of the centre (``families.middle_window``), so the back of the arc passes the
    entry face x = 0 when the patch centre reaches half a half chord. Before it the disc cuts the entry corner, not the
    steady groove: on the 26 mm block (disc 53.975 mm) from patch 0.136 at p 1.9 mm (0.95 reduced) and 0.266 at p 7.6
    mm (3.8 reduced), so 83 % of a deep run's window 0.1 comes before full engagement (session 47)."""
    from deckgen.families import half_chord_mm

    return half_chord_mm(radius_mm, penetration_mm) / 2 / length_mm


def two_window_ratios(width: int = 33, sides: str = "free", windows: tuple[float, ...] = (0.2, 0.4)) -> pd.DataFrame:
    """Session 47: per packing of :func:`packing_replicates` (index), F_n p 7.6 / 1.9 mm of the ``band`` and ``coarse``
    pairs over several non-overlapping windows of :data:`PATCH_WINDOWS` read as one stretch of the cut: each run's F_n
    is the mean over the windows weighted by their rows. The default (0.2, 0.4) is the contact patch over 0.2-0.6 of
    the block, 10.4 mm of the 26 mm block, where the deep cut's arc is 88 % inside the block at the start and whole from
    0.266 (:func:`full_engagement_patch`); (0.1, 0.4) reads patch 0.1-0.3 and 0.4-0.6 (two 5.2 mm pieces), but 83 % of
    a deep run's window 0.1 comes before its arc is whole in the block (69 % of its x extent inside at 0.1), so that
    reading mixes the entry into the deep cut. What a
    run over a longer block would average, if the rock of one stretch does not tell the next (:func:`two_window_spread`
    checks that). NaN where a pair was not run."""
    import numpy as np

    lo = sorted(windows)
    if not lo or any(w not in PATCH_WINDOWS for w in lo) or any(b - a < 0.2 - 1e-9 for a, b in zip(lo, lo[1:])):
        raise ValueError(f"two_window_ratios: windows {windows} must be one or more starts of PATCH_WINDOWS "
                         f"{PATCH_WINDOWS} at least 0.2 apart (each window spans 0.2 of the block; overlapping windows "
                         "count rock twice)")
    w = pd.read_csv(PAIR_WINDOWS_CSV)
    w = w[w["patch_lo_1"].isin(lo)].assign(weighted=lambda d: d["force_normal_N_mean_steady"] * d["rows"])
    g = w.groupby("case")
    fn = g["weighted"].sum() / g["rows"].sum()
    whole = g["patch_lo_1"].count() == len(lo)  # a run that does not finish one of the windows has no stretch mean
    fn = fn[whole]
    rows = []
    for packing in packing_replicates(width, sides).index:
        sizes = GRAIN_PAIRS[(width, sides, packing)]
        row = {"packing": packing}
        for size in ("band", "coarse"):
            tail = sizes.get(size, (None,))[0]
            a, b = f"lin_red_s100_p7p6{tail}", f"lin_red_s100_p1p9{tail}"
            row[size] = fn[a] / fn[b] if tail and a in fn.index and b in fn.index else np.nan
        rows.append(row)
    return pd.DataFrame(rows).set_index("packing")


def two_window_spread(width: int = 33, sides: str = "free", windows: tuple[float, float] = (0.2, 0.4),
                      packings: tuple[int, ...] | None = None) -> pd.DataFrame:
    """Session 47: for ``band`` and ``coarse`` (rows), over the packings that have the pair (at least three): the
    geometric mean of :func:`two_window_ratios` with its Student t 95 % interval and the log sd between packings, beside
    the same for each single window (``log sd window 0.2`` ...), and the Pearson correlation between packings of the
    two windows' log ratios (``window corr``, its two-sided ``window corr p``). A correlation near 0 or below says the
    rock of one stretch of a run does not tell the next, so averaging more of the cut narrows the spread between
    packings (for two independent windows of equal spread, by sqrt 2); a correlation near 1 says a packing's ratio is
    its own, and a longer cut would not help."""
    import numpy as np
    from scipy import stats

    if len(windows) != 2:
        raise ValueError(f"two_window_spread: give two windows (got {windows})")
    both = _only_packings(two_window_ratios(width, sides, windows), packings, "two_window_spread", width, sides)
    per_window = {w: packing_replicates(width, sides, w) for w in windows}
    rows = []
    for size in ("band", "coarse"):
        ok = both[size].dropna().index
        if len(ok) < 3:
            continue
        lg = np.log(both.loc[ok, size].to_numpy(float))
        n = len(lg)
        half = stats.t.ppf(0.975, n - 1) * lg.std(ddof=1) / np.sqrt(n)
        lw = [np.log(per_window[w].loc[ok, size].to_numpy(float)) for w in windows]
        r = stats.pearsonr(lw[0], lw[1])
        row = {"size": size, "packings": n, "geometric mean": float(np.exp(lg.mean())),
               "95% low": float(np.exp(lg.mean() - half)), "95% high": float(np.exp(lg.mean() + half)),
               "t p": float(stats.ttest_1samp(lg, 0.0).pvalue), "log sd between packings": float(lg.std(ddof=1))}
        for w, l in zip(windows, lw):
            row[f"log sd window {w}"] = float(l.std(ddof=1))
        row["window corr"], row["window corr p"] = float(r.statistic), float(r.pvalue)
        rows.append(row)
    if not rows:
        raise ValueError(f"two_window_spread: needs at least three packings with the band or the coarse pair (packings "
                         f"{sorted(both.index)}: band on {both['band'].notna().sum()}, coarse on "
                         f"{both['coarse'].notna().sum()}; fix: pass more packings or none)")
    return pd.DataFrame(rows).set_index("size")


def main() -> None:
    if len(sys.argv) > 3 and sys.argv[1] == "--contacts":
        t = contact_table([Path(a) for a in sys.argv[3:]])
        t.to_csv(sys.argv[2], index=False, float_format="%.6g")
        with pd.option_context("display.width", 250, "display.max_columns", 40):
            runs = contact_runs(t)
            if len(runs):
                print(runs.round(3).to_string(index=False))
            if len(runs) >= 4:  # the fits need family runs (three terms)
                print(contact_fits(t).round(4).to_string(index=False))
            means = contact_means(t)
            other = means[~means.index.isin(runs["case"])]
            if len(other):  # diagnostics (variants of family cases) are not fitted: their means
                print(other.round(3).T.to_string())
        return
    if len(sys.argv) > 3 and sys.argv[1] == "--pair-windows":
        t = window_table([Path(a) for a in sys.argv[3:]])
        t.to_csv(sys.argv[2], index=False, float_format="%.6g")
        print(grain_pair_windows(t).round(1).to_string())
        print("-- F_n p 7.6 / p 1.9 mm, and its standard error within the runs")
        print(pair_window_ratios(t).round(3).to_string())
        print(pair_window_ratio_errors(t).round(3).to_string())
        return
    suffix = {"--windows": "", "--debris-windows": "_debris", "--yfix-windows": "_yfix"}
    if len(sys.argv) > 3 and sys.argv[1] in suffix:
        t = window_table([Path(a) for a in sys.argv[3:]])
        if suffix[sys.argv[1]]:
            t["case"] = t["case"].str.removesuffix(suffix[sys.argv[1]])
        t.to_csv(sys.argv[2], index=False, float_format="%.6g")
        with pd.option_context("display.width", 250, "display.max_columns", 40):
            print(window_fits(t).round(4).T.to_string())
        return
    with pd.option_context("display.width", 250, "display.max_columns", 40):
        for kind in KINDS:
            if not _has(kind):
                print(f"{kind}: no held-shell report yet")
                continue
            print(f"== {kind}")
            print(pairs(kind).round(3).T.to_string())
            s = summary(kind)
            if len(s):
                print(s.round(3).to_string(index=False))
            print()
        if _has("linear") and _has("linear shell0p5"):
            print("== the finer shell on the fixed deck")
            print(shell_gain().round(3).T.to_string())
            print()
            print("== the linear trends as ratios (held and recorded runs of the same cases)")
            print(linear_ratios().round(3).T.to_string())
        if _has("linear") and _has("linear unrelieved"):
            print()
            print("== F_n p 7.6 / p 1.9 mm at S 100 mm, with and without the neighbour grooves")
            print(fn_p_ratio().round(3).T.to_string())
        if _has("linear"):
            print()
            print("== seed 001's eq. 7 form on the held linear runs and the recorded runs of the same cases")
            print(regression_same_cases().round(4).to_string())
            print("-- without the p 1.9 mm cells")
            print(regression_same_cases(2.0).round(4).to_string())
            print("-- with a chip of >= 100 grains (a large piece of the block broken off) as a third term")
            print(large_chip_fit().round(4).to_string())
        if CONTACTS_CSV.is_file():
            print()
            print("== what carries the disc's load on the held linear runs (deckgen.contacts, second half of the cut)")
            print(contact_runs().round(3).to_string(index=False))
            print(contact_fits().round(4).to_string(index=False))
        if (DEBRIS_DIR / "family_table.csv").is_file():
            print()
            print("== with the loose grains deleted every 2000 steps (run.debris_removal_every)")
            d = debris_effect()
            print(d.round(3).T.to_string())
            print(debris_p_ratio().round(3).T.to_string())
            # session 36 ran two packing-12345 cases with the debris deleted; session 37 the other 14
            if (d["packing_seed"] == 12345).sum() > 2:
                print("-- the packing-12345 family with the loose grains deleted (F_n N; F_r/F_n)")
                print(debris_family_grid().round(1).to_string())
                print(debris_family_grid(metric="rolling_to_normal_ratio_1").round(3).to_string())
                print(debris_family_fits().round(4).to_string())
                print(debris_family_trends().round(3).T.to_string())
            if DEBRIS_WINDOWS_CSV.is_file():
                print("-- the same over other windows (contact-patch centre from lo to lo + 0.2 of the block)")
                print(window_fits(pd.read_csv(DEBRIS_WINDOWS_CSV)).round(4).T.to_string())
        if (YFIX_DIR / "family_table.csv").is_file():
            print()
            print("== with the side faces y min, y max held as well (seed 001's boundary; report linear_yfix)")
            y = yfix_effect()
            print(y.round(3).T.to_string())
            print(yfix_p_ratio().round(3).T.to_string())
            if (y["packing_seed"] == 12345).sum() >= 6:
                print("-- the packing-12345 cases with the side faces held (F_n N; F_r/F_n)")
                print(variant_family_grid(YFIX_DIR, "held").round(1).to_string())
                print(variant_family_grid(YFIX_DIR, "held", metric="rolling_to_normal_ratio_1").round(3).to_string())
                print(variant_family_fits(YFIX_DIR, "held").round(4).to_string())
                print(variant_family_trends(YFIX_DIR, "held").round(3).T.to_string())
                if YFIX_WINDOWS_CSV.is_file():
                    print("-- the same over other windows (contact-patch centre from lo to lo + 0.2 of the block)")
                    print(window_fits(pd.read_csv(YFIX_WINDOWS_CSV)).round(4).T.to_string())
        if any((d / "family_table.csv").is_file() for sizes in GRAIN_PAIRS.values() for _, d in sizes.values()):
            print()
            print("== grain size on unrelieved blocks (S 100 mm, 26 x W x 12 mm; W 33 mm, r 0.3 mm shell: linear_unrel)")
            print(grain_pairs().round(3).T.to_string())
            if PAIR_WINDOWS_CSV.is_file():
                print("-- F_n N over windows of the cut (contact-patch centre from lo to lo + 0.2 of the block)")
                print(grain_pair_windows().round(1).to_string())
                print("-- F_n p 7.6 / p 1.9 mm over the same windows, and its standard error within the runs")
                print(pair_window_ratios().round(3).to_string())
                print(pair_window_ratio_errors().round(3).to_string())
                print("-- 33 mm block, case window: the band pair and its coarse reference packing by packing, and the spread")
                print(packing_replicates().round(3).to_string())
                print(packing_spread().round(3).to_string())
        if WINDOWS_CSV.is_file():
            print()
            print("== the held linear runs over other windows (contact-patch centre from lo to lo + 0.2 of the block)")
            print(window_fits().round(4).T.to_string())
        for kind in ("linear", "indentation"):
            if _has(kind):
                print()
                print(f"== the {kind} family's trends, recorded and held runs of the same cases")
                print(trends_same_cases(kind).round(3).T.to_string())


if __name__ == "__main__":
    main()
