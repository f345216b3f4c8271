"""Inputs of the documented discrepancy examples (docs/discrepancy.md), also used by workflow/rules/gap.smk.

``dem-measured``
    "Measured" data made by the DEM itself with one effect switched on, on packings the base model
    does not use (``packing.seed``), two packing seeds per case as replicates: the DEM end-to-end
    example hides an effect from ``deckgen gap --backend dem``.
``seed002``
    Seed 002's Table 4: forces measured on the full-scale rotary cutting machine (Shin et al. 2024)
    on Hwandeung granite at three installation radii and two penetrations, as MEASURED.csv, and a
    linear-cutting base case of the same disc and rock (``cases/gap/rcm_linear_base.yaml``).
"""

from __future__ import annotations

import argparse
import shlex
import sys
from pathlib import Path

import numpy as np
import pandas as pd

from deckgen.gap.data import RESPONSE_COLUMNS, flat_case
from deckgen.spec import load_case

DATA = Path("/work/shared/data")


def _value(s: str):
    try:
        return float(s)
    except ValueError:
        return s


def dem_measured(base: Path, out: Path, *, sets: dict[str, object], penetrations: list[float], seeds: list[int],
                 runs: Path, command: list[str] | None, cache: Path | None, jobs: int = 1) -> pd.DataFrame:
    from deckgen.gap.backends import DemBackend

    be = DemBackend(runs, command=command, cache=cache, jobs=jobs)
    flat0 = flat_case(load_case(base))
    keys, flats = [], []
    for p in penetrations:
        for r, seed in enumerate(seeds, 1):
            f = dict(flat0, **sets)
            f["kinematics.penetration_mm"] = p
            f["packing.seed"] = seed
            f["name"] = f"{flat0['name']}_measured"
            keys.append((p, r))
            flats.append(f)
    rows = [{"kinematics.penetration_mm": p, "replicate": r, **{k: y[k] for k in RESPONSE_COLUMNS}}
            for (p, r), y in zip(keys, be._run_all(flats))]
    df = pd.DataFrame(rows)
    out.parent.mkdir(parents=True, exist_ok=True)
    with out.open("w") as fh:
        fh.write(f"# DEM runs of {base} with {sets} (deckgen.gap.examples dem-measured), packing seeds {seeds} as replicates\n")
        df.to_csv(fh, index=False)
    return df


#: one DEM run per switch for the fast-vs-DEM validation (docs/discrepancy.md)
VALIDATION = {
    "base": {},
    "free_rolling": {"kinematics.spin": "rolling"},
    "wear_flat_0.6mm": {"cutter.wear_flat_mm": 0.6},
    "tilt_8deg": {"cutter.tilt_deg": 8.0},
    "rotary_r30mm": {"kinematics.mode": "rotary", "kinematics.rotary_radius_mm": 30.0},
    "relieved_S4mm": {"kinematics.neighbour_spacing_mm": 4.0},
    "confinement_5MPa": {"specimen.confining_stress_MPa": 5.0},
}


def validate(base: Path, out: Path, *, runs: Path, command: list[str] | None, cache: Path | None) -> pd.DataFrame:
    """Each switch once in the DEM and in the fast model; ratios to the base run side by side."""
    from deckgen.gap.backends import DemBackend
    from deckgen.gap.fast import predict_row

    be = DemBackend(runs, command=command, cache=cache)
    flat0 = flat_case(load_case(base))
    rows = []
    for name, sets in VALIDATION.items():
        f = dict(flat0, **sets)
        dem, fast = be.run_one(f), predict_row(f)
        rows.append({"variant": name, **{f"{k}_dem": dem[k] for k in RESPONSE_COLUMNS},
                     **{f"{k}_fast": fast[k] for k in RESPONSE_COLUMNS}})
        pd.DataFrame(rows).to_csv(out, index=False)
    df = pd.DataFrame(rows)
    df.to_csv(out, index=False)
    return df


def seed002_measured(out: Path) -> pd.DataFrame:
    """Seed 002 Table 4 as MEASURED.csv (forces in N; the side force is a magnitude in the seed and is
    written with deckgen's sign: the rock pushes the disc away from the cutterhead centre, -y')."""
    t = pd.read_csv(DATA / "shin2024_rcm_hwandeung_granite.csv", comment="#")
    df = pd.DataFrame({
        "kinematics.penetration_mm": t["penetration_mm"],
        "kinematics.rotary_radius_mm": t["radial_position_mm"],
        "force_normal_N_mean_steady": 1e3 * t["normal_force_measured_kN"],
        "force_rolling_N_mean_steady": 1e3 * t["rolling_force_measured_kN"],
        "force_side_N_mean_steady": -1e3 * t["side_force_measured_kN"],
    })
    out.parent.mkdir(parents=True, exist_ok=True)
    with out.open("w") as fh:
        fh.write("# Seed 002 Table 4: full-scale rotary cutting machine, Hwandeung granite (Shin et al. 2024), "
                 "17-inch disc, tip 21 mm, spacing 100 mm; forces in N, side force signed (away from the centre)\n")
        df.to_csv(fh, index=False)
    return df


def main(argv: list[str] | None = None) -> int:
    from deckgen.cli import main as cli_main

    ap = argparse.ArgumentParser(prog="python -m deckgen.gap.examples")
    sub = ap.add_subparsers(dest="cmd", required=True)
    d = sub.add_parser("dem-measured")
    d.add_argument("--base", required=True)
    d.add_argument("--out", required=True)
    d.add_argument("--runs", required=True)
    d.add_argument("--set", action="append", default=[], help="spec.path=value of the hidden effect")
    d.add_argument("--penetrations", default="1.0,1.5,2.0")
    d.add_argument("--seeds", default="101,202")
    d.add_argument("--ranks", type=int, default=1)
    d.add_argument("--jobs", type=int, default=1, choices=[1, 2, 3, 4], help="engine runs at a time")
    d.add_argument("--engine-cmd")
    d.add_argument("--cache")
    v = sub.add_parser("validate")
    v.add_argument("--base", required=True)
    v.add_argument("--out", required=True)
    v.add_argument("--runs", required=True)
    v.add_argument("--ranks", type=int, default=1)
    v.add_argument("--cache")
    s = sub.add_parser("seed002")
    s.add_argument("--out", required=True, help="folder: measured.csv and the gap report")
    s.add_argument("--base", default="cases/gap/rcm_linear_base.yaml")
    a = ap.parse_args(argv)
    if a.cmd == "dem-measured":
        from deckgen.runner import engine_command

        sets = dict(kv.split("=", 1) for kv in a.set)
        cmd = shlex.split(a.engine_cmd) if a.engine_cmd else engine_command(a.ranks)
        df = dem_measured(Path(a.base), Path(a.out), sets={k: _value(v) for k, v in sets.items()},
                          penetrations=[float(x) for x in a.penetrations.split(",")],
                          seeds=[int(x) for x in a.seeds.split(",")], runs=Path(a.runs), command=cmd,
                          cache=Path(a.cache) if a.cache else None, jobs=a.jobs)
        print(df.to_string(index=False))
        return 0
    if a.cmd == "validate":
        from deckgen.runner import engine_command

        df = validate(Path(a.base), Path(a.out), runs=Path(a.runs), command=engine_command(a.ranks),
                      cache=Path(a.cache) if a.cache else None)
        print(df.to_string(index=False))
        return 0
    out = Path(a.out)
    seed002_measured(out / "measured.csv")
    return cli_main(["gap", "--measured", str(out / "measured.csv"), "--base", a.base, "--out", str(out)])


if __name__ == "__main__":
    np.seterr(all="ignore")
    sys.exit(main())
