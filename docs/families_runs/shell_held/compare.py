"""Recorded runs against the same cases on the fixed deck, where the cutter's shell is held in y (session 34).

Until session 34 the straight, indentation and untilted eccentric branches of ``templates/lammps/cutting.lmp.j2`` moved
the shell with ``fix move variable v_dx NULL v_dz v_vx NULL v_vz``. LAMMPS integrates a component whose displacement
and velocity are both NULL from the force on each atom, so every shell sphere was free to drift sideways under the
rock's push (the rotary and tilted branches gave all six variables and were right). The runs here are recorded family
cases (and session 32's finer-shell and session 31's unrelieved diagnostics) rendered again after the fix and run
unchanged otherwise: the same grains and bonds as the recorded run (checked), so each pair differs only in the deck's y
motion of the shell. Session 35 added 16 linear family cases (22 in ``linear``), the unrelieved pairs and the 45 mm
block at p 1.9 and 7.6 mm (``linear_block45``, no recorded p 7.6 mm run to pair with) and a 24 mm high block
(``linear_h24``, new).

    python docs/families_runs/shell_held/compare.py

Prints, per kind, one row per case (recorded, held, held / recorded) and the geometric mean of held / recorded with
its 95 % interval (``../rotary_shell0p5/compare.py``'s ``gain_row``); then, where both shells ran on the fixed deck,
the finer shell's gain over the default one; F_n at p 7.6 / 1.9 mm with and without the neighbour grooves; seed 001's
eq. 7 form and the family's trends on the held runs beside the recorded runs of the same cases.
"""
from __future__ import annotations

import importlib.util
from pathlib import Path

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


def load_gain_row():
    """``gain_row`` of ../rotary_shell0p5/compare.py (geometric mean of paired ratios with its 95 % t interval)."""
    path = RUNS / "rotary_shell0p5" / "compare.py"
    spec = importlib.util.spec_from_file_location("rotary_shell0p5_compare", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod.gain_row


def _has(kind: str) -> bool:
    """Whether the held-shell report of ``kind`` exists."""
    return (KINDS[kind][1] / "family_table.csv").is_file()


def _case(base: str, packing: int, tail: str = "") -> str:
    """The case name of ``base`` (e.g. ``lin_red_s100_p1p9``) on ``packing``: the default packing 12345 has no suffix."""
    return f"{base}{'' if packing == 12345 else f'_k{packing}'}{tail}"


def _value(t: pd.DataFrame, name: str, col: str) -> float:
    """``t.loc[name, col]``, NaN where the case was not re-run."""
    return t.loc[name, col] if name in t.index else float("nan")


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
    its grains and bonds."""
    old_dir, new_dir, key, metrics = KINDS[kind]
    new_path = new_dir / "family_table.csv"
    if not new_path.is_file():
        raise SystemExit(f"{new_path}: no report yet (fix: run the held-shell re-runs, docs/families.md, section "
                         "\"The cutter shell held in y\")")
    new = pd.read_csv(new_path).set_index(key)
    old = pd.read_csv(old_dir / "family_table.csv").set_index(key).reindex(new.index)
    if old["n_grains"].isna().any():
        raise ValueError(f"{old_dir}: no recorded run for {list(new.index[old['n_grains'].isna()])}")
    if (old["n_grains"] != new["n_grains"]).any() or (old["n_bonds_initial"] != new["n_bonds_initial"]).any():
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


def main() -> None:
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
        for kind in ("linear", "indentation"):
            if _has(kind):
                print()
                print(f"== the {kind} family's trends, recorded and held runs of the same cases")
                print(trends_same_cases(kind).round(3).T.to_string())


if __name__ == "__main__":
    main()
