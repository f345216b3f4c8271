"""Real LAMMPS runs (seconds each): packing statistics, a tiny UCS test, an unloaded specimen,
and the runner's failure detection. These use the engine installed by `make setup`."""

from __future__ import annotations

import json
import math
import re
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from deckgen.deck import render_case
from deckgen.packing import ensure_packing, load_packing
from deckgen.parse.series import read_series
from deckgen.runner import EngineError, engine_available, engine_command, run_deck
from deckgen.spec import load_case

ROOT = Path(__file__).resolve().parents[1]
CASES = ROOT / "tests" / "data" / "cases"

pytestmark = pytest.mark.engine


if not engine_available():  # pragma: no cover
    pytest.skip("no LAMMPS binary (run `make setup`)", allow_module_level=True)


@pytest.fixture(scope="module")
def cache(tmp_path_factory):
    return tmp_path_factory.mktemp("cache")


@pytest.fixture(scope="module")
def ucs_run(tmp_path_factory, cache):
    case = load_case(CASES / "tiny_ucs.yaml")
    out = tmp_path_factory.mktemp("ucs") / "run"
    spec = render_case(case, out, cache=cache, progress=False)
    res = run_deck(out, expected_steps=spec["derived"]["expected_steps"], progress=False)
    return out, spec, res


def test_packing_is_dense_jammed_and_cached(cache):
    case = load_case(CASES / "tiny_ucs.yaml")
    folder = ensure_packing(case, cache, progress=False)
    atoms, info = load_packing(folder)
    s = info["stats"]
    # a jammed random packing: deflated from over-filled to small overlaps, still in contact
    # (a tiny specimen: walls make up much of it, so the fraction is below the bulk 0.62-0.64)
    assert 0.9 < s["radius_scale"] < 1.0
    assert s["contact_pressure_Pa"] < 1.3 * s["contact_pressure_target_Pa"]
    assert 0.55 < s["solid_fraction"] < 0.64
    assert s["coordination_mean_no_rattlers"] > 5.0
    assert s["overlap_mean_rel"] < 0.005 and s["overlap_max_rel"] < 0.02
    assert len(atoms) == s["n_grains"] > 200
    r_mm = atoms.radius * 1e3 / s["radius_scale"]
    assert r_mm.min() >= 0.6 - 1e-6 and r_mm.max() <= 0.9 + 1e-6
    # all grains inside the cylinder walls (radius 4 mm, height 16 mm) up to a small wall overlap
    rho = np.hypot(atoms.x[:, 0], atoms.x[:, 1])
    assert np.all(rho + atoms.radius <= 4e-3 + 0.03e-3)
    assert np.all(atoms.x[:, 2] - atoms.radius >= -0.03e-3)
    # cached: a second call returns the same folder without running the engine
    stamp = (folder / "packing.json").stat().st_mtime_ns
    assert ensure_packing(case, cache, progress=False, command=["false"]) == folder
    assert (folder / "packing.json").stat().st_mtime_ns == stamp


def test_packing_does_not_depend_on_the_runs_ranks(tmp_path):
    """A case's packing is made on packing.ranks (1) MPI ranks whatever the run's command asks for. Packed on 2 ranks
    (packing.ranks: 2, its own cache key) the same grains end elsewhere, so the command's ranks would matter."""
    case = load_case(CASES / "tiny_ucs.yaml")
    one = ensure_packing(case, tmp_path / "run1", progress=False, command=engine_command(1))
    two = ensure_packing(case, tmp_path / "run2", progress=False, command=engine_command(2))
    assert one.name == two.name
    assert (one / "packed.data").read_bytes() == (two / "packed.data").read_bytes()
    assert json.loads((two / "packing.json").read_text())["command"] == ["lmp"]
    on2 = case.model_copy(update={"packing": case.packing.model_copy(update={"ranks": 2})})
    other = ensure_packing(on2, tmp_path / "pk2", progress=False, command=engine_command(1))
    assert other.name != one.name
    assert json.loads((other / "packing.json").read_text())["command"] == ["mpirun", "-np", "2", "lmp"]
    a, b = load_packing(one)[0], load_packing(other)[0]
    assert len(a) == len(b)  # the same radii are drawn; the positions differ
    assert not np.allclose(a.x, b.x, atol=1e-9)


def test_tiny_ucs_peak_and_post_peak_breakage(ucs_run):
    out, spec, res = ucs_run
    s = read_series(out / "series.txt")
    assert res.steps > 1000 and res.particle_steps_per_s > 0
    i = int(s["stress_Pa"].idxmax())
    peak = float(s["stress_Pa"].iloc[i])
    assert math.isfinite(peak) and peak > 1e6, peak  # at least 1 MPa for 10 GPa bonds of 30 MPa
    assert peak < 200e6
    bonds = s["bonds"].to_numpy()
    n0 = spec["derived"]["n_bonds"]
    assert bonds[0] == n0
    # the specimen failed: the run stopped after the peak with more bonds broken than at the peak
    assert bonds[-1] < bonds[i]
    assert float(s["stress_Pa"].iloc[-1]) < 0.8 * peak
    # the pre-peak branch rises: a positive modulus from 20-50 % of the peak
    pre = s.iloc[: i + 1]
    win = pre[(pre.stress_Pa > 0.2 * peak) & (pre.stress_Pa < 0.5 * peak)]
    slope = np.polyfit(win["strain"], win["stress_Pa"], 1)[0]
    assert slope > 1e8
    # the platens balance: bottom and top forces agree before the peak (quasi-static)
    mid = pre[(pre.stress_Pa > 0.4 * peak) & (pre.stress_Pa < 0.6 * peak)]
    ratio = (mid.force_bottom_N / -mid.force_top_N).mean()
    assert ratio == pytest.approx(1.0, abs=0.1)
    # lateral strain of the outer mid-height grains: the cylinder bulges, Poisson's ratio in (0, 0.5)
    lat = s["lateral_strain"].to_numpy()
    assert lat[i] > 0 and lat[i] < 0.5 * float(s["strain"].iloc[i])
    nu = np.polyfit(win["strain"], win["lateral_strain"], 1)[0]
    assert 0.0 < nu < 0.5, nu


def test_tiny_bts_with_curved_jaws(tmp_path, cache):
    """ISRM jaws: loading starts at contact (no gap), top and bottom jaw forces balance, the disc fails."""
    case = load_case(CASES / "tiny_bts.yaml")
    assert case.specimen.loading == "jaws"
    out = tmp_path / "bts"
    spec = render_case(case, out, cache=cache, progress=False)
    jaws = spec["derived"]["jaws"]
    assert jaws["R_jaw"] == pytest.approx(1.5 * 5e-3)
    run_deck(out, expected_steps=spec["derived"]["expected_steps"], progress=False)
    s = read_series(out / "series.txt")
    assert (s["force_top_N"].iloc[1:4] < 0).all()  # in contact from the first rows: no gap at the start
    i = int(s["stress_Pa"].idxmax())
    peak = float(s["stress_Pa"].iloc[i])
    assert 0.5e6 < peak < 50e6, peak
    pre = s.iloc[: i + 1]
    mid = pre[(pre.stress_Pa > 0.3 * peak) & (pre.stress_Pa < 0.6 * peak)]
    assert (mid.force_bottom_N / -mid.force_top_N).mean() == pytest.approx(1.0, abs=0.15)
    assert float(s["bonds"].iloc[-1]) < float(s["bonds"].iloc[i])


def test_unloaded_specimen_keeps_all_bonds(ucs_run, tmp_path):
    """No loading for 20000 steps at the computed dt: spontaneous breakage would show an unstable dt."""
    src, spec, _ = ucs_run
    out = tmp_path / "rest"
    out.mkdir()
    for f in ("in.deck", "specimen.data"):
        shutil.copy(src / f, out / f)
    cmd = engine_command() + ["-var", "v_platen", "0.0", "-var", "chunk", "4000", "-var", "nchunks", "5",
                              "-var", "stop_frac", "-1.0e9"]
    res = run_deck(out, command=cmd, progress=False)
    assert res.steps >= 20000
    s = read_series(out / "series.txt")
    assert (s["bonds"] == spec["derived"]["n_bonds"]).all()
    assert s["ke_J"].iloc[-1] < 1e-3  # no energy pumped in by an unstable step


def test_runner_reports_engine_error_line(tmp_path):
    (tmp_path / "in.deck").write_text("units si\nbogus_command 1 2 3\n")
    with pytest.raises(EngineError, match=r"log\.lammps:\d+: ERROR.*[Uu]nknown command.*bogus_command"):
        run_deck(tmp_path, command=engine_command(1), progress=False)


def test_runner_reports_lost_atoms(tmp_path):
    (tmp_path / "in.deck").write_text(
        "units si\natom_style sphere\nboundary f f f\nregion b block 0 1 0 1 0 1 units box\ncreate_box 1 b\n"
        "create_atoms 1 single 0.5 0.5 0.5 units box\nset atom 1 diameter 0.1 density 1000\n"
        "velocity all set 100 0 0 units box\npair_style zero 1.0\npair_coeff * *\nfix 1 all nve/sphere\n"
        "timestep 0.001\nthermo 1\nrun 20\n")
    with pytest.raises(EngineError, match=r"log\.lammps:\d+: ERROR: Lost atoms: original 1 current 0"):
        run_deck(tmp_path, command=engine_command(1), progress=False)


_ENDLESS = ("units si\natom_style sphere\nboundary f f f\nregion b block 0 1 0 1 0 1 units box\ncreate_box 1 b\n"
            "create_atoms 1 single 0.5 0.5 0.5 units box\nset atom 1 diameter 0.1 density 1000\npair_style zero 1.0\n"
            "pair_coeff * *\nfix 1 all nve/sphere\ntimestep 1e-9\nthermo 1000000\nrun 2000000000\n")


def _processes_in(folder: Path) -> list[int]:
    """Pids of the processes whose working directory is ``folder`` (the engine's run folder)."""
    pids = []
    for d in Path("/proc").iterdir():
        if d.name.isdigit():
            try:
                if Path(d / "cwd").resolve() == folder.resolve():
                    pids.append(int(d.name))
            except OSError:
                continue
    return pids


def _wait_gone(folder: Path, seconds: float = 10.0) -> list[int]:
    import time

    t0 = time.time()
    while _processes_in(folder) and time.time() - t0 < seconds:
        time.sleep(0.2)
    return _processes_in(folder)


@pytest.mark.skipif(not Path("/proc/self/cwd").exists(), reason="needs /proc to find the engine processes")
def test_runner_timeout_stops_the_engine_binary_not_only_its_wrapper(tmp_path):
    # the PyPI lmp is a Python wrapper that starts the real binary: killing the wrapper alone left the binary running
    (tmp_path / "in.deck").write_text(_ENDLESS)
    with pytest.raises(EngineError, match="exceeded 3 s"):
        run_deck(tmp_path, command=engine_command(1), progress=False, timeout_s=3)
    assert _wait_gone(tmp_path) == []


@pytest.mark.skipif(not Path("/proc/self/cwd").exists(), reason="needs /proc to find the engine processes")
def test_sigterm_stops_the_running_engine(tmp_path):
    import signal
    import subprocess
    import sys
    import time

    (tmp_path / "in.deck").write_text(_ENDLESS)
    script = ("import sys\nfrom deckgen.runner import engine_command, run_deck, stop_engines_on_sigterm\n"
              "stop_engines_on_sigterm()\n"
              f"run_deck({str(tmp_path)!r}, command=engine_command(1), progress=False)\n")
    proc = subprocess.Popen([sys.executable, "-c", script], stderr=subprocess.PIPE, text=True)
    t0 = time.time()
    while not (tmp_path / "log.lammps").exists() and time.time() - t0 < 60:
        time.sleep(0.2)
    time.sleep(1.0)
    assert len(_processes_in(tmp_path)) >= 1  # the engine is running
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=30)
    assert proc.returncode == 128 + signal.SIGTERM, err
    assert "1 running engine(s) stopped" in err
    assert _wait_gone(tmp_path) == []


def test_cli_render_and_stl(tmp_path, cache, capsys):
    from deckgen.cli import main

    assert main(["stl", str(CASES / "tiny_cut.yaml"), "--out", str(tmp_path / "c.stl")]) == 0
    assert "diameter 12.000 mm" in capsys.readouterr().out
    assert (tmp_path / "c.stl").read_bytes()[:5] != b"solid"
    assert main(["render", str(CASES / "tiny_bts.yaml"), "--out", str(tmp_path / "bts"), "--cache", str(cache),
                 "--no-progress"]) == 0
    spec = json.loads((tmp_path / "bts" / "spec.json").read_text())
    assert spec["case"]["test"] == "bts"
    # BTS stress area: sigma_t = 2F/(pi D t)  ->  area = pi D t / 2
    assert spec["derived"]["area_m2"] == pytest.approx(math.pi * 10e-3 * 5e-3 / 2)


def test_indentation_kinematics_and_contact(tmp_path, cache):
    """The shell follows z_c = z_c0 - v t exactly; the normal force appears only after contact."""
    case = load_case(CASES / "tiny_indent.yaml")
    out = tmp_path / "indent"
    spec = render_case(case, out, cache=cache, progress=False)
    cut = spec["derived"]["cutter"]
    assert cut["mode_indent"] == 1.0
    assert cut["yc0"] == pytest.approx(-6e-3 + 4e-3)  # cut spacing from the free y-min face
    run_deck(out, expected_steps=spec["derived"]["expected_steps"], progress=False)
    s = read_series(out / "series.txt").drop_duplicates("step", keep="last")
    assert np.allclose(s["cutter_z_m"], cut["zc0"] - cut["V"] * s["time_s"], atol=1e-12, rtol=0)
    assert np.allclose(s["cutter_x_m"], cut["xc0"], atol=1e-15)
    # the tip reaches the block top (z = 8 mm) after the start clearance: no force before that
    gap = (cut["zc0"] - cut["radius"]) - 8e-3
    before = s[cut["V"] * s["time_s"] < gap - 0.05e-3]
    assert len(before) > 5 and (before[["force_x_N", "force_y_N", "force_z_N"]].abs().max() < 1e-9).all()
    after = s[cut["V"] * s["time_s"] > gap + 0.5e-3]
    assert len(after) > 5 and after["force_z_N"].max() > 1.0  # the rock pushes the disc up
    assert s["bonds"].iloc[-1] < spec["derived"]["n_bonds"]  # the indentation broke bonds
    # parsed: the penetration at the peak normal force is that row's, and the chip's break-off (deckgen.chips.detachment)
    # comes with a destructive force no larger than the peak, reached no later than the break-off
    from deckgen.results import parse_run

    summ = parse_run(out, tmp_path / "indent_parsed")
    ts = pd.read_parquet(tmp_path / "indent_parsed" / "timeseries.parquet")
    i = int(np.argmax(ts["force_normal_N"].abs().to_numpy()))
    assert summ["force_normal_N_peak"] == pytest.approx(ts["force_normal_N"].iloc[i])
    assert summ["penetration_at_peak_normal_m"] == pytest.approx(ts["penetration_m"].iloc[i])
    assert 0 < summ["penetration_at_peak_normal_m"] <= 1.5e-3 + 1e-6
    # the break-off step checked against the bond graph rebuilt from the parsed broken-bond table: a piece of >= 25
    # grains besides the body at that step and none at the break step before it (or none at all by the end)
    from deckgen.chips import DETACH_MIN_GRAINS, bond_components, initial_bonds

    bonds = initial_bonds(out)
    br = pd.read_parquet(tmp_path / "indent_parsed" / "broken.parquet")
    ids = np.unique(bonds)

    def biggest_piece(step):
        _, sizes, body = bond_components(bonds, br.loc[br["step"] <= step, ["id1", "id2"]].to_numpy(), ids)
        return int(np.delete(sizes, body).max(initial=0))

    steps = np.unique(br["step"])
    assert len(steps) > 0
    if math.isfinite(summ["detachment_step"]):
        s0 = int(summ["detachment_step"])
        assert biggest_piece(s0) >= DETACH_MIN_GRAINS
        earlier = steps[steps < s0]
        assert not len(earlier) or biggest_piece(earlier[-1]) < DETACH_MIN_GRAINS
        upto = ts[ts["step"] <= s0]
        assert summ["force_normal_N_destructive"] == pytest.approx(upto["force_normal_N"].max())
        assert summ["penetration_at_failure_m"] == pytest.approx(upto["penetration_m"].iloc[-1])
        assert summ["force_normal_N_destructive"] <= summ["force_normal_N_peak"]
        # the first piece: as many grains as the rebuilt graph's biggest piece then, its zone inside the block
        assert summ["detached_piece_grains"] == biggest_piece(s0)
        blk = spec["case"]["specimen"]
        for a, dim in zip("xyz", ("length_mm", "width_mm", "height_mm")):
            assert 0 < summ[f"detached_piece_extent_{a}_m"] <= blk[dim] * 1e-3 + 1e-9
    else:
        assert all(biggest_piece(s) < DETACH_MIN_GRAINS for s in steps)
        assert math.isnan(summ["force_normal_N_destructive"]) and math.isnan(summ["penetration_at_failure_m"])
        assert math.isnan(summ["detached_piece_grains"]) and math.isnan(summ["detached_piece_volume_m3"])
    # read again at a smaller break-off size (deckgen parse --breakoff-min-grains), and as a case asking for that size:
    # the first break step that frees a piece of that size, never later than at the case's 25 grains
    from deckgen.chips import first_detachment_step
    from deckgen.cli import main

    assert (summ["detachment_min_grains"], summ["detachment_min_grains_source"]) == (DETACH_MIN_GRAINS, "case")
    small = 5
    want = first_detachment_step(bonds, br[["id1", "id2"]].to_numpy(np.int64), br["step"].to_numpy(np.int64), small)
    assert want is not None and biggest_piece(want) >= small
    assert not len(steps[steps < want]) or biggest_piece(steps[steps < want][-1]) < small
    assert not math.isfinite(summ["detachment_step"]) or want <= summ["detachment_step"]
    assert main(["parse", str(out), "--out", str(tmp_path / "p5"), "--breakoff-min-grains", str(small)]) == 0
    s5 = json.loads((tmp_path / "p5" / "summary.json").read_text())
    assert (s5["detachment_min_grains"], s5["detachment_min_grains_source"], s5["detachment_step"]) == (small, "parse", want)
    assert s5["force_normal_N_destructive"] == pytest.approx(ts.loc[ts["step"] <= want, "force_normal_N"].max())
    assert s5["force_normal_N_peak"] == summ["force_normal_N_peak"] and s5["bonds_broken"] == summ["bonds_broken"]
    spec_json = json.loads((out / "spec.json").read_text())
    spec_json["case"]["outputs"]["breakoff_min_grains"] = small
    (out / "spec.json").write_text(json.dumps(spec_json))
    s5c = parse_run(out, tmp_path / "p5c")
    assert (s5c["detachment_min_grains"], s5c["detachment_min_grains_source"], s5c["detachment_step"]) == (small, "case", want)
    assert main(["parse", str(out), "--out", str(tmp_path / "p1"), "--breakoff-min-grains", "1"]) != 0


def test_rotary_path_moves_the_shell_rigidly(tmp_path, cache):
    """Rotary cut: the centre stays on the circle, and every shell sphere ends where the rigid
    motion (spin about the yawing disc axis, then yaw about the rotary axis) puts it."""
    from deckgen.parse.dump import iter_frames

    case = load_case(CASES / "tiny_rotary.yaml")
    out = tmp_path / "rot"
    spec = render_case(case, out, cache=cache, progress=False)
    cut = spec["derived"]["cutter"]
    assert cut["yaw_rate"] == pytest.approx(2.0 / 0.02)
    run_deck(out, expected_steps=spec["derived"]["expected_steps"], progress=False)
    s = read_series(out / "series.txt").drop_duplicates("step", keep="last")
    phi = s["path_angle_rad"].to_numpy()
    assert np.allclose(phi, cut["yaw_rate"] * s["time_s"], rtol=0, atol=1e-10)  # printed with 10 digits
    rr = np.hypot(s["cutter_x_m"] - cut["axis_x"], s["cutter_y_m"] - cut["axis_y"])
    assert np.allclose(rr, 0.02, rtol=0, atol=1e-10)
    assert s["force_z_N"].max() > 0.1  # it cut
    # initial shell positions from the data file, final ones from final.dump.gz
    text = (out / "specimen.data").read_text().split("Atoms # bpm/sphere")[1].split("Bonds")[0]
    init = {int(p[0]): np.array([float(v) for v in p[5:8]]) for p in (ln.split() for ln in text.strip().splitlines())
            if p[2] == "2"}
    final = None
    for frame in iter_frames(out / "final.dump.gz", ["id", "type", "x", "y", "z"]):
        final = frame.data
    final = final[final["type"] == 2]
    t_end = float(s["time_s"].iloc[-1]) + (spec["derived"]["expected_steps"] - int(s["step"].iloc[-1])) * spec["derived"]["dt_s"]
    ph, th = cut["yaw_rate"] * t_end, cut["spin_rate"] * t_end
    c0 = np.array([cut["xc0"], cut["yc0"], cut["zc0"]])
    A = np.array([cut["axis_x"], cut["axis_y"], cut["zc0"]])
    Ry = np.array([[np.cos(th), 0, np.sin(th)], [0, 1, 0], [-np.sin(th), 0, np.cos(th)]])
    Rz = np.array([[np.cos(ph), -np.sin(ph), 0], [np.sin(ph), np.cos(ph), 0], [0, 0, 1]])
    err = [np.linalg.norm(A + Rz @ ((c0 - A) + Ry @ (init[i] - c0)) - np.array([x, y, z]))
           for i, x, y, z in final[["id", "x", "y", "z"]].itertuples(index=False)]
    # write_dump prints 6 significant digits (1e-7 m here); a wrong transform is off by millimetres
    assert len(err) == len(init) and max(err) < 2e-7
    # the Python copy of the motion (used to drop shell spheres that never come near the rock) agrees
    from deckgen.deck import cutter_world_points

    ids = final["id"].to_numpy()
    rel = np.array([init[int(i)] - c0 for i in ids])
    got = cutter_world_points(rel, cut, t_end)
    assert np.abs(got - final[["x", "y", "z"]].to_numpy()).max() < 2e-7


def test_tilted_disc_spins_about_its_own_axis(tmp_path, cache):
    """Oscillating cut by a disc tilted 8 deg about x, rolling spin: the disc turns about its own (tilted) axis and
    its centre orbits in the disc's plane. Checked on the engine's output without the Python copy of the motion:
    every shell sphere keeps its distance to the centre and its coordinate along the fixed axis a, the centre moves
    in the plane normal to a, and each sphere's velocity is v_c + spin_rate a x (p - c). Then the Python copy
    (used by the leak check and the near-rock trimming) agrees to the dump's precision."""
    from deckgen.deck import cutter_world_points

    case = load_case(CASES / "tiny_cut.yaml", overrides={"cutter": {"tilt_deg": 8.0}})
    out = tmp_path / "tilt"
    spec = render_case(case, out, cache=cache, progress=False)
    cut = spec["derived"]["cutter"]
    alpha = cut["axis_tilt"]
    assert abs(abs(alpha) - math.radians(8.0)) < 1e-12
    a = np.array([0.0, math.cos(alpha), math.sin(alpha)])
    with (out / "in.deck").open("a") as fh:  # the shell's velocities at the end (the deck writes no velocity)
        fh.write("\nwrite_dump      cutter custom vel.dump id x y z vx vy vz modify sort id format float %.12e\n")
    run_deck(out, expected_steps=spec["derived"]["expected_steps"], progress=False)
    s = read_series(out / "series.txt").drop_duplicates("step", keep="last")
    c = s[["cutter_x_m", "cutter_y_m", "cutter_z_m"]].to_numpy()
    c0 = np.array([cut["xc0"], cut["yc0"], cut["zc0"]])
    assert np.abs((c - c0) @ a).max() < 1e-12  # the orbit lies in the disc's plane
    assert np.abs(c[:, 1] - c0[1]).max() > 0.2 * cut["ecc"] * math.sin(abs(alpha))  # and the plane is the tilted one
    assert s["force_z_N"].max() > 0.1  # it cut
    text = (out / "specimen.data").read_text().split("Atoms # bpm/sphere")[1].split("Bonds")[0]
    init = {int(p[0]): np.array([float(v) for v in p[5:8]]) for p in (ln.split() for ln in text.strip().splitlines())
            if p[2] == "2"}
    rows = [ln.split() for ln in (out / "vel.dump").read_text().split("ITEM: ATOMS id x y z vx vy vz")[1].strip().splitlines()]
    ids = np.array([int(r[0]) for r in rows])
    pos = np.array([[float(v) for v in r[1:4]] for r in rows])
    vel = np.array([[float(v) for v in r[4:7]] for r in rows])
    dt = spec["derived"]["dt_s"]
    t_end = spec["derived"]["expected_steps"] * dt
    e, w, sense = cut["ecc"], cut["omega"], cut.get("sense", 1.0)
    oz, vo = sense * e * math.sin(w * t_end), sense * e * w * math.cos(w * t_end)
    c_end = c0 + np.array([cut["V"] * t_end + e * (math.cos(w * t_end) - 1.0), 0.0, 0.0]) + oz * np.array([0.0, -a[2], a[1]])
    v_c = np.array([cut["V"] - e * w * math.sin(w * t_end), 0.0, 0.0]) + vo * np.array([0.0, -a[2], a[1]])
    rel0 = np.array([init[int(i)] - c0 for i in ids])
    rel = pos - c_end
    assert np.abs(np.linalg.norm(rel, axis=1) - np.linalg.norm(rel0, axis=1)).max() < 1e-9
    assert np.abs(rel @ a - rel0 @ a).max() < 1e-9  # the axis coordinate of every sphere is kept: spin about a
    assert np.abs(rel - rel0).max() > 1e-4  # and the disc did turn
    v_rigid = v_c + cut["spin_rate"] * np.cross(a, rel)
    assert np.abs(vel - v_rigid).max() < 1e-6 * np.abs(v_rigid).max()
    got = cutter_world_points(rel0, cut, t_end)
    assert np.abs(got - pos).max() < 1e-9


def test_debris_removal_deletes_loose_grains_and_keeps_the_bond_count(tmp_path, cache):
    """run.debris_removal_every (real engine): the straight cut of tiny_cut runs in chunks of 2000 steps and after each
    the rock grains without bonds are deleted. Every deletion is in the log, the final dump holds no loose grain and
    counts the same bonds as the series (the deck rebuilds the ghost atoms after the last delete_atoms: without it, 2
    ranks lost 59 of 1407 bonds in the final dump of a trial), and parse books the deleted grains as damage 1."""
    from deckgen.parse.dump import iter_frames
    from deckgen.results import parse_run

    case = load_case(CASES / "tiny_cut.yaml", overrides={
        "kinematics": {"mode": "linear", "eccentricity_mm": 0.0, "frequency_hz": 0.0},
        "run": {"debris_removal_every": 2000}})
    out = tmp_path / "debris"
    spec = render_case(case, out, cache=cache, progress=False)
    steps = spec["derived"]["expected_steps"]
    assert steps % 2000 == 0 and spec["derived"]["debris_removal_every"] == 2000
    deck = (out / "in.deck").read_text()
    assert len(re.findall(r"^delete_atoms ", deck, re.M)) == 1 and f"variable debris_chunks      index {steps // 2000} " in deck
    run_deck(out, expected_steps=steps, progress=False)
    log = (out / "log.lammps").read_text()
    deleted = [int(n) for n in re.findall(r"^Deleted (\d+) atoms", log, re.M)]
    assert len(deleted) == steps // 2000
    total = int(re.search(r"^deckgen debris deleted: (\d+) grains", log, re.M).group(1))
    assert total == sum(deleted) > 0
    first = next(iter_frames(out / "atoms.dump.gz", ["type", "c_nb"])).data
    final = list(iter_frames(out / "final.dump.gz", ["type", "c_nb"]))[-1].data
    assert len(first) - len(final) == total
    assert ((final["type"] == 1) & (final["c_nb"] == 0)).sum() == 0
    s = read_series(out / "series.txt")
    assert final["c_nb"].sum() / 2 == s["bonds"].iloc[-1] < spec["derived"]["n_bonds"]
    summary = parse_run(out, tmp_path / "parsed")
    assert summary["run_completed"] and summary["n_grains_missing_final"] == 0
    assert summary["n_grains_deleted_debris"] == total
    assert f"{total} grain(s) deleted as loose debris" in summary["notes"]
