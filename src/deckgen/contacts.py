"""What carries the load on the cutter: the rock body, chips or loose debris.

A shell cutter (``cutter.shell_coverage``: spheres of atom type 2 that move with the disc) touches the rock grains
(type 1) through ``pair_style granular`` with ``hertz/material``. The per-atom dumps hold every grain's centre and
radius, so the elastic normal force of each grain-shell contact can be rebuilt at each dumped step:

    F = 4/3 E* sqrt(R_eff delta) delta,   1/E* = (1 - nu_c^2)/E_c + (1 - nu_s^2)/E_s   (Hertz; deck.effective_modulus)

along the line of centres, with ``delta`` the overlap and ``R_eff`` the reduced radius. The damping (tsuji) and the
tangential (mindlin) parts are left out: they need velocities and contact histories the dumps do not hold, so the
rebuilt force is checked against the run's own series (the cutter's summed force at the same step) in every row.

Each touching grain is classed by the bond graph at that step (initial bonds minus those broken up to it,
:func:`deckgen.chips.bond_components`): ``body`` (the largest component), ``chip`` (another component of at least
``min_grains`` grains) or ``debris`` (smaller: mostly single grains whose bonds all broke). A disc that presses on
debris rather than on the body is riding on its own crushed grains, which in a bonded-particle model stay as big as
the grains: a cut shallower than a grain diameter cannot put them out of the way.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.spatial import cKDTree

from deckgen.chips import bond_components, initial_bonds
from deckgen.deck import effective_modulus
from deckgen.parse.dump import iter_frames
from deckgen.spec import GPA, SpecError

CLASSES = ("body", "chip", "debris")
CENSUS_COLUMNS = ["step", "time_s", "grains_touching", *(f"grains_touching_{c}" for c in CLASSES),
                  "force_x_hertz_N", "force_y_hertz_N", "force_z_hertz_N",
                  *(f"force_z_hertz_{c}_N" for c in CLASSES), "detached_share_z_1",
                  "force_x_series_N", "force_z_series_N"]


def hertz_stiffness(case: dict) -> float:
    """4/3 E* (Pa) of a grain-shell contact from the case's ``contact`` section, as the deck gives it to LAMMPS."""
    c = case["contact"]
    nu_c = float(c["poisson_ratio"])
    e_deck = effective_modulus(float(c["youngs_modulus_GPa"]) * GPA, nu_c, float(c["cutter_youngs_modulus_GPa"]) * GPA,
                               float(c["cutter_poisson_ratio"]), nu_c)
    return 4.0 / 3.0 * e_deck / (2.0 * (1.0 - nu_c**2))  # LAMMPS mixes an explicit i-j E with itself


def frame_census(atoms: pd.DataFrame, k_hertz: float, label: np.ndarray, body: int, sizes: np.ndarray,
                 min_grains: int = 2) -> dict[str, float]:
    """Grains of ``atoms`` (columns id, type, radius, x, y, z; rock type 1 in the order of ``label``) that overlap a
    shell sphere (type 2), by class, and the Hertz normal force they put on the cutter (N, global axes)."""
    rock, shell = atoms[atoms["type"] == 1], atoms[atoms["type"] == 2]
    out: dict[str, float] = {"grains_touching": 0, **{f"grains_touching_{c}": 0 for c in CLASSES},
                             "force_x_hertz_N": 0.0, "force_y_hertz_N": 0.0, "force_z_hertz_N": 0.0,
                             **{f"force_z_hertz_{c}_N": 0.0 for c in CLASSES}}
    if not len(rock) or not len(shell):
        return out
    xr, rr = rock[["x", "y", "z"]].to_numpy(float), rock["radius"].to_numpy(float)
    xs, rs = shell[["x", "y", "z"]].to_numpy(float), shell["radius"].to_numpy(float)
    pairs = cKDTree(xr).sparse_distance_matrix(cKDTree(xs), rr.max() + rs.max(), output_type="ndarray")
    i, j, d = pairs["i"], pairs["j"], pairs["v"]
    delta = rr[i] + rs[j] - d
    hit = (delta > 0) & (d > 0)
    i, j, d, delta = i[hit], j[hit], d[hit], delta[hit]
    reff = rr[i] * rs[j] / (rr[i] + rs[j])
    f = k_hertz * np.sqrt(reff * delta) * delta
    # on the cutter: along grain -> shell centre
    fvec = f[:, None] * (xs[j] - xr[i]) / d[:, None]
    cls = np.where(label[i] == body, 0, np.where(sizes[label[i]] >= min_grains, 1, 2))
    touching = np.unique(i)
    out["grains_touching"] = int(len(touching))
    grain_cls = np.zeros(len(rr), int)
    grain_cls[i] = cls
    for n, c in enumerate(CLASSES):
        out[f"grains_touching_{c}"] = int((grain_cls[touching] == n).sum())
        out[f"force_z_hertz_{c}_N"] = float(fvec[cls == n, 2].sum())
    out["force_x_hertz_N"], out["force_y_hertz_N"], out["force_z_hertz_N"] = (float(v) for v in fvec.sum(axis=0))
    return out


def cutter_load_census(run_dir: str | Path, broken: pd.DataFrame, series: pd.DataFrame,
                       min_grains: int = 2) -> pd.DataFrame:
    """One row per dumped step of ``run_dir`` (atoms.dump.gz frames, then final.dump.gz when it is a later step):
    :data:`CENSUS_COLUMNS`. ``broken`` is the parsed broken-bond table (id1, id2, step) and ``series`` the parsed
    time series (step, time_s, force_x_N, force_z_N); ``detached_share_z_1`` is the share of the rebuilt F_z that
    chips and debris carry (NaN without contact).

    Raises SpecError naming the run folder when the cutter has no shell spheres (a wall-region cutter's contacts
    are not in the dumps), FileNotFoundError when the initial bonds are unknown."""
    run_dir = Path(run_dir)
    if not (run_dir / "spec.json").is_file():
        raise FileNotFoundError(f"{run_dir / 'spec.json'}: no spec.json (fix: a folder made by `deckgen render`)")
    spec = json.loads((run_dir / "spec.json").read_text())
    if not int(spec["derived"].get("n_shell", 0)):
        raise SpecError(f"{run_dir}: the cutter has no shell spheres (a wall region): its contacts are not in the "
                         "dumps (fix: a case with cutter.shell_coverage)")
    bonds = initial_bonds(run_dir)
    if bonds is None:
        raise FileNotFoundError(f"{run_dir}: no specimen.data and no step-0 bond sample: the initial bonds are unknown")
    k_hertz = hertz_stiffness(spec["case"])
    br_steps = broken["step"].to_numpy(np.int64)
    br_pairs = broken[["id1", "id2"]].to_numpy(np.int64)
    ts = series.drop_duplicates("step", keep="last").set_index("step").sort_index()  # a restart repeats steps
    rows, last = [], -1
    for name in ("atoms.dump.gz", "final.dump.gz"):
        path = run_dir / name
        if not path.is_file():
            continue
        for fr in iter_frames(path, ["id", "type", "radius", "x", "y", "z"]):
            if fr.timestep <= last:
                continue
            last = fr.timestep
            atoms = fr.data
            ids = atoms.loc[atoms["type"] == 1, "id"].to_numpy(np.int64)
            label, sizes, body = bond_components(bonds, br_pairs[br_steps <= fr.timestep], ids)
            row = {"step": fr.timestep, **frame_census(atoms, k_hertz, label, body, sizes, min_grains)}
            fz = row["force_z_hertz_N"]
            row["detached_share_z_1"] = ((row["force_z_hertz_chip_N"] + row["force_z_hertz_debris_N"]) / fz
                                         if fz > 0 else float("nan"))
            at = ts.index.get_indexer([fr.timestep], method="nearest")[0] if len(ts) else -1
            row["time_s"] = float(ts["time_s"].iloc[at]) if at >= 0 else float("nan")
            row["force_x_series_N"] = float(ts["force_x_N"].iloc[at]) if at >= 0 else float("nan")
            row["force_z_series_N"] = float(ts["force_z_N"].iloc[at]) if at >= 0 else float("nan")
            rows.append(row)
    return pd.DataFrame(rows, columns=CENSUS_COLUMNS)


def census_of_parsed(run_dir: str | Path, parsed_dir: str | Path, min_grains: int = 2) -> pd.DataFrame:
    """:func:`cutter_load_census` of ``run_dir`` with the broken bonds and the series that ``deckgen parse`` wrote to
    ``parsed_dir``."""
    parsed_dir = Path(parsed_dir)
    for f in ("broken.parquet", "timeseries.parquet"):
        if not (parsed_dir / f).is_file():
            raise FileNotFoundError(f"{parsed_dir / f}: missing (fix: `deckgen parse {run_dir} --out {parsed_dir}`)")
    return cutter_load_census(run_dir, pd.read_parquet(parsed_dir / "broken.parquet"),
                              pd.read_parquet(parsed_dir / "timeseries.parquet"), min_grains)
