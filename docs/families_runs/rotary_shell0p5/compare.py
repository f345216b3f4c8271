"""The rotary family on the finer shell (sessions 33-34).

Sessions 31-32 found that the default cutter shell (``shell_spacing`` 1: sphere centres 0.6 mm apart on a tip one grain
wide) leaks grains into the linear disc's tip and that a shell twice as fine (``shell_spacing`` 0.5) about doubles the
linear F_n. The rotary family uses the same disc and shell. The diagnostics here are the family cases
``rot_red_r{250,1000}{,_k202,_k303,_k404}`` (session 33, ``report/``) and ``rot_red_r{250,1000}_k{505,606,707}`` (session
34, ``report_k505_k707/``) with ``cutter.shell_spacing`` 0.5 and nothing else, so each pairs with the family run of the
same case (the same grains and bonds; ``../rotary_reduced_7packings/family_table.csv``). Every function takes
``reports``: the report folders to pool (default all of :data:`REPORTS`; ``("report",)`` is session 33's four packings).

Prints one row per run (family and finer shell side by side, their ratio, grains inside the tip at the end), the
shell's paired gain in F_n and F_r (geometric mean with its 95 % interval), the
packing means at r 250 and 1000 mm with their standard errors and the ratio r 1000 / r 250 with its verdict (the rule
of ``../linear_fn_vs_p/compare.py``: "rises" if >= 1.3 and 2 s.e. above 1, "flat" if 1 lies within 2 s.e.; the
family's standard errors are the packings' scatter alone, its runs were parsed before the sems existed), and the
family's rotary trends (:func:`deckgen.families.trend_table`) fitted on the shell runs and on the family runs of the
same cases; then the finer shell on session 31's unrelieved linear cut (:func:`unrelieved_gain`).

    python docs/families_runs/rotary_shell0p5/compare.py
"""
from __future__ import annotations

import functools
from pathlib import Path

import numpy as np
import pandas as pd

HERE = Path(__file__).resolve().parent
#: the report folders of the shell0p5 runs, by session: 33 packings 12345, 202, 303, 404; 34 packings 505, 606, 707
REPORTS = ("report", "report_k505_k707")
FAMILY = HERE.parent / "rotary_reduced_7packings" / "family_table.csv"
KEYS = ["packing_seed", "rotary_radius_full_mm"]
RADII = (250, 1000)  # full-scale mm
QUANTITIES = {"F_n": "force_normal_N", "F_r": "force_rolling_N", "F_s": "force_side_N"}


@functools.cache
def _linear_compare():
    """The packing-mean and ratio rules of the session-31 comparison (one rule for both families), loaded once."""
    from deckgen.scriptload import load_script

    return load_script(HERE.parent / "linear_fn_vs_p" / "compare.py", "linear_fn_vs_p_compare")


def _same_grains(a: pd.DataFrame, b: pd.DataFrame, what: str) -> None:
    """Raise unless each row of ``a`` and ``b`` (same index) has the same grains and bonds: the shell the only change."""
    if (a["n_grains"] != b["n_grains"]).any() or (a["n_bonds_initial"] != b["n_bonds_initial"]).any():
        raise ValueError(f"{what} must share their grains and bonds")


def tables(reports: tuple[str, ...] = REPORTS) -> tuple[pd.DataFrame, pd.DataFrame]:
    """(family, shell): the runs of the report folders ``reports`` indexed by (packing, r), the family restricted to the
    cases the shell ran. Raises when a pair does not share its grains and bonds (the shell must be the only change) or
    when two reports hold the same case."""
    parts = []
    for name in reports:
        path = HERE / name / "family_table.csv"
        if not path.is_file():
            raise SystemExit(f"{path}: no report yet (fix: run the shell0p5 diagnostics and report them, docs/families.md,"
                             " section The rotary family on the finer shell)")
        parts.append(pd.read_csv(path))
    shell = pd.concat(parts, ignore_index=True).set_index(KEYS).sort_index()
    if shell.index.duplicated().any():
        raise ValueError(f"{reports}: the same (packing, r) in two reports: {list(shell.index[shell.index.duplicated()])}")
    family = pd.read_csv(FAMILY).set_index(KEYS).reindex(shell.index)
    if family["n_grains"].isna().any():
        raise ValueError(f"{FAMILY}: no family run for {list(shell.index[family['n_grains'].isna()])}")
    _same_grains(family, shell, "a shell0p5 run and its family run")
    return family, shell


def paired(reports: tuple[str, ...] = REPORTS) -> pd.DataFrame:
    """One row per (packing, r): each force and F_r/F_n for the family shell and the finer one, and shell/family."""
    family, shell = tables(reports)
    out = pd.DataFrame(index=shell.index)
    cols = {**{f"{q} N": f"{c}_mean_steady" for q, c in QUANTITIES.items()}, "F_r/F_n": "rolling_to_normal_ratio_1"}
    for name, col in cols.items():
        out[f"{name} family"], out[f"{name} shell"] = family[col], shell[col]
        if name != "F_s N":  # a signed force near zero: its ratio is noise
            out[f"{name} shell/family"] = shell[col] / family[col]
    out["F_n sem shell"] = shell["force_normal_N_sem_steady"]
    out["inside family"] = family["grains_inside_cutter_final"]
    out["inside shell"] = shell["grains_inside_cutter_final"]
    out["broken family"], out["broken shell"] = family["broken_fraction_1"], shell["broken_fraction_1"]
    out["n_shell family"], out["n_shell shell"] = family["n_shell"], shell["n_shell"]
    out["wall_min family"], out["wall_min shell"] = family["wall_s"] / 60, shell["wall_s"] / 60
    return out


def gain_row(label: str, g: np.ndarray) -> dict:
    """The paired gains ``g`` (shell / family) summarised: geometric mean with its 95 % t interval and the p-value of a
    one-sample t test of log(g) against 0 (scipy), the median, the range and how many runs the finer shell lifts."""
    from scipy import stats

    lg = np.log(np.asarray(g, float))
    n = len(lg)
    half = stats.t.ppf(0.975, n - 1) * lg.std(ddof=1) / np.sqrt(n)
    return {"pairs": label, "runs": n, "geometric mean": float(np.exp(lg.mean())),
            "ci95 low": float(np.exp(lg.mean() - half)), "ci95 high": float(np.exp(lg.mean() + half)),
            "p_value": float(stats.ttest_1samp(lg, 0.0).pvalue), "median": float(np.median(g)),
            "min": float(np.min(g)), "max": float(np.max(g)), "above 1": int((np.asarray(g) > 1).sum())}


def gains(reports: tuple[str, ...] = REPORTS) -> pd.DataFrame:
    """The shell's gain over the family run of the same case (:func:`gain_row`): rotary F_n and F_r over the pairs
    here, and for comparison the linear F_n over session 32's 24 pairs and its 12 at p 7.6 mm."""
    t = paired(reports)
    lin = _linear_compare()
    linear = pd.concat([lin.per_run(("shell0p5",), s) for s in lin.SPACINGS])
    return pd.DataFrame([gain_row("rotary F_n", t["F_n N shell/family"]), gain_row("rotary F_r", t["F_r N shell/family"]),
                         gain_row("linear F_n", linear["F_n/family"]),
                         gain_row("linear F_n p 7.6", linear.loc[linear["p_full_mm"] == 7.6, "F_n/family"])])


#: session 33's check on the linear block: session 31's unrelieved S 100 mm cut at p 7.6 mm (no neighbour grooves) with
#: the finer shell, packings 12345 and 202 (``../linear_fn_vs_p/unrel_shell0p5``)
UNRELIEVED = HERE.parent / "linear_fn_vs_p"


def unrelieved_gain() -> pd.DataFrame:
    """The finer shell on the unrelieved linear cut: per packing F_n, F_r and grains inside for the coarse shell
    (``unrel``) and the finer (``unrel_shell0p5``), and F_n fine/coarse (summarise it with :func:`gain_row`)."""
    lin = _linear_compare()
    coarse, fine = lin.runs("unrel").loc[7.6], lin.runs("unrel_shell0p5").loc[7.6]
    coarse = coarse.reindex(fine.index)
    _same_grains(coarse, fine, "an unrel_shell0p5 run and its unrel run")
    out = pd.DataFrame({"F_n coarse N": coarse["force_normal_N_mean_steady"], "F_n fine N": fine["force_normal_N_mean_steady"],
                        "F_n sem fine": fine["force_normal_N_sem_steady"], "F_r coarse N": coarse["force_rolling_N_mean_steady"],
                        "F_r fine N": fine["force_rolling_N_mean_steady"],
                        "inside coarse": coarse["grains_inside_cutter_final"], "inside fine": fine["grains_inside_cutter_final"],
                        "wall_min fine": fine["wall_s"] / 60})
    out["F_n fine/coarse"] = out["F_n fine N"] / out["F_n coarse N"]
    return out


def _both_radii(reports: tuple[str, ...]) -> tuple[pd.DataFrame, pd.DataFrame]:
    """:func:`tables` restricted to the packings run at both radii (a packing with one radius would shift one mean)."""
    family, shell = tables(reports)
    counts = shell.reset_index().groupby("packing_seed")["rotary_radius_full_mm"].nunique()
    keep = shell.index.get_level_values("packing_seed").isin(counts.index[counts == len(RADII)])
    return family[keep], shell[keep]


def radius_ratios(reports: tuple[str, ...] = REPORTS) -> pd.DataFrame:
    """Per configuration and quantity: the packing means at r 250 and 1000 mm (± s.e.), their ratio r 1000 / r 250
    (± s.e.) and its verdict, over the packings run at both radii. abs(F_s) per run before the mean (the family trend
    is on the side force's magnitude)."""
    lin = _linear_compare()
    family, shell = _both_radii(reports)
    rows = []
    for name, t in (("family", family), ("shell0p5", shell)):
        for q, c in {**QUANTITIES, "F_r/F_n": None}.items():
            stats = {}
            for r in RADII:
                at = t.xs(r, level="rotary_radius_full_mm")
                if c is None:
                    v, s = at["rolling_to_normal_ratio_1"], pd.Series(float("nan"), index=at.index)
                else:
                    v = at[f"{c}_mean_steady"].abs() if q == "F_s" else at[f"{c}_mean_steady"]
                    s = at[f"{c}_sem_steady"] if f"{c}_sem_steady" in at else pd.Series(float("nan"), index=at.index)
                stats[r] = lin.mean_and_se(v, s)
            ratio, se = lin.ratio_and_se(stats[RADII[0]], stats[RADII[1]])
            rows.append({"config": name, "quantity": "abs(F_s)" if q == "F_s" else q,
                         "r250": stats[250][0], "se r250": stats[250][1], "r1000": stats[1000][0],
                         "se r1000": stats[1000][1], "r1000/r250": ratio, "se": se, "verdict": lin.verdict(ratio, se)})
    return pd.DataFrame(rows)


def matched_trends(reports: tuple[str, ...] = REPORTS) -> pd.DataFrame:
    """The family's rotary trends fitted on the shell runs and on the family runs of the same cases (the packings run at
    both radii)."""
    from deckgen.families import trend_table

    family, shell = _both_radii(reports)
    rows = []
    for name, t in (("family", family), ("shell0p5", shell)):
        for _, r in trend_table("rotary", t.reset_index()).iterrows():
            rows.append({"config": name, "trend": r["trend"], "runs": r["runs"], "change": r["change_1"],
                         "ci95 low": r["change_1_ci95_low"], "ci95 high": r["change_1_ci95_high"],
                         "p_value": r["p_value"], "seed": r["seed_change_1"]})
    return pd.DataFrame(rows)


def main() -> None:
    present = tuple(r for r in REPORTS if (HERE / r / "family_table.csv").is_file()) or REPORTS
    with pd.option_context("display.width", 220, "display.max_columns", 40):
        print(f"reports pooled: {', '.join(present)}")
        print(paired(present).round(3).to_string())
        print()
        print(gains(present).round(3).to_string(index=False))
        for name in present if len(present) > 1 else ():
            t = paired((name,))
            print(pd.DataFrame([gain_row(f"rotary F_n, {name} alone", t["F_n N shell/family"]),
                                gain_row(f"rotary F_r, {name} alone", t["F_r N shell/family"])]).round(3).to_string(
                                    index=False, header=False))
        print()
        print(radius_ratios(present).round(3).to_string(index=False))
        print()
        print(matched_trends(present).round(4).to_string(index=False))
        if (UNRELIEVED / "unrel_shell0p5" / "family_table.csv").is_file():
            print()
            print(unrelieved_gain().round(3).to_string())


if __name__ == "__main__":
    main()
