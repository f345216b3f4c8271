"""Result tables of engine runs: one run folder -> tidy tables + a flat summary; many -> tables.

:func:`parse_run` reads a run folder (``spec.json``, ``series.txt``, ``broken.dump.gz``,
``atoms.dump.gz``, ``final.dump.gz``, ``bonds.dump.gz``, ``log.lammps``, ``run.json``; see
``templates/lammps/*.j2`` for what the decks write) and writes, each as ``.parquet`` and ``.csv``:

``timeseries``
    one row per series sample (duplicate steps of ``fix print`` at each ``run`` setup dropped,
    the last kept). Platen tests (UCS, BTS): ``time_s, step, platen_displacement_m, force_top_N,
    force_bottom_N, stress_Pa, strain_1, bonds_intact, bonds_broken, broken_fraction_1,
    kinetic_energy_J``; ``stress_Pa = -force_top_N / area_m2`` is compression positive (BTS: the
    deck's area is pi D t / 2, so it is the Brazilian tensile stress 2F/(pi D t)); ``strain_1`` is
    platen displacement / specimen height. Cutting: ``time_s, step, cutter_{x,y,z}_m,
    force_{x,y,z}_N, torque_{x,y,z}_Nm, spin_angle_rad, force_magnitude_N`` (global frame; force and
    torque ON the cutter FROM the rock, torque about the moving disc centre) plus the cutter frame
    (disc axis y, cut direction +x, z up): ``force_normal_N = Fz`` (rock pushes the disc up),
    ``force_rolling_N = -Fx`` (positive when it resists the forward motion), ``force_side_N = Fy``,
    ``torque_axis_Nm = Ty`` (a tilted disc that spins: T along its own axis); ``cutter_advance_m = x - x0``; indentation also
    ``penetration_m = (z0 - z) - start_clearance``.
``broken``
    one row per broken bond: ``id1, id2`` (id1 < id2), ``step`` (time step of breakage),
    ``time_s = step * dt``, ``x_m, y_m, z_m`` (bond centre), ``mode`` and the bond state it was
    classed from (``btype, sample_step, bond_force_normal_N, bond_force_shear_N``).
``broken_timeseries``
    cumulative broken bonds on the series steps: ``bonds_broken`` and by mode
    ``bonds_broken_tension|shear|unknown`` (events with ``step <=`` the row's step).
``damage``
    one row per rock grain (type 1): ``id, radius_m, x_m, y_m, z_m`` (initial state),
    ``bonds_initial`` (first frame of ``atoms.dump.gz``), ``bonds_final`` (``final.dump.gz``, or
    the last frame of ``atoms.dump.gz`` when the run stopped before writing it),
    ``damage_ratio_1 = 1 - bonds_final / bonds_initial`` (broken / initial bonds as in seed 000;
    NaN for grains without an initial bond or missing from the final frame; a grain deleted as loose debris by
    ``run.debris_removal_every`` has ``bonds_final`` 0, is counted in ``n_grains_deleted_debris`` and not missing).
``summary.json``
    one flat dict of scalars (NaN written as ``null``), see :func:`parse_run`.

Failure mode of a bond (``mode``), from the optional ``bonds.dump.gz`` (``dump local`` of every
intact bond: ``id1 id2 btype dist r0 fx fy fz``; f = total bond force on atom id1): at the last
sample strictly before the breakage step, ``f_n = k_r[btype] (dist - r0)`` (tension positive,
the elastic normal force of ``bpm/rotational``) and ``f_s = sqrt(max(|f|^2 - f_n^2, 0))``; the
bond is ``tension`` if ``max(f_n, 0) / F_rc >= f_s / F_sc`` (strengths of its type from
``spec.json`` derived.bond_coefficients), else ``shear``; ``unknown`` without a sample, or when its
last sample carries no load (both ratios 0, e.g. the step-0 sample), or without ``bonds.dump.gz``
(then every mode is unknown and the summary says so). The join streams: sample
frames are read one at a time in step order, a dict ``(id1, id2) -> last state`` is updated, and
the broken bonds, ordered by step, are resolved just before the first sample at or after their
breakage step.

:func:`aggregate` concatenates parsed runs into ``forces_timeseries``, ``forces_summary``,
``platen_timeseries``, ``platen_summary``, ``damage_summary``, ``broken_bonds_timeseries``
(all with ``case`` and ``engine`` columns; empty kinds are written with their columns).

Streaming: series and logs are read line by line, dumps frame by frame (never a whole dump in
memory). Corrupt files raise :class:`deckgen.parse.ParseError` (``file:line``). A file cut off at
its end is accepted only when the run did not complete (log with an ERROR or unfinished, no
``final.dump.gz``): the readable part is used and the summary's ``notes`` name the file and line.
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from deckgen.deck import FLAT_JOINT_BROKEN
from deckgen.parse import ParseError, TruncatedError, check_log, iter_frames, read_series
from deckgen.parse.common import open_text

__all__ = [
    "CUTTING_SUMMARY_COLUMNS",
    "CUTTING_TIMESERIES_COLUMNS",
    "PLATEN_SUMMARY_COLUMNS",
    "PLATEN_TIMESERIES_COLUMNS",
    "STAT_SUFFIXES",
    "UNITLESS_COLUMNS",
    "UNIT_SUFFIXES",
    "aggregate",
    "has_unit",
    "parse_run",
    "read_table",
    "steady_mask",
    "write_table",
]

#: Column names without a unit suffix: labels, ids and counts.
UNITLESS_COLUMNS = frozenset({
    "chip", "chips_count", "chips_grains", "debris_grains", "body_grains", "largest_chip_grains",
    "case", "engine", "test", "mode", "step", "id", "id1", "id2", "btype", "sample_step",
    "bonds_intact", "peak_reached", "bonds_broken", "bonds_broken_tension", "bonds_broken_shear",
    "bonds_broken_unknown", "bonds_initial", "bonds_final", "n_grains", "n_bonds_initial",
    "n_grains_bonded", "n_grains_missing_final", "n_grains_deleted_debris", "grains_inside_cutter_final", "steps",
    "final_step", "damage_step", "detachment_step", "detached_piece_grains",
    "steady_rows", "modulus_fit_points", "bonds_broken_at_peak", "bonds_broken_series", "bonds_broken_at_split",
    "split_crack_bonds", "split_source",
    "bonds_broken_dumps", "run_completed", "kinematics_mode", "damage_source", "mode_source",
    "steady_window_source", "notes", "log_failure", "detachment_min_grains", "detachment_min_grains_source",
})

#: Suffixes that carry a unit (SI) in column names; ``_1`` = dimensionless.
UNIT_SUFFIXES = ("_s", "_m", "_N", "_Nm", "_Pa", "_1", "_J", "_rad", "_m2", "_m3", "_J_m3", "_m_s",
                 "_rad_s", "_per_s")
#: Statistic suffixes after the unit (``force_normal_N_mean_steady``).
STAT_SUFFIXES = ("_mean_steady", "_sem_steady", "_mean_cycles", "_mean_cycles_sliding", "_peak", "_destructive")


def has_unit(name: str) -> bool:
    """True if a column name carries its unit (or is a label, id or count)."""
    names = [name] + [name[: -len(st)] for st in STAT_SUFFIXES if name.endswith(st)]
    return any(n in UNITLESS_COLUMNS or n.endswith(UNIT_SUFFIXES) for n in names)

PLATEN_TIMESERIES_COLUMNS = [
    "time_s", "step", "platen_displacement_m", "force_top_N", "force_bottom_N", "stress_Pa",
    "strain_1", "bonds_intact", "bonds_broken", "broken_fraction_1", "kinetic_energy_J",
    "lateral_strain_1",
]
CUTTING_TIMESERIES_COLUMNS = [
    "time_s", "step", "cutter_x_m", "cutter_y_m", "cutter_z_m", "force_x_N", "force_y_N",
    "force_z_N", "torque_x_Nm", "torque_y_Nm", "torque_z_Nm", "spin_angle_rad", "path_angle_rad",
    "force_magnitude_N", "force_normal_N", "force_rolling_N", "force_side_N", "torque_axis_Nm",
    "cutter_advance_m", "penetration_m", "bonds_intact", "bonds_broken", "broken_fraction_1",
    "kinetic_energy_J",
]
BROKEN_COLUMNS = ["id1", "id2", "step", "time_s", "x_m", "y_m", "z_m", "mode", "btype",
                  "sample_step", "bond_force_normal_N", "bond_force_shear_N"]
BROKEN_TS_COLUMNS = ["time_s", "step", "bonds_broken", "bonds_broken_tension",
                     "bonds_broken_shear", "bonds_broken_unknown"]
DAMAGE_COLUMNS = ["id", "radius_m", "x_m", "y_m", "z_m", "bonds_initial", "bonds_final",
                  "damage_ratio_1"]

#: Cutter-frame quantities summarised for cutting runs (``<name>_mean_steady``, ``<name>_sem_steady``, ``<name>_peak``).
CUTTING_QUANTITIES = ["force_normal_N", "force_rolling_N", "force_side_N", "torque_axis_Nm",
                      "force_magnitude_N"]

_COMMON_SUMMARY = [
    "case", "test", "engine", "n_grains", "n_bonds_initial", "bonds_broken", "broken_fraction_1",
    "bonds_broken_tension", "bonds_broken_shear", "bonds_broken_unknown", "mode_source",
    "bonds_broken_series", "bonds_broken_dumps", "damage_ratio_mean_1",
    "damaged_grain_fraction_1", "n_grains_bonded", "n_grains_missing_final", "n_grains_deleted_debris", "damage_source",
    "damage_step", "dt_s", "final_step", "final_time_s", "run_completed", "steps", "wall_s",
    "loop_s", "particle_steps_per_s", "log_failure", "notes",
]
PLATEN_SUMMARY_COLUMNS = _COMMON_SUMMARY + [
    "peak_stress_Pa", "strain_at_peak_1", "time_at_peak_s", "peak_force_N",
    "bonds_broken_at_peak", "youngs_modulus_Pa", "secant_modulus_Pa", "modulus_fit_points",
    "modulus_fit_intercept_Pa", "modulus_fit_stress_lo_Pa", "modulus_fit_stress_hi_Pa",
    "final_strain_1", "max_strain_1", "post_peak_drop_1", "peak_reached", "area_m2", "height_m", "platen_speed_m_s",
    "poisson_ratio_1", "split_stress_Pa", "split_strain_1", "bonds_broken_at_split", "split_crack_bonds",
    "split_localisation_1", "split_source",
]
CUTTING_SUMMARY_COLUMNS = _COMMON_SUMMARY + [
    f"{q}_{s}" for q in CUTTING_QUANTITIES for s in ("mean_steady", "mean_cycles", "mean_cycles_sliding", "peak")
] + ["cycles_averaged_1",
    "contact_fraction_steady_1", "rolling_to_normal_ratio_1", "velocity_ratio_nu_1",
    "kinematics_mode", "cut_duration_s", "steady_start_s", "steady_end_s", "steady_rows",
    "cutter_radius_m", "cutter_speed_m_s", "eccentricity_m", "omega_rad_s", "travel_m",
    "penetration_m", "grains_inside_cutter_final",
]
DAMAGE_SUMMARY_COLUMNS = [
    "case", "engine", "test", "n_grains", "n_grains_bonded", "n_grains_missing_final",
    "n_bonds_initial", "bonds_broken", "broken_fraction_1", "bonds_broken_tension",
    "bonds_broken_shear", "bonds_broken_unknown", "mode_source", "damage_ratio_mean_1",
    "damaged_grain_fraction_1", "damage_source", "damage_step",
]

_PLATEN_RENAME = {
    "time_s": "time_s", "platen_displacement_m": "platen_displacement_m",
    "force_top_N": "force_top_N", "force_bottom_N": "force_bottom_N", "stress_Pa": "stress_Pa",
    "strain": "strain_1", "bonds": "bonds_intact", "ke_J": "kinetic_energy_J",
}
_CUTTING_RENAME = {
    "time_s": "time_s", "cutter_x_m": "cutter_x_m", "cutter_y_m": "cutter_y_m",
    "cutter_z_m": "cutter_z_m", "force_x_N": "force_x_N", "force_y_N": "force_y_N",
    "force_z_N": "force_z_N", "torque_x_Nm": "torque_x_Nm", "torque_y_Nm": "torque_y_Nm",
    "torque_z_Nm": "torque_z_Nm", "spin_angle_rad": "spin_angle_rad", "bonds": "bonds_intact",
    "ke_J": "kinetic_energy_J",
}

#: |F| above which the cutter counts as in contact with the rock.
CONTACT_THRESHOLD_N = 1e-9
#: Pre-peak window of the modulus fit, as fractions of the peak stress.
MODULUS_WINDOW = (0.2, 0.5)
#: A platen test has failed (its peak is a strength, not the stress where the run stopped) when the
#: stress at the last sample is at least this fraction below the peak and the peak lies before this
#: fraction of the final strain. The stop rules end runs at 20-80 % below the peak; a run cut by
#: ``max_strain`` before the peak ends at or near its maximum.
PEAK_DROP_MIN = 0.1
PEAK_STRAIN_MAX_FRACTION = 0.97
#: ... or when the run ended below this fraction of its ``max_strain`` (the stop rule fired; a run that
#: reaches max_strain ends at or just above it).
STOPPED_EARLY_FRACTION = 0.99
#: A peak before this fraction of the final strain is a failure whatever the drop: the load never came
#: back to it over the last 10 % of the run (a split Brazilian disc whose halves keep some jaw load).
PEAK_CLEARLY_EARLY_FRACTION = 0.9

#: Brazilian split (docs/calibration.md, section "BTS at the split"): a disc has split when the bonds broken along
#: its loaded diameter (within SPLIT_BAND R of the loading line and SPLIT_CORE R of the disc centre, the crushed
#: zones under the jaws left out) number SPLIT_CRACK_SHARE x the bonds one diametral plane cuts,
#: n_bonds l / (pi R) for bond length l = r_min + r_max (an isotropic bond network).
SPLIT_CRACK_SHARE = 1.0
SPLIT_BAND = 0.3
SPLIT_CORE = 0.7

_PLATEN_TESTS = ("ucs", "bts")


# ----------------------------------------------------------------------------- helpers
def write_table(df: pd.DataFrame, stem: Path) -> Path:
    """Write ``stem.parquet`` and ``stem.csv``; return the parquet path."""
    stem.parent.mkdir(parents=True, exist_ok=True)
    pq = stem.with_name(stem.name + ".parquet")
    df.to_parquet(pq, index=False)
    df.to_csv(stem.with_name(stem.name + ".csv"), index=False)
    return pq


def read_table(stem: Path) -> pd.DataFrame:
    """Read ``stem.parquet`` (as written by :func:`write_table`)."""
    return pd.read_parquet(stem.with_name(stem.name + ".parquet"))


def _nan() -> float:
    return float("nan")


def _scalar(v: Any) -> Any:
    """Plain Python scalar (numpy -> int/float/bool)."""
    if isinstance(v, (np.bool_, bool)):
        return bool(v)
    if isinstance(v, (np.integer,)):
        return int(v)
    if isinstance(v, (np.floating, float)):
        return float(v)
    return v


def _json_safe(d: dict[str, Any]) -> dict[str, Any]:
    out = {}
    for k, v in d.items():
        v = _scalar(v)
        if isinstance(v, float) and not math.isfinite(v):
            v = None
        out[k] = v
    return out


class _RunState:
    """What is known about how the run ended; collects notes."""

    def __init__(self, run_dir: Path) -> None:
        self.run_dir = run_dir
        self.notes: list[str] = []
        self.log_failure = ""
        self.completed = True
        self.steps: int | float = _nan()
        self.wall_s: float = _nan()
        self.loop_s: float = _nan()
        self.particle_steps_per_s: float = _nan()
        log = run_dir / "log.lammps"
        if not log.is_file() and (run_dir / "log.liggghts").is_file():
            log = run_dir / "log.liggghts"
        run_json = run_dir / "run.json"
        health = None
        if log.is_file():
            health = check_log(log)
            self.completed = health.ok
            if not health.ok:
                self.log_failure = health.failure() or ""
                self.notes.append(f"run did not complete: {self.log_failure}")
            self.steps = int(health.total_steps)
            self.loop_s = float(health.loop_seconds)
            if health.particle_steps_per_s:
                self.particle_steps_per_s = float(health.particle_steps_per_s)
        else:
            self.notes.append("no log.lammps")
        if run_json.is_file():
            rj = json.loads(run_json.read_text())
            self.wall_s = float(rj.get("wall_s", _nan()))
            if rj.get("particle_steps_per_s") is not None:
                self.particle_steps_per_s = float(rj["particle_steps_per_s"])
            if rj.get("steps") is not None:
                self.steps = int(rj["steps"])
            if rj.get("loop_s") is not None:
                self.loop_s = float(rj["loop_s"])
        else:
            self.notes.append("no run.json (wall_s unknown)")
            if health is None:
                self.completed = False
        if not (run_dir / "final.dump.gz").is_file():
            self.completed = False
            self.notes.append("no final.dump.gz (run stopped before its final write_dump)")

    def truncated(self, exc: TruncatedError) -> None:
        """A file ends early: fine for an incomplete run (noted), an error otherwise."""
        if self.completed:
            raise exc
        self.notes.append(f"truncated file, readable part used: {exc}")


def _frames(path: Path, state: _RunState, columns: Iterable[str] | None = None) -> Iterator[Any]:
    """Frames of a dump; a truncated tail ends the iteration for incomplete runs."""
    it = iter_frames(path, columns)
    while True:
        try:
            fr = next(it)
        except StopIteration:
            return
        except TruncatedError as exc:
            state.truncated(exc)
            return
        yield fr


def _series(path: Path, state: _RunState) -> pd.DataFrame:
    try:
        df = read_series(path)
    except TruncatedError as exc:
        state.truncated(exc)
        df = read_series(path, allow_truncated_tail=True)
    if "step" not in df.columns:
        raise ParseError(path, 1, "series file has no 'step' column")
    # fix print writes a row at the setup of every run: the same step twice -> keep the last
    df = df.drop_duplicates(subset="step", keep="last").sort_values("step", kind="stable")
    return df.reset_index(drop=True)


def _require(df: pd.DataFrame, names: Iterable[str], path: Path) -> None:
    missing = [n for n in names if n not in df.columns]
    if missing:
        raise ParseError(path, 1, f"series title lacks column(s) {' '.join(missing)}; "
                         f"it has {' '.join(df.columns)}")


def steady_mask(time_s: np.ndarray | pd.Series, duration_s: float,
                window: tuple[float, float] | list[float]) -> np.ndarray:
    """Rows of the steady window: ``a * duration <= time_s <= b * duration``."""
    a, b = float(window[0]), float(window[1])
    t = np.asarray(time_s, dtype=float)
    return (t >= a * duration_s) & (t <= b * duration_s)


def mean_standard_error(values: np.ndarray | pd.Series) -> dict[str, float]:
    """Standard error of the mean of a correlated series (a force over the steady window), from its integrated
    autocorrelation time: ``tau = 1 + 2 * sum(acf[1:k])`` with the sum cut at the first lag ``k`` where the sample
    autocorrelation (statsmodels ``acf``, FFT) falls below zero; ``n_eff = n / tau`` and ``sem = std / sqrt(n_eff)``.

    A cutting force rises and drops with the chips, so neighbouring rows are far from independent: ``std / sqrt(n)``
    would understate the error by ``sqrt(tau)``. Cutting the sum at the first zero is the simple window (it
    underestimates ``tau`` a little for slowly decaying correlation; with few chips in the window the estimate itself
    is rough). Returns ``sem``, ``tau_rows`` (tau in rows) and ``n_eff``; NaN for fewer than 3 finite values."""
    from statsmodels.tsa.stattools import acf

    x = np.asarray(values, dtype=float)
    x = x[np.isfinite(x)]
    if len(x) < 3 or np.all(x == x[0]):
        nan = float("nan")
        return {"sem": nan if len(x) < 3 else 0.0, "tau_rows": nan, "n_eff": nan if len(x) < 3 else float(len(x))}
    rho = acf(x, nlags=len(x) - 1, fft=True)
    below = np.flatnonzero(rho < 0)
    k = int(below[0]) if len(below) else len(rho)
    tau = max(1.0, 1.0 + 2.0 * float(rho[1:k].sum()))
    n_eff = len(x) / tau
    return {"sem": float(x.std(ddof=1) / math.sqrt(n_eff)), "tau_rows": tau, "n_eff": n_eff}


# ----------------------------------------------------------------------------- timeseries
def _platen_timeseries(raw: pd.DataFrame, path: Path, n0: int) -> pd.DataFrame:
    _require(raw, ["step", *_PLATEN_RENAME], path)
    ts = pd.DataFrame({"time_s": raw["time_s"].astype(float), "step": raw["step"].astype(np.int64)})
    for src, dst in _PLATEN_RENAME.items():
        if dst in ("time_s", "bonds_intact"):
            continue
        ts[dst] = raw[src].astype(float)
    ts["bonds_intact"] = np.rint(raw["bonds"].astype(float)).astype(np.int64)
    ts["bonds_broken"] = n0 - ts["bonds_intact"]
    ts["broken_fraction_1"] = ts["bonds_broken"] / n0 if n0 else _nan()
    # UCS decks print the lateral strain (mean radial displacement of the outer mid-height grains / R)
    ts["lateral_strain_1"] = raw["lateral_strain"].astype(float) if "lateral_strain" in raw else _nan()
    return ts[PLATEN_TIMESERIES_COLUMNS]


def _cutting_timeseries(raw: pd.DataFrame, path: Path, n0: int, spec: dict[str, Any]) -> pd.DataFrame:
    _require(raw, ["step", *_CUTTING_RENAME], path)
    ts = pd.DataFrame({"time_s": raw["time_s"].astype(float), "step": raw["step"].astype(np.int64)})
    for src, dst in _CUTTING_RENAME.items():
        if dst in ("time_s", "bonds_intact", "kinetic_energy_J"):
            continue
        ts[dst] = raw[src].astype(float)
    fx, fy, fz = ts["force_x_N"], ts["force_y_N"], ts["force_z_N"]
    ts["force_magnitude_N"] = np.sqrt(fx**2 + fy**2 + fz**2)
    # disc frame (seed 002's r, s, n): rolling = -F along the path tangent (cos phi, sin phi, 0), side = F
    # along the disc axis (-sin phi, cos phi, 0) (toward the rotary axis), normal = F_z; phi = 0 unless rotary
    phi = raw["path_angle_rad"].astype(float) if "path_angle_rad" in raw else pd.Series(0.0, index=raw.index)
    c, s_ = np.cos(phi), np.sin(phi)
    ts["path_angle_rad"] = phi.to_numpy()
    ts["force_normal_N"] = fz
    ts["force_rolling_N"] = -(fx * c + fy * s_)
    ts["force_side_N"] = -fx * s_ + fy * c
    ts["torque_axis_Nm"] = -ts["torque_x_Nm"] * s_ + ts["torque_y_Nm"] * c
    cut = spec["derived"].get("cutter", {})
    alpha = float(cut.get("axis_tilt", 0.0) or 0.0)
    if alpha:  # a tilted disc spins about its own axis (0, cos a, sin a) (deckgen.deck.cutter_path; never rotary)
        ts["torque_axis_Nm"] = ts["torque_y_Nm"] * math.cos(alpha) + ts["torque_z_Nm"] * math.sin(alpha)
    if float(cut.get("rotary_radius", 0.0) or 0.0) > 0:
        ts["cutter_advance_m"] = float(cut["rotary_radius"]) * phi  # arc length along the path
    else:
        ts["cutter_advance_m"] = ts["cutter_x_m"] - float(cut.get("xc0", ts["cutter_x_m"].iloc[0] if len(ts) else 0.0))
    if spec["derived"].get("kinematics_mode") == "indentation":
        clear = float(spec["case"]["kinematics"]["start_clearance_mm"]) * 1e-3
        zc0 = float(cut.get("zc0", ts["cutter_z_m"].iloc[0] if len(ts) else 0.0))
        ts["penetration_m"] = (zc0 - ts["cutter_z_m"]) - clear
    else:
        ts["penetration_m"] = _nan()
    ts["bonds_intact"] = np.rint(raw["bonds"].astype(float)).astype(np.int64)
    ts["bonds_broken"] = n0 - ts["bonds_intact"]
    ts["broken_fraction_1"] = ts["bonds_broken"] / n0 if n0 else _nan()
    ts["kinetic_energy_J"] = raw["ke_J"].astype(float)
    return ts[CUTTING_TIMESERIES_COLUMNS]


# ----------------------------------------------------------------------------- broken bonds
def _pair_keys(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    a = np.asarray(a).astype(np.int64)
    b = np.asarray(b).astype(np.int64)
    return np.minimum(a, b), np.maximum(a, b)


def _read_broken(path: Path, state: _RunState) -> pd.DataFrame:
    parts = []
    for fr in _frames(path, state, ["id1", "id2", "step", "x", "y", "z"]):
        if fr.natoms == 0:
            continue
        d = fr.data
        lo, hi = _pair_keys(d["id1"].to_numpy(), d["id2"].to_numpy())
        parts.append(pd.DataFrame({
            "id1": lo, "id2": hi, "step": np.rint(d["step"].to_numpy(dtype=float)).astype(np.int64),
            "x_m": d["x"].to_numpy(dtype=float), "y_m": d["y"].to_numpy(dtype=float),
            "z_m": d["z"].to_numpy(dtype=float),
        }))
    if not parts:
        return pd.DataFrame({"id1": pd.Series(dtype="int64"), "id2": pd.Series(dtype="int64"),
                             "step": pd.Series(dtype="int64"), "x_m": pd.Series(dtype="float64"),
                             "y_m": pd.Series(dtype="float64"), "z_m": pd.Series(dtype="float64")})
    df = pd.concat(parts, ignore_index=True)
    return df.sort_values(["step", "id1", "id2"], kind="stable").reset_index(drop=True)


FLAT_JOINT_MODES = {1: "tension", 2: "shear"}


def _read_broken_joints(path: Path) -> pd.DataFrame:
    """The flat-joint plugin's broken-bond file (``step id1 id2 mode x y z``; mode 1 tension, 2 shear),
    read line by line; a bad line fails with the file and line. The failure mode is the bond's own."""
    cols: dict[str, list] = {k: [] for k in ("id1", "id2", "step", "x_m", "y_m", "z_m", "mode")}
    with open_text(path) as fh:
        for lineno, line in enumerate(fh, 1):
            t = line.split()
            if not t or t[0].startswith("#"):
                continue
            if len(t) != 7:
                raise ParseError(path, lineno, f"expected 7 fields (step id1 id2 mode x y z), got {len(t)}")
            try:
                step, i1, i2, mode = int(t[0]), int(t[1]), int(t[2]), int(t[3])
                xyz = [float(v) for v in t[4:]]
            except ValueError:
                raise ParseError(path, lineno, f"not numbers: {line.strip()[:80]!r}") from None
            if mode not in FLAT_JOINT_MODES or not all(math.isfinite(v) for v in xyz):
                raise ParseError(path, lineno, f"mode must be 1 or 2 and coordinates finite: {line.strip()[:80]!r}")
            lo, hi = min(i1, i2), max(i1, i2)
            for k, v in zip(cols, (lo, hi, step, *xyz, FLAT_JOINT_MODES[mode])):
                cols[k].append(v)
    out = pd.DataFrame({k: pd.Series(v, dtype="int64" if k in ("id1", "id2", "step") else
                                     (object if k == "mode" else "float64")) for k, v in cols.items()})
    return out.sort_values("step", kind="stable").reset_index(drop=True)


def _classify(broken: pd.DataFrame, bonds_path: Path, coeffs: dict[str, list[float]],
              state: _RunState) -> pd.DataFrame:
    """Streaming join of the broken bonds (sorted by step) with the bond-state samples."""
    n = len(broken)
    mode = np.full(n, "unknown", dtype=object)
    btype = np.full(n, -1, dtype=np.int64)
    sample_step = np.full(n, -1, dtype=np.int64)
    f_n = np.full(n, np.nan)
    f_s = np.full(n, np.nan)
    k_r = np.asarray(coeffs["k_r"], dtype=float)
    F_rc = np.asarray(coeffs["F_rc"], dtype=float)
    F_sc = np.asarray(coeffs["F_sc"], dtype=float)
    steps = broken["step"].to_numpy()
    keys = list(zip(broken["id1"].tolist(), broken["id2"].tolist()))
    last: dict[tuple[int, int], tuple[int, int, float, float]] = {}
    pos = 0

    def resolve(upto_step: int | None) -> None:
        """Resolve broken rows with step <= upto_step (all if None) from the current state."""
        nonlocal pos
        while pos < n and (upto_step is None or steps[pos] <= upto_step):
            st = last.get(keys[pos])
            if st is not None:
                s, t, fn, fs = st
                sample_step[pos], btype[pos], f_n[pos], f_s[pos] = s, t, fn, fs
                rt, rs = max(fn, 0.0) / F_rc[t - 1], fs / F_sc[t - 1]
                if rt > 0.0 or rs > 0.0:  # a sample without load (step 0) says nothing
                    mode[pos] = "tension" if rt >= rs else "shear"
            pos += 1

    cols = ["id1", "id2", "btype", "dist", "r0", "fx", "fy", "fz"]
    frames = _frames(bonds_path, state, cols)
    for fr in frames:
        # rows broken at or before this sample's step were last seen in an earlier sample
        resolve(fr.timestep)
        if pos >= n:
            break
        if fr.natoms == 0:
            continue
        d = fr.data
        t = np.rint(d["btype"].to_numpy(dtype=float)).astype(np.int64)
        if t.min() < 1 or t.max() > len(k_r):
            raise ParseError(bonds_path, fr.lineno, f"bond type {t.min()}..{t.max()} outside "
                             f"1..{len(k_r)} of spec.json derived.bond_coefficients")
        fn = k_r[t - 1] * (d["dist"].to_numpy(dtype=float) - d["r0"].to_numpy(dtype=float))
        F2 = d["fx"].to_numpy(dtype=float) ** 2 + d["fy"].to_numpy(dtype=float) ** 2 + d["fz"].to_numpy(dtype=float) ** 2
        fs = np.sqrt(np.maximum(F2 - fn * fn, 0.0))
        lo, hi = _pair_keys(d["id1"].to_numpy(), d["id2"].to_numpy())
        ts = fr.timestep
        last.update(zip(zip(lo.tolist(), hi.tolist()),
                        zip([ts] * len(t), t.tolist(), fn.tolist(), fs.tolist())))
    frames.close()  # all resolved: the rest of the samples is not read
    resolve(None)
    out = broken.copy()
    out["mode"] = mode
    out["btype"] = _nullable_int(btype)
    out["sample_step"] = _nullable_int(sample_step)
    out["bond_force_normal_N"] = f_n
    out["bond_force_shear_N"] = f_s
    return out


def _nullable_int(a: np.ndarray) -> pd.arrays.IntegerArray:
    """Int64 array with <NA> where ``a < 0`` (no sample)."""
    return pd.arrays.IntegerArray(np.where(a >= 0, a, 0).astype(np.int64), a < 0)


def _unclassified(broken: pd.DataFrame) -> pd.DataFrame:
    out = broken.copy()
    out["mode"] = np.full(len(out), "unknown", dtype=object)
    out["btype"] = _nullable_int(np.full(len(out), -1, dtype=np.int64))
    out["sample_step"] = _nullable_int(np.full(len(out), -1, dtype=np.int64))
    out["bond_force_normal_N"] = np.full(len(out), np.nan)
    out["bond_force_shear_N"] = np.full(len(out), np.nan)
    return out


def _broken_timeseries(broken: pd.DataFrame, ts: pd.DataFrame) -> pd.DataFrame:
    steps = ts["step"].to_numpy()
    out = pd.DataFrame({"time_s": ts["time_s"].to_numpy(), "step": steps})
    ev = broken["step"].to_numpy()
    out["bonds_broken"] = np.searchsorted(np.sort(ev), steps, side="right").astype(np.int64)
    for m in ("tension", "shear", "unknown"):
        sel = np.sort(ev[broken["mode"].to_numpy() == m])
        out[f"bonds_broken_{m}"] = np.searchsorted(sel, steps, side="right").astype(np.int64)
    return out[BROKEN_TS_COLUMNS]


# ----------------------------------------------------------------------------- damage
def _damage(run_dir: Path, state: _RunState, debris_deleted: bool = False) -> tuple[pd.DataFrame, dict[str, Any]]:
    """Per-grain damage from the first and the last frame. ``debris_deleted``: the deck deleted grains that had lost
    all their bonds (``run.debris_removal_every``), so a grain missing from the last frame has 0 bonds there."""
    cols = ["id", "type", "radius", "x", "y", "z", "c_nb"]
    atoms = run_dir / "atoms.dump.gz"
    final = run_dir / "final.dump.gz"
    info: dict[str, Any] = {"damage_source": "none", "damage_step": _nan(), "bonds_broken_dumps": _nan(),
                            "n_grains_missing_final": _nan(), "n_grains_deleted_debris": 0}
    empty = pd.DataFrame({c: pd.Series(dtype="float64") for c in DAMAGE_COLUMNS})
    if not atoms.is_file():
        state.notes.append("no atoms.dump.gz: no damage table")
        return empty, info
    first = None
    last = None
    for fr in _frames(atoms, state, cols):
        if first is None:
            first = fr
        last = fr  # only the newest frame is kept
    if first is None:
        state.notes.append("atoms.dump.gz has no complete frame: no damage table")
        return empty, info
    source = "atoms.dump.gz"
    if final.is_file():
        for fr in _frames(final, state, cols):
            last = fr
        source = "final.dump.gz"
    elif last is first:
        state.notes.append("atoms.dump.gz holds only the initial frame and there is no final.dump.gz: "
                           "bonds_final is the initial state")
    assert last is not None
    d0 = first.data[first.data["type"] == 1]
    d1 = last.data[last.data["type"] == 1]
    nb0 = np.rint(d0["c_nb"].to_numpy(dtype=float)).astype(np.int64)
    fin = pd.Series(np.rint(d1["c_nb"].to_numpy(dtype=float)).astype(np.int64),
                    index=d1["id"].to_numpy().astype(np.int64))
    ids = d0["id"].to_numpy().astype(np.int64)
    nb1 = fin.reindex(ids)
    missing = int(nb1.isna().sum())
    deleted = 0
    if debris_deleted and missing:
        deleted, missing = missing, 0
        nb1 = nb1.fillna(0)
    dmg = pd.DataFrame({
        "id": ids, "radius_m": d0["radius"].to_numpy(dtype=float), "x_m": d0["x"].to_numpy(dtype=float),
        "y_m": d0["y"].to_numpy(dtype=float), "z_m": d0["z"].to_numpy(dtype=float),
        "bonds_initial": nb0,
        "bonds_final": pd.arrays.IntegerArray(np.nan_to_num(nb1.to_numpy(dtype=float)).astype(np.int64),
                                              nb1.isna().to_numpy()),
    })
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = 1.0 - nb1.to_numpy(dtype=float) / nb0.astype(float)
    ratio[nb0 == 0] = np.nan
    dmg["damage_ratio_1"] = ratio
    dmg = dmg.sort_values("id", kind="stable").reset_index(drop=True)
    if missing:
        state.notes.append(f"{missing} grain(s) missing from the final frame (lost atoms): damage NaN")
    if deleted:
        state.notes.append(f"{deleted} grain(s) deleted as loose debris (run.debris_removal_every): damage 1, not in "
                           "the chips' removed volume")
    info["final_xyz_m"] = d1[["x", "y", "z"]].to_numpy(dtype=float)
    info.update({
        "damage_source": source, "damage_step": int(last.timestep), "n_grains_missing_final": missing,
        "n_grains_deleted_debris": deleted,
        # (sum c_nb initial - sum c_nb final) / 2 over rock grains present in both frames
        "bonds_broken_dumps": (int(nb0.sum()) - int(np.nansum(nb1.to_numpy(dtype=float)))) / 2.0
        if not missing else _nan(),
    })
    return dmg, info


# ----------------------------------------------------------------------------- summaries
def _platen_summary(ts: pd.DataFrame, spec: dict[str, Any], test: str) -> dict[str, Any]:
    d = spec["derived"]
    out: dict[str, Any] = {"area_m2": float(d.get("area_m2", _nan())), "height_m": float(d.get("height_m", _nan())),
                           "platen_speed_m_s": float(d.get("platen_speed_m_s", _nan()))}
    modulus_key = "youngs_modulus_Pa" if test == "ucs" else "secant_modulus_Pa"
    if ts.empty:
        out.update({k: _nan() for k in ("peak_stress_Pa", "strain_at_peak_1", "time_at_peak_s", "peak_force_N",
                                         "bonds_broken_at_peak", modulus_key, "modulus_fit_points",
                                         "modulus_fit_intercept_Pa", "modulus_fit_stress_lo_Pa",
                                         "modulus_fit_stress_hi_Pa", "final_strain_1", "poisson_ratio_1",
                                         "post_peak_drop_1", "max_strain_1")})
        out["peak_reached"] = False
        return out
    stress = ts["stress_Pa"].to_numpy()
    strain = ts["strain_1"].to_numpy()
    ip = int(np.argmax(stress))
    peak = float(stress[ip])
    lo, hi = MODULUS_WINDOW[0] * peak, MODULUS_WINDOW[1] * peak
    pre = np.arange(len(stress)) <= ip
    sel = pre & (stress >= lo) & (stress <= hi)
    slope = intercept = _nan()
    if sel.sum() >= 2 and np.ptp(strain[sel]) > 0:
        x, y = strain[sel], stress[sel]
        xm, ym = x.mean(), y.mean()
        slope = float(((x - xm) * (y - ym)).sum() / ((x - xm) ** 2).sum())
        intercept = float(ym - slope * xm)
    # Poisson's ratio: -d(lateral strain)/d(axial strain) over the same pre-peak window (UCS only)
    nu = _nan()
    lat = ts["lateral_strain_1"].to_numpy(dtype=float)  # NaN for decks without it (BTS, older UCS decks)
    if test == "ucs" and sel.sum() >= 2 and np.ptp(strain[sel]) > 0 and np.isfinite(lat[sel]).all():
        nu = float(np.polyfit(strain[sel], lat[sel], 1)[0])  # compression-positive axial, expansion-positive lateral
    out["poisson_ratio_1"] = nu
    out.update({
        "peak_stress_Pa": peak, "strain_at_peak_1": float(strain[ip]),
        "time_at_peak_s": float(ts["time_s"].iloc[ip]), "peak_force_N": float(-ts["force_top_N"].iloc[ip]),
        "bonds_broken_at_peak": int(ts["bonds_broken"].iloc[ip]),
        modulus_key: slope, "modulus_fit_points": int(sel.sum()), "modulus_fit_intercept_Pa": intercept,
        "modulus_fit_stress_lo_Pa": lo, "modulus_fit_stress_hi_Pa": hi,
        "final_strain_1": float(strain[-1]),
    })
    out["post_peak_drop_1"] = float(1.0 - stress[-1] / peak) if peak > 0 else _nan()
    out["max_strain_1"] = float(spec.get("case", {}).get("specimen", {}).get("max_strain") or _nan())
    out["peak_reached"] = peak_reached(out)
    return out


def split_onset(ts: pd.DataFrame, broken: pd.DataFrame, spec: dict[str, Any]) -> dict[str, Any]:
    """Where a Brazilian disc splits: the stress when a diametral crack's worth of bonds along its loaded diameter
    has broken.

    A disc whose bonds open in tension long before its peak (a flat joint with a low sigma_c/E_b and a high
    cohesion) cracks along the loaded diameter and is then crushed between the jaws: its load rises again, carried
    by the broken faces' compression and friction, to a peak 1.2-4x the load at which it split. The split, not that
    peak, is the disc's tensile failure; a laboratory disc splits at its peak and the test ends there.

    Crack count: the broken bonds within SPLIT_BAND R of the loading line (x of the jaws) and SPLIT_CORE R of the
    disc centre, in the order they broke; the split is the sample where their number first reaches
    ``SPLIT_CRACK_SHARE n_bonds l / (pi R)`` (the bonds a diametral plane cuts, l = r_min + r_max).
    ``split_stress_Pa`` is the largest stress up to that sample, or the peak when the count is reached after the
    peak or never (a brittle disc splits at its peak and cracks through after it: ``split_source`` "peak";
    otherwise "crack"). Always ``split_stress_Pa <= peak_stress_Pa``. Also ``split_crack_bonds`` (the count
    needed), ``split_localisation_1`` (that count over all bonds broken by then: ~0.85 for a diametral crack),
    ``bonds_broken_at_split``, ``split_step`` (the step of the reading's sample) and the counted band's centre
    ``split_band_x_m``, ``split_band_z_m``.
    """
    nan = _nan()
    out: dict[str, Any] = {"split_stress_Pa": nan, "split_strain_1": nan, "bonds_broken_at_split": nan,
                           "split_crack_bonds": nan, "split_localisation_1": nan, "split_source": "none",
                           "split_step": None, "split_band_x_m": nan, "split_band_z_m": nan}
    if ts.empty:
        return out
    stress = ts["stress_Pa"].to_numpy(dtype=float)
    bb = ts["bonds_broken"].to_numpy(dtype=float)
    steps = ts["step"].to_numpy(dtype=np.int64)
    ip = int(np.argmax(stress))
    stop = ip  # default: the peak
    case, derived = spec.get("case", {}), spec.get("derived", {})
    sp, pk = case.get("specimen", {}), case.get("packing", {})
    try:
        R = 0.5e-3 * float(sp["diameter_mm"])
        bond_len = 1e-3 * (float(pk["radius_min_mm"]) + float(pk["radius_max_mm"]))
        n0 = float(derived["n_bonds"])
    except (KeyError, TypeError, ValueError):
        R = bond_len = n0 = nan
    jaws = derived.get("jaws") or {}
    x_load = float(jaws.get("x", 0.0))
    z_c = (0.5 * (float(jaws["zc_bot"]) + float(jaws["zc_top"])) if {"zc_bot", "zc_top"} <= set(jaws)
           else 0.5 * float(derived.get("height_m", 2.0 * R)))
    need = SPLIT_CRACK_SHARE * n0 * bond_len / (math.pi * R) if R > 0 else nan
    out.update(split_crack_bonds=need, split_band_x_m=x_load, split_band_z_m=z_c)  # the counted band's centre
    if len(broken) and math.isfinite(need) and need > 0:
        on_diameter = ((np.abs(broken["x_m"].to_numpy(dtype=float) - x_load) < SPLIT_BAND * R)
                       & (np.abs(broken["z_m"].to_numpy(dtype=float) - z_c) < SPLIT_CORE * R))
        crack_steps = np.sort(broken["step"].to_numpy(dtype=np.int64)[on_diameter])
        k = int(math.ceil(need)) - 1
        if k < len(crack_steps):
            at = int(crack_steps[k])
            j = min(int(np.searchsorted(steps, at, side="left")), len(stress) - 1)  # first sample that holds it
            if j <= ip:
                stop = int(np.argmax(stress[: j + 1]))
                out["split_source"] = "crack"
            out["split_localisation_1"] = (k + 1) / max(1, int((broken["step"].to_numpy() <= at).sum()))
    if out["split_source"] == "none":
        out["split_source"] = "peak"
    out.update(split_stress_Pa=float(stress[stop]), split_strain_1=float(ts["strain_1"].iloc[stop]),
               bonds_broken_at_split=int(bb[stop]), split_step=int(steps[stop]))
    return out


def split_onset_on_disk(test_dir: str | Path) -> dict[str, Any]:
    """:func:`split_onset` of a parsed Brazilian test folder (``<test_dir>/run/spec.json``, ``<test_dir>/parsed/``
    timeseries and broken tables): for summaries written before the split onset existed."""
    d = Path(test_dir)
    spec = json.loads((d / "run" / "spec.json").read_text())
    return split_onset(pd.read_parquet(d / "parsed" / "timeseries.parquet"),
                       pd.read_parquet(d / "parsed" / "broken.parquet"), spec)


def peak_reached(summary: dict[str, Any]) -> bool:
    """Did the platen test fail, i.e. is ``peak_stress_Pa`` a strength?

    Yes when the peak lies before 90 % of the final strain, or when the stress at the last sample is
    :data:`PEAK_DROP_MIN` or more below the peak and either
    the run stopped before its ``max_strain`` (the stop rule fired: a brittle specimen may lose its
    load within a few samples of the peak) or the peak lies before 97 % of the final strain. A run
    cut by ``max_strain`` whose last sample happens to sit on a dip just after the maximum is not a
    failure. Summaries written before ``post_peak_drop_1`` existed get the strain criterion only."""
    def num(k: str) -> float:
        try:
            return float(summary.get(k))  # type: ignore[arg-type]
        except (TypeError, ValueError):
            return _nan()
    peak_eps, final_eps, drop = num("strain_at_peak_1"), num("final_strain_1"), num("post_peak_drop_1")
    max_eps = num("max_strain_1")
    if not (math.isfinite(peak_eps) and math.isfinite(final_eps)) or final_eps <= 0:
        return False
    peak_early = peak_eps < PEAK_STRAIN_MAX_FRACTION * final_eps
    if peak_eps < PEAK_CLEARLY_EARLY_FRACTION * final_eps:
        return True
    if not math.isfinite(drop):
        return bool(peak_early)
    stopped_early = math.isfinite(max_eps) and final_eps < STOPPED_EARLY_FRACTION * max_eps
    return bool(drop >= PEAK_DROP_MIN and (stopped_early or peak_early))


def grains_inside_cutter(xyz: np.ndarray, spec: dict[str, Any], t: float) -> int | None:
    """Rock grains whose centres lie inside the true cutter body at time ``t`` (a leak through the shell).

    A grain touching the shell from outside keeps its centre at least its radius outside the true
    surface (the shell spheres sit their own radius inside it), so a centre inside the body means the
    grain got through a gap of the shell or through a part ``shell_coverage: near_rock`` left out.
    The body is the revolved profile about the disc axis, moved as the deck moves it
    (:func:`deckgen.deck.cutter_world_points`): a tilted axis (clearance angle or ``tilt_deg``) stays fixed
    while the disc spins about it (spec.json files from before ``axis_tilt``: spun about y), and the axis
    yaws on a rotary path. None when the geometry cannot be rebuilt from the spec.
    """
    from types import SimpleNamespace

    from matplotlib.path import Path as MplPath

    from deckgen.deck import cutter_modifications, cutter_params, cutter_profile, cutter_world_points
    from deckgen.geometry import build_cutter
    from deckgen.spec import Cutter

    case, cut = spec["case"], spec["derived"].get("cutter") or {}
    try:
        cutter = Cutter.model_validate(case["cutter"])
    except Exception:  # a spec.json of another version: no check rather than a wrong one
        return None
    if not cut:
        return None
    holder = SimpleNamespace(cutter=cutter)
    prof = cutter_profile(holder)
    axis0 = np.array([0.0, 1.0, 0.0])
    if cutter.tilt_deg or (cutter.kind == "cone_disc" and cutter.clearance_angle_deg):
        axis0 = np.asarray(build_cutter(*cutter_params(holder), **cutter_modifications(holder)).metadata["deckgen_axis"],
                           float)
    # the deck's rigid motion (deckgen.deck.cutter_world_points) carries the centre and the axis tip;
    # spec.json files from before the rotary path lack its keys (no spin, no yaw)
    path = {"spin_rate": 0.0, "rotary_radius": 0.0, "yaw_rate": 0.0, "axis_x": 0.0, "axis_y": 0.0, **cut}
    centre, tip = cutter_world_points(np.array([[0.0, 0.0, 0.0], axis0]), path, t)
    axis = tip - centre
    d = np.asarray(xyz, float) - centre
    a = d @ axis
    rho = np.linalg.norm(d - np.outer(a, axis), axis=1)
    return int(MplPath(prof).contains_points(np.column_stack([rho, a])).sum())


def _cutting_summary(ts: pd.DataFrame, spec: dict[str, Any]) -> dict[str, Any]:
    d = spec["derived"]
    cut = d.get("cutter", {})
    duration = float(cut.get("duration", _nan()))
    window = d.get("steady_window") or spec["case"]["outputs"]["steady_window"]
    V, ecc, omega = float(cut.get("V", _nan())), float(cut.get("ecc", 0.0)), float(cut.get("omega", 0.0))
    out: dict[str, Any] = {
        "kinematics_mode": d.get("kinematics_mode", spec["case"]["kinematics"]["mode"]),
        "cut_duration_s": duration, "steady_start_s": float(window[0]) * duration,
        "steady_end_s": float(window[1]) * duration, "cutter_radius_m": float(cut.get("radius", _nan())),
        "steady_window_start_1": float(window[0]), "steady_window_end_1": float(window[1]),
        "cutter_speed_m_s": V, "eccentricity_m": ecc, "omega_rad_s": omega,
        "travel_m": float(cut.get("travel", _nan())), "penetration_m": float(cut.get("penetration", _nan())),
        "velocity_ratio_nu_1": V / (ecc * omega) if ecc > 0 and omega > 0 else _nan(),
    }
    mask = steady_mask(ts["time_s"], duration, window)
    out["steady_rows"] = int(mask.sum())
    for q in CUTTING_QUANTITIES:
        v = ts[q].to_numpy()
        out[f"{q}_mean_steady"] = float(v[mask].mean()) if mask.any() else _nan()
        # its standard error: the chips correlate the rows, so from the integrated autocorrelation time
        out[f"{q}_sem_steady"] = mean_standard_error(v[mask])["sem"]
        out[f"{q}_peak"] = float(v[int(np.argmax(np.abs(v)))]) if len(v) else _nan()
    # oscillating cuts: means over the whole cycles that fit in the steady window from its start (a mean over
    # 1.4 cycles weights the phase that is in the window twice); no whole cycle: NaN; no oscillation: the
    # steady mean
    n_cycles, cyc = 0, mask
    if ecc > 0 and omega > 0:
        period = 2 * math.pi / omega
        n_cycles = int(math.floor((out["steady_end_s"] - out["steady_start_s"]) / period + 1e-9))
        t = ts["time_s"].to_numpy()
        cyc = (t >= out["steady_start_s"]) & (t < out["steady_start_s"] + n_cycles * period)  # empty at 0 cycles
    out["cycles_averaged_1"] = n_cycles
    for q in CUTTING_QUANTITIES:
        out[f"{q}_mean_cycles"] = float(ts[q].to_numpy()[cyc].mean()) if cyc.any() else _nan()
    # the same span of whole cycles slid over the steady window: the mean of the means of every window of
    # cycles_averaged_1 whole cycles that starts at a steady row and ends inside the window. Each window weighs
    # every phase alike, and together they use all of the steady window, where the mean from its start drops the
    # rest: a long cut at 90 Hz holds 1.39 cycles, and the chipping moves a one-cycle mean by +-20 % with its start.
    # Cumulative sums (numpy) make it O(rows); no oscillation: the steady mean.
    sliding: dict[str, float] = {}
    if n_cycles >= 1 and mask.any():
        t = ts["time_s"].to_numpy()
        rows = np.flatnonzero(mask)
        t_s = t[rows]
        span = n_cycles * 2 * math.pi / omega
        ends = np.searchsorted(t_s, t_s + span * (1 - 1e-9), side="left")  # first row at or after start + span
        starts = np.flatnonzero(ends < len(rows))  # windows that close inside the steady rows
        ends = ends[starts]
        for q in CUTTING_QUANTITIES:
            c = np.concatenate([[0.0], np.cumsum(ts[q].to_numpy()[rows])])
            sliding[q] = float(np.mean((c[ends] - c[starts]) / (ends - starts))) if len(starts) else _nan()
    for q in CUTTING_QUANTITIES:
        out[f"{q}_mean_cycles_sliding"] = (sliding.get(q, _nan()) if ecc > 0 and omega > 0
                                           else out[f"{q}_mean_steady"])
    # indentation (seed 000 sec. 3.3): the indentation depth at the maximum (destructive) normal force, the seed's
    # "penetration at failure"; the same row as force_normal_N_peak
    fz = ts["force_normal_N"].to_numpy()
    out["penetration_at_peak_normal_m"] = (float(ts["penetration_m"].iloc[int(np.argmax(np.abs(fz)))])
                                           if out["kinematics_mode"] == "indentation" and len(fz) else _nan())
    out["contact_fraction_steady_1"] = (float((ts["force_magnitude_N"].to_numpy()[mask] > CONTACT_THRESHOLD_N).mean())
                                        if mask.any() else _nan())
    fn = out["force_normal_N_mean_steady"]
    out["rolling_to_normal_ratio_1"] = out["force_rolling_N_mean_steady"] / fn if fn and math.isfinite(fn) else _nan()
    if not mask.any():
        out_note = "steady window holds no series row"
        out["notes_extra"] = out_note
    return out


# ----------------------------------------------------------------------------- parse_run
def _steady_window(run_dir: Path, window: Any, test: str) -> tuple[float, float]:
    """``window`` as two floats, checked by the case schema's rule (:class:`deckgen.spec.Outputs`), for a cutting run;
    else SpecError naming the run folder and the fix."""
    from pydantic import ValidationError

    from deckgen.spec import Outputs, SpecError

    if test != "cutting":
        raise SpecError(f"{run_dir}: a steady window is for cutting runs; this run is a {test} test (fix: drop it)")
    try:
        a, b = (float(x) for x in window)
        Outputs(steady_window=(a, b))
    except (TypeError, ValueError) as exc:  # pydantic's ValidationError is a ValueError
        why = exc.errors()[0]["msg"] if isinstance(exc, ValidationError) else "not two numbers"
        raise SpecError(f"{run_dir}: steady window {' '.join(map(str, window))}: {why} (fix: START END fractions of "
                        "the travel, e.g. 0.3 1.0)") from None
    return a, b


def _whole_size(n: Any) -> int:
    """``n`` as a break-off size by the case schema's rule (:class:`deckgen.spec.Outputs`); ValueError saying why."""
    from pydantic import ValidationError

    from deckgen.spec import Outputs

    try:
        if isinstance(n, bool) or float(n) != int(n):
            raise ValueError("not a whole number")
        Outputs(breakoff_min_grains=int(n))
    except ValidationError as exc:
        raise ValueError(exc.errors()[0]["msg"]) from None
    except (TypeError, ValueError, OverflowError):
        raise ValueError("not a whole number") from None
    return int(n)


def _breakoff_size(run_dir: Path, spec: dict[str, Any], n: Any) -> tuple[int, str]:
    """The break-off size of a run and where it comes from: ``n`` (``deckgen parse --breakoff-min-grains``, ``parse``),
    else the case's ``outputs.breakoff_min_grains`` in spec.json (``case``), else, for a spec.json written before the
    field existed, :data:`deckgen.spec.DETACH_MIN_GRAINS` (``default``, the only size then). SpecError naming the run
    folder or spec.json and the fix: a size given for a run that is not an indentation run, or one that is not a whole
    number >= 2."""
    from deckgen.spec import DETACH_MIN_GRAINS, SpecError

    mode = spec["derived"].get("kinematics_mode")
    test = spec["case"].get("test")
    if n is not None:
        if test != "cutting" or mode != "indentation":
            what = f"a {mode} cut" if test == "cutting" else f"a {test} test"
            raise SpecError(f"{run_dir}: a break-off size is for indentation runs; this run is {what} (fix: drop it)")
        try:
            return _whole_size(n), "parse"
        except ValueError as exc:
            raise SpecError(f"{run_dir}: break-off size {n}: {exc} (fix: a whole number of grains >= 2, e.g. 25)") from None
    outputs = spec["case"].get("outputs", {})
    if "breakoff_min_grains" not in outputs:
        return DETACH_MIN_GRAINS, "default"
    try:
        return _whole_size(outputs["breakoff_min_grains"]), "case"
    except ValueError as exc:
        raise SpecError(f"{run_dir / 'spec.json'}: case.outputs.breakoff_min_grains {outputs['breakoff_min_grains']!r}: "
                        f"{exc} (fix: parse with --breakoff-min-grains N, or a whole number >= 2 in the case file and "
                        "render again)") from None


def parse_run(run_dir: str | Path, out_dir: str | Path,
              steady_window: tuple[float, float] | None = None,
              breakoff_min_grains: int | None = None) -> dict[str, Any]:
    """Parse one run folder into tables in ``out_dir``; return the flat summary dict.

    ``steady_window`` (cutting runs): fractions [a, b] of the travel that replace the case's
    ``outputs.steady_window`` for the means, so a finished run can be read again over another window without
    running it again; the summary keeps the window used (``steady_window_start_1``, ``steady_window_end_1``)
    and where it came from (``steady_window_source``: ``case`` or ``parse``).

    ``breakoff_min_grains`` (indentation runs): the smallest piece whose break-off counts as the chip's detachment,
    in place of the case's ``outputs.breakoff_min_grains``; the summary keeps the size used
    (``detachment_min_grains``) and where it came from (``detachment_min_grains_source``: ``case``, ``parse``, or
    ``default`` for a spec.json written before the field existed, read at 25 grains as every run then was).

    Writes ``timeseries``, ``broken``, ``broken_timeseries`` and ``damage`` (``.parquet`` and
    ``.csv``) and ``summary.json``. Summary keys (all scalars; NaN in the dict, ``null`` in the
    JSON): ``case, test, engine, n_grains, n_bonds_initial`` (spec.json), ``bonds_broken``
    (rows of ``broken``; from the series when broken.dump.gz is missing), ``broken_fraction_1``,
    ``bonds_broken_tension|shear|unknown``, ``mode_source``, the cross-checks
    ``bonds_broken_series`` (n_bonds_initial - last series ``bonds``) and ``bonds_broken_dumps``
    ((sum c_nb initial - final) / 2, rock grains), ``damage_ratio_mean_1`` (mean over grains with
    an initial bond), ``damaged_grain_fraction_1`` (share of those grains with damage > 0),
    ``damage_source, damage_step``, ``run_completed, steps, wall_s, loop_s,
    particle_steps_per_s, final_step, final_time_s, log_failure, notes``.

    Platen tests add ``peak_stress_Pa, strain_at_peak_1, time_at_peak_s, peak_force_N,
    bonds_broken_at_peak`` and the modulus: slope of the least-squares line of stress_Pa on
    strain_1 over the pre-peak rows (up to and including the peak) with
    0.2 peak <= stress <= 0.5 peak, named ``youngs_modulus_Pa`` for UCS and ``secant_modulus_Pa``
    for BTS (there it is the slope of the Brazilian stress over diametral strain, not a Young's
    modulus); NaN with fewer than 2 rows in the window.

    Cutting adds, for q in force_normal_N, force_rolling_N, force_side_N, torque_axis_Nm,
    force_magnitude_N: ``q_mean_steady`` (mean over rows with a*T <= time_s <= b*T, [a, b] the
    steady window, T = derived.cutter.duration), ``q_sem_steady`` (the standard error of that mean from the series'
    integrated autocorrelation time, :func:`mean_standard_error`) and ``q_peak`` (the value of largest magnitude
    over the whole run, with its sign); ``q_mean_cycles`` (oscillating cuts: mean over the
    ``cycles_averaged_1`` whole cycles 2 pi / omega that fit in the steady window from its start, NaN when
    none fits; other cuts: ``q_mean_steady``); ``q_mean_cycles_sliding`` (the mean of the means of every window of
    ``cycles_averaged_1`` whole cycles inside the steady window: all of the window, every phase alike; NaN when no
    whole cycle fits; other cuts: ``q_mean_steady``); ``contact_fraction_steady_1`` (steady rows with
    |F| > 1e-9 N), ``rolling_to_normal_ratio_1``, ``velocity_ratio_nu_1 = V / (e omega)``
    (NaN when e = 0) and the kinematics.
    """
    run_dir = Path(run_dir)
    out_dir = Path(out_dir)
    spec_path = run_dir / "spec.json"
    if not spec_path.is_file():
        raise FileNotFoundError(f"{spec_path}: no spec.json (not a rendered run folder?)")
    spec = json.loads(spec_path.read_text())
    case = spec["case"]
    test = case.get("test")
    if test not in ("ucs", "bts", "cutting"):
        raise ValueError(f"{spec_path}: case.test is {test!r}, expected ucs, bts or cutting")
    if steady_window is not None:
        a, b = _steady_window(run_dir, steady_window, test)
        spec = {**spec, "derived": {**spec["derived"], "steady_window": [a, b]}}
    if breakoff_min_grains is not None or spec["derived"].get("kinematics_mode") == "indentation":
        n, source = _breakoff_size(run_dir, spec, breakoff_min_grains)
        spec = {**spec, "derived": {**spec["derived"], "breakoff_min_grains": n, "breakoff_min_grains_source": source}}
    derived = spec["derived"]
    engine = spec.get("engine") or case.get("engine", "lammps")
    state = _RunState(run_dir)
    n0 = int(derived["n_bonds"])
    dt = float(derived["dt_s"])

    series_path = run_dir / "series.txt"
    if not series_path.is_file():
        raise FileNotFoundError(f"{series_path}: no series.txt")
    raw = _series(series_path, state)
    if test in _PLATEN_TESTS:
        ts = _platen_timeseries(raw, series_path, n0)
    else:
        ts = _cutting_timeseries(raw, series_path, n0, spec)

    broken_path = run_dir / "broken.dump.gz"
    joints_path = run_dir / FLAT_JOINT_BROKEN
    have_broken = broken_path.is_file() or joints_path.is_file()
    joint_modes = None
    if broken_path.is_file():
        broken = _read_broken(broken_path, state)
    elif joints_path.is_file():  # deckgen's flat-joint bond writes its own list, with the failure mode
        broken = _read_broken_joints(joints_path)
        joint_modes = broken.pop("mode").to_numpy(dtype=object)
    else:
        state.notes.append("no broken.dump.gz: no broken-bond list; bonds_broken from the series")
        broken = pd.DataFrame(  # empty, typed
            {"id1": pd.Series(dtype="int64"), "id2": pd.Series(dtype="int64"), "step": pd.Series(dtype="int64"),
             "x_m": pd.Series(dtype="float64"), "y_m": pd.Series(dtype="float64"), "z_m": pd.Series(dtype="float64")})
    broken.insert(3, "time_s", broken["step"].to_numpy(dtype=float) * dt)
    bonds_path = run_dir / "bonds.dump.gz"
    if joint_modes is not None:
        broken = _unclassified(broken)
        broken["mode"] = joint_modes
        mode_source = FLAT_JOINT_BROKEN
    elif bonds_path.is_file():
        broken = _classify(broken, bonds_path, derived["bond_coefficients"], state)
        mode_source = "bonds.dump.gz"
    else:
        broken = _unclassified(broken)
        mode_source = "none"
        state.notes.append("no bonds.dump.gz: failure modes unknown (set outputs.bond_state_every)")
    broken = broken[BROKEN_COLUMNS]
    bts = _broken_timeseries(broken, ts)

    dmg, dinfo = _damage(run_dir, state, debris_deleted=bool(derived.get("debris_removal_every")))

    bonds_broken_series = int(ts["bonds_broken"].iloc[-1]) if len(ts) else _nan()
    bonds_broken = len(broken) if have_broken else bonds_broken_series
    counts = broken["mode"].value_counts()
    bonded = dmg["bonds_initial"].to_numpy() > 0 if len(dmg) else np.zeros(0, bool)
    ratio = dmg["damage_ratio_1"].to_numpy(dtype=float) if len(dmg) else np.zeros(0)
    finite = np.isfinite(ratio)
    summary: dict[str, Any] = {
        "case": case["name"], "test": test, "engine": engine,
        "n_grains": int(derived["n_grains"]), "n_bonds_initial": n0,
        "bonds_broken": bonds_broken, "broken_fraction_1": bonds_broken / n0 if n0 else _nan(),
        "bonds_broken_tension": int(counts.get("tension", 0)),
        "bonds_broken_shear": int(counts.get("shear", 0)),
        "bonds_broken_unknown": int(counts.get("unknown", 0)),
        "mode_source": mode_source,
        "bonds_broken_series": bonds_broken_series,
        "bonds_broken_dumps": dinfo["bonds_broken_dumps"],
        "damage_ratio_mean_1": float(ratio[finite].mean()) if finite.any() else _nan(),
        "damaged_grain_fraction_1": float((ratio[finite] > 0).mean()) if finite.any() else _nan(),
        "n_grains_bonded": int(bonded.sum()),
        "n_grains_missing_final": dinfo["n_grains_missing_final"],
        "n_grains_deleted_debris": dinfo["n_grains_deleted_debris"],
        "damage_source": dinfo["damage_source"], "damage_step": dinfo["damage_step"],
        "dt_s": dt,
        "final_step": int(ts["step"].iloc[-1]) if len(ts) else _nan(),
        "final_time_s": float(ts["time_s"].iloc[-1]) if len(ts) else _nan(),
        "run_completed": bool(state.completed), "steps": state.steps, "wall_s": state.wall_s,
        "loop_s": state.loop_s, "particle_steps_per_s": state.particle_steps_per_s,
        "log_failure": state.log_failure,
    }
    if test in _PLATEN_TESTS:
        summary.update(_platen_summary(ts, spec, test))
        if test == "bts":
            summary.update(split_onset(ts, broken, spec))
        if not ts.empty and not summary["peak_reached"]:
            state.notes.append(f"no failure: the stress at the last sample is {100 * summary['post_peak_drop_1']:.0f} % below "
                               f"the peak (strain at peak {summary['strain_at_peak_1']:.4g} of {summary['final_strain_1']:.4g}); "
                               f"peak_stress_Pa is a lower bound, not a strength (fix: raise specimen.max_strain)")
    else:
        extra = _cutting_summary(ts, spec)
        extra["steady_window_source"] = "parse" if steady_window is not None else "case"
        note = extra.pop("notes_extra", None)
        if note:
            state.notes.append(note)
        summary.update(extra)
        xyz = dinfo.get("final_xyz_m")
        inside = (grains_inside_cutter(xyz, spec, int(dinfo["damage_step"]) * dt)
                  if xyz is not None and dinfo["damage_source"] == "final.dump.gz" else None)
        summary["grains_inside_cutter_final"] = inside if inside is not None else _nan()
        if inside:
            state.notes.append(f"{inside} grain centre(s) inside the cutter body at the end: grains leaked through the "
                               "cutter shell (denser shell_spacing, larger shell margin or weaker forces)")
        from deckgen.chips import analyse, initial_bonds

        if derived.get("n_bonds", 0) and initial_bonds(run_dir) is not None:
            chips, chip_summary = analyse(run_dir, broken, ts, spec)
            summary.update(chip_summary)
        else:
            chips = None
            state.notes.append("initial bonds unknown (no specimen.data, no step-0 bond sample): no chips")
    if have_broken and bonds_broken != bonds_broken_series:
        state.notes.append(f"broken list has {bonds_broken} bonds, the series' last row says {bonds_broken_series}")
    bd = dinfo["bonds_broken_dumps"]
    if have_broken and isinstance(bd, float) and math.isfinite(bd) and bd != bonds_broken:
        state.notes.append(f"broken list has {bonds_broken} bonds, the atom dumps (step "
                           f"{dinfo['damage_step']}) say {bd:g}")
    summary["notes"] = "; ".join(state.notes)
    summary = {k: _scalar(v) for k, v in summary.items()}

    out_dir.mkdir(parents=True, exist_ok=True)
    write_table(ts, out_dir / "timeseries")
    write_table(broken, out_dir / "broken")
    write_table(bts, out_dir / "broken_timeseries")
    write_table(dmg, out_dir / "damage")
    if test not in _PLATEN_TESTS and chips is not None:
        write_table(chips, out_dir / "chips")
    (out_dir / "summary.json").write_text(json.dumps(_json_safe(summary), indent=2) + "\n")
    return summary


# ----------------------------------------------------------------------------- aggregate
def _load_summary(d: Path) -> dict[str, Any]:
    p = d / "summary.json"
    if not p.is_file():
        raise FileNotFoundError(f"{p}: no summary.json (run deckgen parse on the run folder first)")
    s = json.loads(p.read_text())
    return {k: (_nan() if v is None else v) for k, v in s.items()}


def _empty(columns: list[str]) -> pd.DataFrame:
    labels = {"case", "engine", "test", "mode", "mode_source", "damage_source", "kinematics_mode",
              "notes", "log_failure"}
    ints = {"step"}
    return pd.DataFrame({c: pd.Series(dtype="string" if c in labels else "int64" if c in ints else "float64")
                         for c in columns})


def _frame(rows: list[dict[str, Any]] | list[pd.DataFrame], columns: list[str], *, concat: bool) -> pd.DataFrame:
    if not rows:
        return _empty(columns)
    df = pd.concat(rows, ignore_index=True) if concat else pd.DataFrame(rows)  # type: ignore[arg-type]
    extra = [c for c in df.columns if c not in columns]
    return df[[c for c in columns if c in df.columns] + extra].reindex(columns=columns + extra)


def aggregate(parsed_dirs: Iterable[str | Path], tables_dir: str | Path) -> dict[str, Path]:
    """Concatenate parsed runs (folders written by :func:`parse_run`) into ``tables_dir``.

    Tables (each ``<name>.parquet`` + ``<name>.csv``; every one has ``case`` and ``engine``
    columns; a kind without runs is written with its columns and no rows):
    ``forces_timeseries`` (cutting runs' timeseries), ``forces_summary`` (one row per cutting
    run), ``platen_timeseries`` and ``platen_summary`` (UCS/BTS, with ``test``),
    ``damage_summary`` (one row per run), ``broken_bonds_timeseries`` (per run: time_s, step,
    cumulative bonds_broken and by mode). Returns {name: parquet path}.
    """
    tables_dir = Path(tables_dir)
    seen: dict[tuple[str, str], Path] = {}
    forces_ts: list[pd.DataFrame] = []
    platen_ts: list[pd.DataFrame] = []
    broken_ts: list[pd.DataFrame] = []
    forces_sum: list[dict[str, Any]] = []
    platen_sum: list[dict[str, Any]] = []
    damage_sum: list[dict[str, Any]] = []
    for d in map(Path, parsed_dirs):
        s = _load_summary(d)
        case, engine, test = s["case"], s["engine"], s["test"]
        if (case, engine) in seen:  # the same case may run on both engines (cross-engine checks)
            raise ValueError(f"{d}: case {case!r} on {engine} also parsed in {seen[case, engine]} "
                             "(one folder per case and engine)")
        seen[case, engine] = d
        ts = read_table(d / "timeseries")
        ts.insert(0, "engine", engine)
        ts.insert(0, "case", case)
        bt = read_table(d / "broken_timeseries")
        bt.insert(0, "test", test)
        bt.insert(0, "engine", engine)
        bt.insert(0, "case", case)
        broken_ts.append(bt)
        damage_sum.append({k: s.get(k, _nan()) for k in DAMAGE_SUMMARY_COLUMNS})
        if test == "cutting":
            forces_ts.append(ts)
            forces_sum.append(s)
        else:
            ts.insert(2, "test", test)
            platen_ts.append(ts)
            platen_sum.append(s)
    head = ["case", "engine"]
    tables = {
        "forces_timeseries": _frame(forces_ts, head + CUTTING_TIMESERIES_COLUMNS, concat=True),
        "forces_summary": _frame(forces_sum, head + [c for c in CUTTING_SUMMARY_COLUMNS if c not in head], concat=False),
        "platen_timeseries": _frame(platen_ts, head + ["test"] + PLATEN_TIMESERIES_COLUMNS, concat=True),
        "platen_summary": _frame(platen_sum, head + [c for c in PLATEN_SUMMARY_COLUMNS if c not in head], concat=False),
        "damage_summary": _frame(damage_sum, DAMAGE_SUMMARY_COLUMNS[:2] + [c for c in DAMAGE_SUMMARY_COLUMNS[2:]], concat=False),
        "broken_bonds_timeseries": _frame(broken_ts, head + ["test"] + BROKEN_TS_COLUMNS, concat=True),
    }
    return {name: write_table(df, tables_dir / name) for name, df in tables.items()}
