"""cutter.surface: smooth — the cone disc as a moving LAMMPS region wall instead of a shell of spheres."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from deckgen.deck import render_case
from deckgen.parse.series import read_series
from deckgen.runner import engine_available, run_deck
from deckgen.spec import SpecError, load_case, resolved_dict

ROOT = Path(__file__).resolve().parents[1]
CASES = ROOT / "tests" / "data" / "cases"

# the tiny oscillating cut with a small cone disc (12/8 mm, rake 30, clearance 9 deg, sharp), frictionless
CONE = {"kind": "cone_disc", "diameter_mm": 12.0, "small_diameter_mm": 8.0, "rake_angle_deg": 30.0,
        "clearance_angle_deg": 9.0, "tip_radius_mm": 0.0, "surface": "smooth"}
SMOOTH = {"cutter": CONE, "contact": {"cutter_friction": 0.0}, "kinematics": {"spin": "shaft"}}


def _case(**over):
    o = {k: dict(v) for k, v in SMOOTH.items()}
    for k, v in over.items():
        o.setdefault(k, {}).update(v)
    return load_case(CASES / "tiny_cut.yaml", overrides=o)


@pytest.mark.parametrize("over, msg", [
    ({"cutter": {"kind": "v_disc"}}, "needs kind cone_disc"),
    ({"cutter": {"tip_radius_mm": 0.2}}, "needs kind cone_disc with tip_radius_mm 0"),
    ({"contact": {"cutter_friction": 0.3}}, "cannot also spin with friction"),
    ({"cutter": {"wear_flat_mm": 0.5}}, "no worn land"),
])
def test_smooth_surface_refuses_what_a_region_cone_cannot_be(over, msg):
    with pytest.raises(SpecError, match=msg):
        _case(**over)


def test_smooth_surface_is_lammps_only():
    o = {k: dict(v) for k, v in SMOOTH.items()}
    o["engine"] = "liggghts"
    with pytest.raises(SpecError, match="LIGGGHTS decks use the STL mesh itself"):
        load_case(CASES / "tiny_cut.yaml", overrides=o)


def test_smooth_surface_allows_friction_when_the_cone_does_not_spin_or_is_upright():
    assert _case(contact={"cutter_friction": 0.3}, kinematics={"spin": "none"}).cutter.surface == "smooth"
    assert _case(contact={"cutter_friction": 0.3}, cutter={"clearance_angle_deg": 0.0}).cutter.surface == "smooth"


def test_shell_default_is_left_out_of_the_resolved_case():
    shell = load_case(CASES / "tiny_cut.yaml")
    assert "surface" not in resolved_dict(shell)["cutter"]
    assert resolved_dict(_case())["cutter"]["surface"] == "smooth"


def test_smooth_deck_has_a_region_cone_and_no_shell(tmp_path):
    out = tmp_path / "d"
    spec = render_case(_case(), out, cache=tmp_path / "cache", progress=False)
    d = spec["derived"]
    assert d["n_shell"] == 0
    cone = d["smooth_cone"]
    assert cone["cone_r_lo"] == pytest.approx(6e-3, rel=1e-9)
    assert cone["cone_r_hi"] == pytest.approx(4e-3, rel=1e-9)
    assert cone["cone_h"] == pytest.approx(2e-3 * math.tan(math.radians(60.0)), rel=1e-9)  # (R - r) tan(90 - rake)
    assert cone["cone_tilt"] == pytest.approx(-math.radians(9.0), rel=1e-9)  # the clearance tilt, rim toward -y
    deck = (out / "in.deck").read_text()
    assert "region          disc cone y ${xc0} ${zc0} ${cone_r_lo} ${cone_r_hi} ${yc0} ${cone_y1} side out" in deck
    assert "rotate v_rot ${xc0} ${yc0} ${zc0} 1 0 0" in deck
    assert "wall/gran/region" in deck and "fix             move cutter" not in deck
    atoms = (out / "specimen.data").read_text().split("Atoms # bpm/sphere")[1].split("Bonds")[0]
    assert {ln.split()[2] for ln in atoms.strip().splitlines()} == {"1"}  # no shell sphere (type 2)
    # upright: the region turns with the spin about y
    spec0 = render_case(_case(cutter={"clearance_angle_deg": 0.0}), tmp_path / "u", cache=tmp_path / "cache",
                        progress=False)
    assert "cone_tilt" not in spec0["derived"]["smooth_cone"]
    assert "rotate v_rot ${xc0} ${yc0} ${zc0} 0 1 0" in (tmp_path / "u" / "in.deck").read_text()


def test_smooth_cone_narrower_than_two_grain_diameters_is_refused(tmp_path):
    with pytest.raises(SpecError, match="less than two grain diameters"):  # 3 mm < 4 x 0.9 mm
        render_case(_case(cutter={"small_diameter_mm": 6.0}), tmp_path / "d", cache=tmp_path / "cache", progress=False)


@pytest.mark.engine
@pytest.mark.skipif(not engine_available(), reason="no LAMMPS binary (run `make setup`)")
def test_frictionless_smooth_cone_exerts_no_torque_about_its_axis(tmp_path):
    """Without friction every force of a surface of revolution is normal to it, so its line passes through the
    axis (cone face, rim) or runs parallel to it (flat faces): the torque about the disc's own axis is zero while
    the cut loads it. Checks the contact points and forces the deck reads from fix wall/gran/region."""
    out = tmp_path / "run"
    spec = render_case(_case(), out, cache=tmp_path / "cache", progress=False)
    run_deck(out, expected_steps=spec["derived"]["expected_steps"], progress=False)
    s = read_series(out / "series.txt").drop_duplicates("step", keep="last")
    alpha = spec["derived"]["smooth_cone"]["cone_tilt"]
    a = np.array([0.0, math.cos(alpha), math.sin(alpha)])
    F = s[["force_x_N", "force_y_N", "force_z_N"]].to_numpy()
    T = s[["torque_x_Nm", "torque_y_Nm", "torque_z_Nm"]].to_numpy()
    R = spec["derived"]["smooth_cone"]["cone_r_lo"]
    Fmag = np.linalg.norm(F, axis=1)
    assert F[:, 2].max() > 0.1  # it cut: the rock pushes the disc up
    print(f"rows in contact {(Fmag > 0).sum()} of {len(Fmag)}; max |F| {Fmag.max():.4g} N; "
          f"max |T.a| {np.abs(T @ a).max():.3g} N m; max |T| {np.abs(T).max():.3g} N m; R |F|max {R * Fmag.max():.3g} N m")
    assert (Fmag > 0).sum() >= 10
    assert np.abs(T @ a).max() < 1e-6 * R * Fmag.max()  # no torque about the axis
    assert np.abs(T).max() > 0.05 * R * Fmag.max()  # while the torque about other axes is not zero
