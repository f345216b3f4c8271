"""Chips (connected components of the remaining bond graph) and specific energy."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from deckgen.chips import cutter_work, detachment, find_chips, groove_area, initial_positions, kinematic_volume
from deckgen.datafile import read_bonds
from deckgen.results import UNITLESS_COLUMNS, has_unit
from deckgen.geometry import ccs_disc, v_disc
from helpers import load_script

RUNS = Path(__file__).resolve().parent / "data" / "runs"


def _atoms(n: int, r: float = 1e-3) -> pd.DataFrame:
    return pd.DataFrame({"id": np.arange(1, n + 1), "type": 1, "radius": r,
                         "x": np.arange(n) * 2 * r, "y": 0.0, "z": 0.0})


def test_detachment_is_the_first_break_that_frees_a_piece_of_min_grains():
    """A chain 1-2-...-10 (the body) with a 4-grain branch 11-14 hanging off grain 5 by the bond 5-11. Bonds break
    at steps 100 (10-9: one grain of debris), 200 (13-14: the branch's tail, 1 grain) and 300 (5-11: the 3-grain rest
    of the branch comes off). With min_grains 3 the detachment is step 300: F_n's largest value up to it is the
    destructive force (step 200's 9 N, not the later 12 N), the penetration at step 300 the penetration at failure.
    With min_grains 2 it is still 300 (the freed tail and debris are single grains); with 4 no piece is big enough."""
    chain = [[i, i + 1] for i in range(1, 10)]
    branch = [[5, 11], [11, 12], [12, 13], [13, 14]]
    bonds = np.array(chain + branch)
    broken = pd.DataFrame({"id1": [10, 13, 5], "id2": [9, 14, 11], "step": [100, 200, 300]})
    ts = pd.DataFrame({"step": [0, 100, 200, 300, 400], "force_normal_N": [0.0, 4.0, 9.0, 3.0, 12.0],
                       "penetration_m": [0.0, 1e-4, 2e-4, 3e-4, 4e-4]})
    d = detachment(bonds, broken, ts, min_grains=3)
    assert d["detachment_step"] == 300
    assert d["force_normal_N_destructive"] == 9.0 and d["penetration_at_destructive_m"] == pytest.approx(2e-4)
    assert d["penetration_at_failure_m"] == pytest.approx(3e-4)
    assert math.isnan(d["force_side_N_destructive"])  # the series has no side force
    with_side = detachment(bonds, broken, ts.assign(force_side_N=[0.0, -1.0, -2.5, -1.0, -6.0]), min_grains=3)
    assert with_side["force_side_N_destructive"] == -2.5
    assert detachment(bonds, broken, ts, min_grains=2)["detachment_step"] == 300
    none = detachment(bonds, broken, ts, min_grains=4)
    assert math.isnan(none["detachment_step"]) and math.isnan(none["force_normal_N_destructive"])
    # every key obeys the table's unit rule (deckgen.results)
    assert all(has_unit(k) or k in UNITLESS_COLUMNS for k in d)
    # a break between series rows reads the last row at or before it: the branch off at step 250 -> rows up to 200
    between = broken.assign(step=[100, 200, 250])
    b = detachment(bonds, between, ts, min_grains=3)
    assert b["detachment_step"] == 250 and b["force_normal_N_destructive"] == 9.0
    assert b["penetration_at_failure_m"] == pytest.approx(2e-4)
    # a piece that later splits below the size still counts from when it came off: the branch is off at step 100,
    # split at 200, and four later breaks free single grains of the chain's end. A bisection over the six break
    # steps would test step 300 (no piece of 3), search later and find none; the scan in step order finds 100.
    seq = pd.DataFrame({"id1": [5, 12, 10, 9, 8, 7], "id2": [11, 13, 9, 8, 7, 6], "step": [100, 200, 300, 310, 320, 330]})
    assert detachment(bonds, seq, ts, min_grains=3)["detachment_step"] == 100


def test_backward_detachment_scan_agrees_with_the_plain_definition_on_random_break_records():
    """first_detachment_step (final graph once, then bonds put back step by step with a DisjointSet) against
    _first_detachment_scan (the graph relabelled after every break step) on 300 random records: lattice-like graphs
    of 30-160 grains with a few loose clusters, 5-100 % of the bonds broken in random order with shared steps, some
    pairs recorded twice (the first step counts) and some pairs that are no initial bond (ignored), min_grains 2-40.
    Both must give the same step or both None; the records are made so that both outcomes and late, non-monotone
    break-offs occur (a piece off early and split below the size later)."""
    from deckgen.chips import _first_detachment_scan, bond_components, first_detachment_step

    rng = np.random.default_rng(51)
    outcomes = {"none": 0, "found": 0, "gone_at_the_end": 0}
    for _ in range(300):
        n = int(rng.integers(30, 160))
        w = int(rng.integers(3, 9))
        grid = [(i, i + 1) for i in range(1, n) if i % w] + [(i, i + w) for i in range(1, n - w + 1)]
        extra = [tuple(sorted(rng.choice(np.arange(1, n + 1), 2, replace=False))) for _ in range(n // 10)]
        loose = [(n + 1 + j, n + 2 + j) for j in range(int(rng.integers(0, 4)))]  # a small loose chain
        bonds = np.array(grid + extra + loose, dtype=np.int64)
        k = int(rng.integers(max(1, len(bonds) // 20), len(bonds) + 1))
        pick = bonds[rng.choice(len(bonds), k, replace=False)]
        steps = np.sort(rng.integers(1, max(2, k // 2), k)) * 100
        again = rng.choice(k, k // 8, replace=False)  # recorded a second time, later
        # strays: a pair with a grain that does not exist, and pairs of two real grains that are no bond
        strays = np.array([[1, n + 20]] * int(rng.integers(0, 2)) + [[2, n]] * int(rng.integers(0, 2))
                          + [[3, n - 1]] * int(rng.integers(0, 2)), dtype=np.int64).reshape(-1, 2)
        strays = strays[[not ((bonds == p).all(axis=1) | (bonds == p[::-1]).all(axis=1)).any() for p in strays]]
        pairs = np.vstack([pick, pick[again][:, ::-1], strays])
        st = np.concatenate([steps, steps[again] + 1000, rng.integers(1, 50, len(strays)) * 100])
        mg = int(rng.integers(2, 41))
        fast, plain = first_detachment_step(bonds, pairs, st, mg), _first_detachment_scan(bonds, pairs, st, mg)
        assert fast == plain, (n, w, k, mg)
        outcomes["none" if plain is None else "found"] += 1
        if plain is not None:  # the piece found no longer has min_grains at the end: a late split (non-monotone)
            _, sizes, body = bond_components(bonds, pairs, np.unique(bonds))
            outcomes["gone_at_the_end"] += not (np.delete(sizes, body) >= mg).any()
    assert min(outcomes.values()) >= 30, outcomes
    # the recorded example of the test above: the branch off at step 100, split below 3 grains at 200
    chain = [[i, i + 1] for i in range(1, 10)]
    bonds = np.array(chain + [[5, 11], [11, 12], [12, 13], [13, 14]])
    seq = np.array([[5, 11], [12, 13], [10, 9], [9, 8], [8, 7], [7, 6]])
    assert first_detachment_step(bonds, seq, np.array([100, 200, 300, 310, 320, 330]), 3) == 100
    assert first_detachment_step(bonds, seq[2:], np.array([300, 310, 320, 330]), 3) is None
    assert first_detachment_step(bonds, np.zeros((0, 2)), np.zeros(0), 3) is None
    with pytest.raises(ValueError, match="must not be negative"):
        first_detachment_step(bonds, np.array([[-1, 2]]), np.array([100]), 3)


def test_detachment_gives_the_first_piece_at_its_initial_place():
    """The chain-and-branch graph of the test above, the branch 11-14 laid out along z at x = 8 mm (grain 11 at
    z = 2 mm, then 4, 6, 8 mm; radius 1 mm), and the grains moved afterwards (the piece's place at the start counts).
    At step 300 grains 11-13 come off (14 left at step 200): 3 grains, x and y extents one diameter (2 mm), z from
    1 to 7 mm (6 mm), bulk volume 3 * 4/3 pi r^3 / 0.6. Without initial positions the keys are NaN."""
    chain = [[i, i + 1] for i in range(1, 10)]
    bonds = np.array(chain + [[5, 11], [11, 12], [12, 13], [13, 14]])
    broken = pd.DataFrame({"id1": [10, 13, 5], "id2": [9, 14, 11], "step": [100, 200, 300]})
    ts = pd.DataFrame({"step": [0, 100, 200, 300], "force_normal_N": [0.0, 4.0, 9.0, 3.0],
                       "penetration_m": [0.0, 1e-4, 2e-4, 3e-4]})
    initial = _atoms(14)
    initial.loc[10:, "x"] = 8e-3
    initial.loc[10:, "z"] = [2e-3, 4e-3, 6e-3, 8e-3]
    d = detachment(bonds, broken, ts, min_grains=3, initial=initial.sample(frac=1.0, random_state=1),
                   solid_fraction=0.6)
    assert d["detachment_step"] == 300 and d["detached_piece_grains"] == 3
    assert d["detached_piece_extent_x_m"] == pytest.approx(2e-3)
    assert d["detached_piece_extent_y_m"] == pytest.approx(2e-3)
    assert d["detached_piece_extent_z_m"] == pytest.approx(6e-3)
    assert d["detached_piece_volume_m3"] == pytest.approx(3 * 4 / 3 * math.pi * 1e-9 / 0.6)
    assert [d[f"detached_piece_min_{a}_m"] for a in "xyz"] == pytest.approx([7e-3, -1e-3, 1e-3])
    assert [d[f"detached_piece_max_{a}_m"] for a in "xyz"] == pytest.approx([9e-3, 1e-3, 7e-3])
    assert all(has_unit(k) or k in UNITLESS_COLUMNS for k in d)
    bare = detachment(bonds, broken, ts, min_grains=3)
    assert bare["detachment_step"] == 300 and math.isnan(bare["detached_piece_extent_z_m"])
    with pytest.raises(ValueError, match="lack 1 bonded grains"):
        detachment(bonds, broken, ts, min_grains=3, initial=initial[initial["id"] != 12], solid_fraction=0.6)


def test_initial_positions_read_a_bpm_data_file_and_else_the_step_0_dump(tmp_path):
    """deckgen's bpm/sphere data file (id molecule type diameter density x y z) read back: radius = diameter / 2, the
    types kept (a type-2 shell sphere included), positions exact; without it the step-0 frame of atoms.dump.gz; a later
    first frame or no file gives None; a short atom line is a ParseError naming the file and line."""
    from deckgen.datafile import write_bpm_data
    from deckgen.parse.common import ParseError

    x = np.array([[1e-3, 2e-3, 3e-3], [4e-3, -5e-3, 6e-3], [7e-3, 8e-3, -9e-3]])
    write_bpm_data(tmp_path / "specimen.data", title="t", box=np.array([[-1e-2, 1e-2]] * 3),
                   types=np.array([1, 1, 2]), radius=np.array([0.7e-3, 0.9e-3, 0.3e-3]),
                   density=np.full(3, 2000.0), x=x, n_atom_types=2, bonds=np.array([[0, 1]]),
                   bond_types=np.array([1]), n_bond_types=1)
    a = initial_positions(tmp_path)
    assert a["id"].tolist() == [1, 2, 3] and a["type"].tolist() == [1, 1, 2]
    assert a["radius"].to_numpy() == pytest.approx([0.7e-3, 0.9e-3, 0.3e-3], rel=1e-9)
    assert a[["x", "y", "z"]].to_numpy() == pytest.approx(x, rel=1e-9)
    dump = tmp_path / "d"
    dump.mkdir()
    frame = ("ITEM: TIMESTEP\n{step}\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS pp pp pp\n-1 1\n-1 1\n-1 1\n"
             "ITEM: ATOMS id type radius x y z\n7 1 0.001 0.1 0.2 0.3\n8 1 0.002 0.4 0.5 0.6\n")
    import gzip

    with gzip.open(dump / "atoms.dump.gz", "wt") as fh:
        fh.write(frame.format(step=0) + frame.format(step=100))
    b = initial_positions(dump)
    assert b["id"].tolist() == [7, 8] and b["radius"].tolist() == [0.001, 0.002] and b["z"].tolist() == [0.3, 0.6]
    with gzip.open(dump / "atoms.dump.gz", "wt") as fh:
        fh.write(frame.format(step=100))
    assert initial_positions(dump) is None and initial_positions(tmp_path / "none") is None
    text = (tmp_path / "specimen.data").read_text().replace("2 0 1 ", "2 0 ", 1)
    (tmp_path / "bad").mkdir()
    (tmp_path / "bad" / "specimen.data").write_text(text)
    with pytest.raises(ParseError, match=r"specimen.data:\d+: bpm/sphere atom line needs 8 columns"):
        initial_positions(tmp_path / "bad")


def test_two_triangles_split_into_body_and_chip():
    # grains 1-3 and 4-6 are triangles joined by the bond 3-4 (plus 7 bonded only to 6)
    bonds = np.array([[1, 2], [2, 3], [1, 3], [3, 4], [4, 5], [5, 6], [4, 6], [6, 7]])
    atoms = _atoms(8)  # grain 8 never had a bond: neither chip nor debris
    table, s = find_chips(bonds, np.array([[4, 3], [7, 6]]), atoms, solid_fraction=0.6, min_grains=3)
    assert s["chips_count"] == 1 and s["chips_grains"] == 3
    assert s["body_grains"] == 3
    assert s["debris_grains"] == 1  # grain 7 lost its only bond
    v = 4 / 3 * math.pi * 1e-9
    assert s["chips_volume_m3"] == pytest.approx(3 * v / 0.6)
    assert s["removed_volume_m3"] == pytest.approx(4 * v / 0.6)
    # the chip is one of the triangles: 3 grains in a row of 2 mm spacing, 1 mm radius
    assert table["extent_x_m"].iloc[0] == pytest.approx(6e-3)
    assert table["extent_z_m"].iloc[0] == pytest.approx(2e-3)


def test_nothing_broken_means_no_chips():
    bonds = np.array([[1, 2], [2, 3]])
    table, s = find_chips(bonds, np.zeros((0, 2), dtype=int), _atoms(3), 0.6)
    assert s["chips_count"] == 0 and s["removed_volume_m3"] == 0 and len(table) == 0


def test_groove_area_of_a_sharp_v_disc():
    # a sharp V of included angle 60 deg cuts a triangle: area = p^2 tan(30 deg)
    R, p = 10e-3, 2e-3
    prof = v_disc(2 * R, 60.0, 0.0, 8e-3)
    assert groove_area(prof, R, p) == pytest.approx(p**2 * math.tan(math.radians(30)), rel=1e-6)
    assert groove_area(prof, R, 0.0) == pytest.approx(0.0, abs=1e-15)


def test_groove_area_of_a_ccs_disc_grows_with_tip_width():
    R, p = 0.2159, 5e-3
    narrow = groove_area(ccs_disc(2 * R, 12e-3, 0.0 + 1e-4, 10.0, 60e-3), R, p)
    wide = groove_area(ccs_disc(2 * R, 20e-3, 1e-4, 10.0, 60e-3), R, p)
    assert wide - narrow == pytest.approx(8e-3 * p, rel=0.02)  # 8 mm wider land over 5 mm depth


def test_cutter_work_of_a_constant_force():
    t = np.linspace(0, 1e-3, 101)
    ts = pd.DataFrame({"time_s": t, "cutter_x_m": 2.0 * t, "cutter_y_m": 0.0, "cutter_z_m": 0.0,
                       "force_x_N": -10.0, "force_y_N": 3.0, "force_z_N": 5.0, "torque_y_Nm": -0.5,
                       "torque_z_Nm": -0.2})
    # translation: -F.v = 10 N * 2 m/s for 1 ms = 0.02 J; spin 100 rad/s against -0.5 N m: 0.05 J
    assert cutter_work(ts, 0.0) == pytest.approx(0.02)
    assert cutter_work(ts, 100.0) == pytest.approx(0.02 + 0.05)
    # yaw (rotary path) at 10 rad/s against -0.2 N m about z: 0.002 J more
    assert cutter_work(ts, 100.0, yaw_rate=10.0) == pytest.approx(0.02 + 0.05 + 0.002)


def test_chips_on_the_committed_reference_cut(tmp_path):
    """Initial bonds from the step-0 bond sample; every grain is body, chip, debris or intact-unbonded."""
    from deckgen.chips import initial_bonds
    from deckgen.results import parse_run

    run = RUNS / "ref_cut"
    spec = json.loads((run / "spec.json").read_text())
    bonds = initial_bonds(run)
    assert len(bonds) == spec["derived"]["n_bonds"]
    s = parse_run(run, tmp_path / "p")
    assert s["notes"] == ""
    assert s["body_grains"] + s["chips_grains"] + s["debris_grains"] <= spec["derived"]["n_grains"]
    assert s["body_grains"] > 0.5 * spec["derived"]["n_grains"]
    assert s["cutter_work_J"] > 0
    assert s["kinematic_volume_m3"] == pytest.approx(kinematic_volume(spec["case"], spec["derived"]), rel=1e-12)


@pytest.mark.engine
def test_chips_of_a_real_cut(tmp_path):
    """Tiny oscillating cut (golden case, committed packing) run by the engine, then parsed."""
    from deckgen.results import parse_run
    from deckgen.runner import engine_available, run_deck

    if not engine_available():
        pytest.skip("no LAMMPS binary (run `make setup`)")
    golden = Path(__file__).resolve().parent / "data" / "golden"
    regen = load_script(golden / "regenerate.py")
    run = tmp_path / "run"
    regen.render_golden("tiny_cut", run, tmp_path / "cache")
    spec = json.loads((run / "spec.json").read_text())
    run_deck(run, expected_steps=spec["derived"]["expected_steps"], progress=False)
    s = parse_run(run, tmp_path / "parsed")
    chips = pd.read_parquet(tmp_path / "parsed" / "chips.parquet")
    n = spec["derived"]["n_grains"]
    assert s["bonds_broken"] > 0
    assert s["chips_count"] == len(chips) and s["chips_grains"] == int(chips["n_grains"].sum())
    assert (chips["n_grains"] >= 2).all()
    assert s["body_grains"] + s["chips_grains"] + s["debris_grains"] <= n
    assert s["body_grains"] > 0.5 * n  # the block stays one piece
    assert s["removed_volume_m3"] == pytest.approx(s["chips_volume_m3"] + s["debris_volume_m3"])
    assert s["cutter_work_J"] > 0
    # kinematic groove of the 60 deg V disc (tip radius 0.3 mm) at 1.5 mm over 3 - 1 mm of cut
    assert s["kinematic_volume_m3"] == pytest.approx(kinematic_volume(spec["case"], spec["derived"]))
    assert 0.3 * 1.5e-3**2 * math.tan(math.radians(30)) * 2e-3 < s["kinematic_volume_m3"] < 1.5e-3**2 * 2e-3
    assert s["specific_energy_kinematic_J_m3"] == pytest.approx(s["cutter_work_J"] / s["kinematic_volume_m3"])
    assert len(read_bonds(run / "specimen.data")) == spec["derived"]["n_bonds"]


def test_bench_detachment_times_both_scans_on_a_recorded_run_folder(tmp_path, capsys):
    """bench/detachment.py on a folder laid out as the session scripts leave one (run/specimen.data of the reference
    cut, parsed/broken.csv): its bonds broken one by one in a random order at steps 10, 20, ... The two scans must agree and
    the line must name the bonds, the broken records and the break-off step; a folder without a broken table is a
    clear exit naming the fix."""
    import shutil

    from deckgen.chips import _first_detachment_scan, initial_bonds
    from deckgen.scriptload import load_script

    root = Path(__file__).resolve().parents[1]
    bench = load_script(root / "bench" / "detachment.py", "bench_detachment")
    run = tmp_path / "case" / "run"
    run.mkdir(parents=True)
    shutil.copy(root / "tests" / "data" / "runs" / "ref_cut" / "specimen.data", run / "specimen.data")
    bonds = initial_bonds(run)
    pick = bonds[np.random.default_rng(7).permutation(len(bonds))]
    (tmp_path / "case" / "parsed").mkdir()
    steps = 10 * np.arange(1, len(pick) + 1)
    pd.DataFrame({"id1": pick[:, 0], "id2": pick[:, 1], "step": steps}).to_csv(
        tmp_path / "case" / "parsed" / "broken.csv", index=False)
    expected = _first_detachment_scan(bonds, pick, steps, 5)
    assert expected is not None and 10 < expected < steps[-1]  # neither the first nor the last break
    assert bench.main([str(tmp_path / "case"), "--repeat", "1", "--min-grains", "5"]) == 0
    out = capsys.readouterr().out
    assert f"{len(bonds)} bonds, {len(pick)} broken at {len(pick)} steps, break-off step {expected};" in out
    assert "1 runs: plain/backward x" in out
    (tmp_path / "empty" / "run").mkdir(parents=True)
    shutil.copy(run / "specimen.data", tmp_path / "empty" / "run" / "specimen.data")
    with pytest.raises(SystemExit, match="no parsed/broken.parquet or parsed/broken.csv"):
        bench.main([str(tmp_path / "empty")])
