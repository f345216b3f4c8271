"""The recorded 44 mm smooth-cone ODC cuts beside the swept-floor model of their paths (session 24).

Reads the recorded tables of the smooth-cone runs (paths relative to this folder) and, for every oscillating run, the
model's engaged arc and contact fraction (src/deckgen/odc_kinematics.py) at the run's e, nu and orbit reading. Each
run's force is set over the straight cut of its own set (same cone, friction and speed) on its own packing where that
straight cut was run (``_k<seed>`` in the name; column straight_packing says which packing's cut was used). Writes
geometry_vs_dem.csv here, and geometry_seed003_paths.csv: the model on seed 003's own paths beside its forces, and the plot
geometry_vs_dem.png.

    python docs/families_runs/odc_kinematics/geometry_vs_dem.py

The diagnostics of this folder (a recorded summary of each, beside its case file here or in cases/odc/reduced; the
orbit_lift_ratio cuts of session 24, the packing-202 cuts of sessions 24-25) join set A: the same cone, friction and
speed as the family's smooth cuts.
"""
from __future__ import annotations

import argparse
import json
import re
from pathlib import Path

import pandas as pd

from deckgen.families import DEFAULT_PACKING_SEED as DEFAULT_PACKING  # cases without a _k<seed> suffix
from deckgen.odc_kinematics import Orbit, sweep
from deckgen.spec import orbit_lift

HERE = Path(__file__).resolve().parent
RUNS = HERE.parent
FAMILY_CASES = HERE.parents[2] / "cases" / "odc" / "reduced"
R_M, P_M = 0.010, 0.004
SETS = {  # set: (table, force column, note)
    "A": (RUNS / "odc_smooth/smoothcone_family/family_table.csv", "force_magnitude_N_mean_cycles_sliding",
          "x4, upright smooth cone, friction 0.3, turning with the shaft (session 11)"),
    "B": (RUNS / "odc_x1_smooth/x1_table.csv", "force_magnitude_N_mean_cycles_sliding",
          "x1 (seed's speed), upright smooth cone, friction 0.3, turning (session 23)"),
    "C": (RUNS / "odc_smooth/long_smooth_f0/family_table.csv", "force_magnitude_N_mean_cycles",
          "x4, cone tilted 9 deg, smooth, friction 0 (session 10; first-cycle means)"),
    "C_bottom": (RUNS / "odc_smooth/long_bottom_smooth_f0/family_table.csv", "force_magnitude_N_mean_cycles",
                 "as C, depth at the orbit's bottom"),
}


def _rows_of(set_name: str, table: Path, col: str) -> pd.DataFrame:
    t = pd.read_csv(table)
    name = t["variant_case"] if "variant_case" in t.columns else t["case"]
    out = pd.DataFrame({"set": set_name, "run": name, "force_N": t[col], "dem_contact_fraction_1": t["contact_fraction_steady_1"]})
    if set_name == "B":  # x1_table has the path as omega, speed and nu; the cases are the family's (bottom reading)
        out["eccentricity_mm"] = [0.0 if not (n > 0) else v / (n * w) * 1e3 for n, v, w in
                                  zip(t["velocity_ratio_nu_1"].fillna(0), t["cutter_speed_m_s"], t["omega_rad_s"])]
        out["nu_1"] = t["velocity_ratio_nu_1"]
        out["lift_1"] = 1.0
    else:
        out["eccentricity_mm"] = t["eccentricity_mm"].astype(float)
        out["nu_1"] = t["velocity_ratio_nu_1"]
        out["lift_1"] = [orbit_lift(p, None) for p in t["penetration_at"]]
    return out


def _lift_rows() -> pd.DataFrame:
    """The diagnostics of this folder: each ``<case>_summary.json`` (the run's parsed summary) beside its case file
    ``<case>.yaml`` (here, or the family's in cases/odc/reduced), whose kinematics give e and the orbit's lift; nu is
    the summary's (None for a straight cut)."""
    from deckgen.spec import load_case

    rows = []
    for summ in sorted(HERE.glob("*_summary.json")):
        s = json.loads(summ.read_text())
        case = HERE / f"{s['case']}.yaml"
        k = load_case(case if case.is_file() else FAMILY_CASES / case.name).kinematics
        osc = k.mode == "oscillation"
        rows.append({"set": "A", "run": s["case"], "force_N": s["force_magnitude_N_mean_cycles_sliding"],
                     "dem_contact_fraction_1": s["contact_fraction_steady_1"],
                     "eccentricity_mm": k.eccentricity_mm if osc else 0.0,
                     "nu_1": round(s["velocity_ratio_nu_1"], 3) if osc else float("inf"),
                     "lift_1": k.orbit_lift if osc else 1.0})
    return pd.DataFrame(rows)


def packing_of(run: str) -> int:
    """The packing seed of a run from its name (``..._k202...``), else the family's default."""
    m = re.search(r"_k(\d+)(?:_|$)", run)
    return int(m.group(1)) if m else DEFAULT_PACKING


def build() -> pd.DataFrame:
    parts = [_rows_of(s, *SETS[s][:2]) for s in SETS] + [_lift_rows()]
    t = pd.concat(parts, ignore_index=True)
    t["packing"] = t["run"].map(packing_of)
    # each set's straight cut on each packing where it was run (C_bottom shares C's)
    straight = t[t["eccentricity_mm"] == 0].groupby(["set", "packing"])[["force_N", "dem_contact_fraction_1"]].first()
    straight = pd.concat([straight, straight.loc[["C"]].rename(index={"C": "C_bottom"}, level="set")])
    t = t[t["eccentricity_mm"] > 0].copy()
    own = pd.Series(list(zip(t["set"], t["packing"])), index=t.index).isin(straight.index)
    t["straight_packing"] = t["packing"].where(own, DEFAULT_PACKING)
    ref = straight.loc[list(zip(t["set"], t["straight_packing"]))].set_axis(t.index)
    geo = []
    for r in t.itertuples():
        w = sweep(Orbit(R_M, P_M, r.eccentricity_mm * 1e-3, float(r.nu_1), float(r.lift_1)))
        geo.append((w.arc_ratio, w.contact_fraction, w.removal_ratio))
    t["geom_arc_ratio_1"], t["geom_contact_fraction_1"], t["geom_removal_ratio_1"] = zip(*geo)
    t["deepest_cut_mm"] = P_M * 1e3 + (1 - t["lift_1"]) * t["eccentricity_mm"]
    t["dem_force_ratio_1"] = t["force_N"] / ref["force_N"]
    t["dem_contact_rel_1"] = t["dem_contact_fraction_1"] / ref["dem_contact_fraction_1"]
    t["dem_over_geom_1"] = t["dem_force_ratio_1"] / t["geom_arc_ratio_1"]
    cols = ["set", "run", "packing", "straight_packing", "eccentricity_mm", "nu_1", "lift_1", "deepest_cut_mm", "force_N", "dem_force_ratio_1",
            "geom_arc_ratio_1", "dem_over_geom_1", "dem_contact_fraction_1", "dem_contact_rel_1",
            "geom_contact_fraction_1", "geom_removal_ratio_1"]
    return t[cols].round(4)


#: seed 003's mean force over its straight cut (712 N, sec. 5.4.3; Table 5.1 and sec. 5.4.3 in ../shared/data)
SEED003_RATIO = {(0.4, 22.5): 636 / 712, (0.4, 67.5): 442.3 / 712, (0.2, 22.5): 754 / 712, (0.1, 22.5): 735 / 712}


def seed_series(lifts=(0.0, 0.57, 1.0)) -> pd.DataFrame:
    """The model on seed 003's paths (R 10 mm, 4 mm, 0.5 m/s): its eccentricity series at 22.5 rev/s, its nu < 1
    frequency series (e/R 0.4) and the nu > 1 frequency series it did not run (e/R 0.1), at three orbit readings."""
    rows = []
    paths = [(er, f) for er in (0.1, 0.2, 0.4) for f in (22.5,)] + [(er, f) for er in (0.4, 0.1) for f in (45.0, 60.0, 67.5)]
    for er, f in paths:
        for lift in lifts:
            o = Orbit.from_rates(R_M, P_M, er * R_M, 0.5, f, lift)
            w = sweep(o)
            rows.append({"eccentricity_ratio_1": er, "rotation_rev_s": f, "nu_1": round(o.nu, 3), "lift_1": lift,
                         "geom_arc_ratio_1": w.arc_ratio, "geom_contact_fraction_1": w.contact_fraction,
                         "geom_removal_ratio_1": w.removal_ratio,
                         "seed_force_ratio_1": SEED003_RATIO.get((er, f), float("nan"))})
    return pd.DataFrame(rows).round(4)


def plot(t: pd.DataFrame, path: Path) -> None:
    """Each run's force ratio against the engaged-arc ratio of its path (log-log, with the 1:1 line)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5.5, 4.5))
    marks = {"A": "o", "B": "s", "C": "^", "C_bottom": "v"}
    short = {"A": "x4 upright smooth, friction 0.3", "B": "x1 upright smooth, friction 0.3",
             "C": "x4 tilted smooth, friction 0", "C_bottom": "as C, depth at orbit bottom"}
    for name, g in t.groupby("set"):
        ax.scatter(g["geom_arc_ratio_1"], g["dem_force_ratio_1"], marker=marks.get(name, "x"),
                   label=f"{name}: {short.get(name, name)}")
    lo, hi = 0.15, 20
    ax.plot([lo, hi], [lo, hi], "k:", lw=1, label="force ratio = arc ratio")
    ax.set(xscale="log", yscale="log", xlim=(0.15, 1.2), ylim=(lo, hi), xlabel="engaged arc / straight cut's (model)",
           ylabel="mean force / straight cut's (bonded-particle runs)")
    ax.legend(fontsize=7, loc="upper left")
    for r in t[t["deepest_cut_mm"] > 5].itertuples():
        ax.annotate(f"{r.deepest_cut_mm:g} mm deep", (r.geom_arc_ratio_1, r.dem_force_ratio_1), fontsize=6,
                    xytext=(4, -8), textcoords="offset points")
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)


def main() -> None:
    argparse.ArgumentParser(description=__doc__.split("\n")[0]).parse_args()
    t = build()
    t.to_csv(HERE / "geometry_vs_dem.csv", index=False)
    plot(t, HERE / "geometry_vs_dem.png")
    seed = seed_series()
    seed.to_csv(HERE / "geometry_seed003_paths.csv", index=False)
    with pd.option_context("display.width", 250, "display.max_columns", 30):
        print(t.to_string(index=False))
        print(seed.to_string(index=False))


if __name__ == "__main__":
    main()
