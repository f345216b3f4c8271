"""Deck rendering: filters keep case strings out of decks; golden decks; resolved spec beside the deck."""

from __future__ import annotations

import hashlib
import json
import math
from pathlib import Path

import pytest

from deckgen.render import DeckError, f_comment, f_num, f_path, f_tok, render
from helpers import load_script

ROOT = Path(__file__).resolve().parents[1]
GOLDEN = ROOT / "tests" / "data" / "golden"


def _regen():
    return load_script(GOLDEN / "regenerate.py")


def _render_tiny(tmp_path, name: str, edit) -> tuple:
    """Render the tiny case ``name`` (tests/data/cases) after ``edit(data)`` changes its YAML data, against the
    committed packing fixture (no engine). Returns (case, spec.json content); the deck is in ``tmp_path / "run"``."""
    import yaml

    from deckgen.deck import render_case
    from deckgen.spec import load_case

    data = yaml.safe_load((ROOT / "tests" / "data" / "cases" / f"{name}.yaml").read_text())
    edit(data)
    (tmp_path / f"{name}.yaml").write_text(yaml.safe_dump(data))
    case = load_case(tmp_path / f"{name}.yaml")
    _regen().install_fixture(case, name, tmp_path / "cache")
    return case, render_case(case, tmp_path / "run", cache=tmp_path / "cache", progress=False, command=["false"])


@pytest.mark.parametrize("bad", [float("nan"), float("inf"), "1; shell ls", True, None, [1]])
def test_num_filter_rejects_non_numbers(bad):
    with pytest.raises(DeckError):
        f_num(bad)


def test_num_filter_formats():
    assert f_num(2650) == "2650"
    assert f_num(1.0e-8) == "1e-08"
    assert f_num(math.pi) == "3.141592654"


@pytest.mark.parametrize("bad", ["a b", "x;shell rm", "$(v_x)", "${x}", "a\nshell ls", "../x", "", "\"q\"", "a&b"])
def test_token_filter_rejects_injection(bad):
    with pytest.raises(DeckError):
        f_tok(bad)


def test_path_and_comment_filters():
    assert f_path("specimen.data") == "specimen.data"
    for bad in ["/etc/passwd", "../up.data", "a b.data"]:
        with pytest.raises(DeckError):
            f_path(bad)
    with pytest.raises(DeckError):
        f_comment("text $(shell) here")
    with pytest.raises(DeckError):
        f_comment("two\nlines")


def test_strict_undefined():
    import jinja2

    with pytest.raises(jinja2.UndefinedError):
        render("lammps/ucs.lmp.j2", {"version": "0.1.0"})


def _assert_same_tree(got, want, where="spec"):
    """Equal nested JSON values; floats to within 1e-12 relative (a few ulp), everything else exactly."""
    if isinstance(want, dict):
        assert isinstance(got, dict) and set(got) == set(want), f"{where}: keys differ"
        for k in want:
            _assert_same_tree(got[k], want[k], f"{where}.{k}")
    elif isinstance(want, list):
        assert isinstance(got, list) and len(got) == len(want), f"{where}: lengths differ"
        for i, (g, w) in enumerate(zip(got, want)):
            _assert_same_tree(g, w, f"{where}[{i}]")
    elif isinstance(want, float) and not isinstance(got, bool) and isinstance(got, (int, float)):
        assert got == pytest.approx(want, rel=1e-12, abs=0.0), where
    else:
        assert got == want, where


def test_same_tree_tolerates_ulps_not_changes():
    _assert_same_tree({"a": [1.0, {"b": 0.41194893095965224}], "c": "x"}, {"a": [1.0, {"b": 0.4119489309596522}], "c": "x"})
    for bad in ({"a": [1.0, {"b": 0.41194893}], "c": "x"}, {"a": [1.0, {"b": 0.4119489309596522}], "c": "y"},
                {"a": [1.0], "c": "x"}):
        with pytest.raises(AssertionError):
            _assert_same_tree(bad, {"a": [1.0, {"b": 0.4119489309596522}], "c": "x"})


@pytest.mark.parametrize("name", ["tiny_ucs", "tiny_bts", "tiny_cut", "tiny_rotary"])
def test_golden_deck(tmp_path, name):
    """Rendering the tiny case against its committed packing reproduces the committed deck exactly.

    After an intentional change: python tests/data/golden/regenerate.py, and review the diff.
    """
    out = tmp_path / "run"
    _regen().render_golden(name, out, tmp_path / "cache")
    expected = (GOLDEN / name / "in.deck").read_text()
    got = (out / "in.deck").read_text()
    assert got == expected
    # the deck is byte-exact; the spec's derived floats may differ in the last bit between machines (numpy picks its
    # vector loops by instruction set): on an X86_V3 machine without AVX-512, gamma_n came out 0.41194893095965224
    # against the committed 0.4119489309596522, with the same numpy 2.4.6
    _assert_same_tree(json.loads((out / "spec.json").read_text()), json.loads((GOLDEN / name / "spec.json").read_text()))
    # relative paths only, and every file the deck reads exists in the run folder
    assert "/tmp" not in got and str(ROOT) not in got
    assert (out / "specimen.data").is_file()
    spec = json.loads((out / "spec.json").read_text())
    assert spec["case"]["name"] == name
    assert spec["derived"]["dt_s"] > 0
    # the parameters are a commented variable block at the top
    lines = [ln for ln in got.splitlines() if ln.startswith("variable ") and " index " in ln]
    assert len(lines) >= 14 and all("#" in ln and "[" in ln for ln in lines)


def test_golden_cut_geometry(tmp_path):
    out = tmp_path / "run"
    _regen().render_golden("tiny_cut", out, tmp_path / "cache")
    spec = json.loads((out / "spec.json").read_text())
    d = spec["derived"]
    # disc of 12 mm: starts with its bottom at block top - penetration, clear of the block front
    R = d["cutter"]["radius"]
    assert R == pytest.approx(6e-3, rel=1e-3)
    assert d["cutter"]["zc0"] - R == pytest.approx(8e-3 - 1.5e-3, abs=1e-9)
    half_chord = math.sqrt(R**2 - (R - 1.5e-3) ** 2)
    assert d["cutter"]["xc0"] + half_chord == pytest.approx(-1e-3, abs=1e-9)  # start_clearance_mm 1.0
    assert d["cutter"]["spin_rate"] == pytest.approx(2.0 / R)  # rolling: v / R
    # shell spheres sit on the STL offset inward by their radius

    n_shell = d["n_shell"]
    lines = (out / "specimen.data").read_text().split("Atoms # bpm/sphere")[1].split("Bonds")[0].strip().splitlines()
    shell = [ln.split() for ln in lines if ln.split()[2] == "2"]
    assert len(shell) == n_shell > 300
    import numpy as np

    from deckgen.geometry import v_disc

    # distance of each shell centre to the true cutter profile (rho, a) = (sqrt(x^2 + z^2), y)
    pts = np.array([[float(v) for v in s[5:8]] for s in shell]) - [d["cutter"]["xc0"], d["cutter"]["yc0"], d["cutter"]["zc0"]]
    q = np.stack([np.hypot(pts[:, 0], pts[:, 2]), pts[:, 1]], axis=1)
    prof = v_disc(12e-3, 60.0, 0.3e-3, 4e-3)
    a, b = prof, np.roll(prof, -1, axis=0)
    ab = b - a
    t = np.clip(((q[:, None, :] - a) * ab).sum(-1) / np.maximum((ab * ab).sum(-1), 1e-30), 0, 1)
    dist = np.linalg.norm(q[:, None, :] - (a + t[..., None] * ab), axis=-1).min(axis=1)
    assert np.allclose(dist, d["shell_radius_m"], atol=0.01e-3), (dist.min(), dist.max())


def test_specimen_data_is_deterministic(tmp_path):
    """Same case, same packing -> byte-identical bonded data file."""
    regen = _regen()
    digests = []
    for k in range(2):
        out = tmp_path / f"run{k}"
        regen.render_golden("tiny_ucs", out, tmp_path / f"cache{k}")
        digests.append(hashlib.sha256((out / "specimen.data").read_bytes()).hexdigest())
    assert digests[0] == digests[1]


def _rolling_path(R=6e-3, V=2.0, duration=5e-3):
    return dict(xc0=-4e-3, yc0=0.0, zc0=8e-3 - 1.5e-3 + R, V=V, ecc=0.0, omega=0.0, spin_rate=V / R, duration=duration,
                travel=V * duration, penetration=1.5e-3, radius=R, mode_indent=0.0, yaw_rate=0.0, rotary_radius=0.0,
                axis_x=0.0, axis_y=0.0)


def test_cutter_motion_rolls_without_slip():
    """The Python copy of the deck's motion: the lowest rim point of a rolling disc is at rest, the top moves at 2V."""
    import numpy as np

    from deckgen.deck import cutter_world_points

    path = _rolling_path()
    R, V, h = path["radius"], path["V"], 1e-9
    rel = np.array([[0.0, 0.0, -R], [0.0, 0.0, R], [R, 0.0, 0.0]])
    vel = (cutter_world_points(rel, path, h) - cutter_world_points(rel, path, -h)) / (2 * h)
    assert vel[0] == pytest.approx([0.0, 0.0, 0.0], abs=1e-5)
    assert vel[1] == pytest.approx([2 * V, 0.0, 0.0], abs=1e-5)
    assert vel[2] == pytest.approx([V, 0.0, -V], abs=1e-5)  # front point moves down as the disc rolls forward
    # after a quarter turn the front point is at the bottom, a quarter turn of travel further on
    t = (math.pi / 2) * R / V
    assert cutter_world_points(rel[2:], path, t)[0] == pytest.approx(
        [path["xc0"] + V * t, 0.0, path["zc0"] - R], abs=1e-12)


def test_near_rock_mask_matches_dense_sampling():
    """Kept shell points are exactly those that come within the margin of the block (checked at 20x the samples)."""
    import numpy as np

    from deckgen.deck import cutter_world_points, near_rock_mask

    rng = np.random.default_rng(3)
    R = 6e-3
    ang = rng.uniform(0, 2 * math.pi, 3000)
    rel = np.column_stack([R * np.cos(ang), rng.uniform(-1e-3, 1e-3, 3000), R * np.sin(ang)])
    path = _rolling_path(R=R)
    lo, hi = np.array([0.0, -5e-3, 0.0]), np.array([20e-3, 5e-3, 8e-3])
    margin = 1e-3
    keep = near_rock_mask(rel, path, lo, hi, margin)
    dmin = np.full(len(rel), np.inf)
    for t in np.linspace(0, path["duration"], 4001):
        p = cutter_world_points(rel, path, float(t))
        dmin = np.minimum(dmin, np.linalg.norm(np.maximum(np.maximum(lo - p, p - hi), 0.0), axis=1))
    assert not keep[dmin > margin * 1.01].any()
    assert keep[dmin < margin * 0.99].all()
    # a 12 mm disc rolling 10 mm (1.7 rad) at 1.5 mm depth keeps a third of its rim (measured 0.36), not all of it
    assert 0.25 < keep.mean() < 0.5, keep.mean()


def test_near_rock_shell_keeps_the_contact_band(tmp_path):
    """tiny_cut with shell_coverage near_rock: fewer spheres, all of them on the lower part of the rolling disc."""
    import numpy as np

    _, spec = _render_tiny(tmp_path, "tiny_cut", lambda data: data["cutter"].update(shell_coverage="near_rock",
                                                                                   shell_margin_mm=1.0))
    d = spec["derived"]
    assert d["n_shell"] < 0.9 * d["n_shell_full_cover"]
    lines = (tmp_path / "run" / "specimen.data").read_text().split("Atoms # bpm/sphere")[1].split("Bonds")[0].strip().splitlines()
    xyz = np.array([[float(v) for v in ln.split()[5:8]] for ln in lines if ln.split()[2] == "2"])
    assert len(xyz) == d["n_shell"]
    # where the kept spheres are at the end of the cut: they reach the disc's lowest level there (the cut floor)
    from deckgen.deck import cutter_world_points

    cut = d["cutter"]
    c0 = np.array([cut["xc0"], cut["yc0"], cut["zc0"]])
    end = cutter_world_points(xyz - c0, cut, cut["duration"])
    zc_end = cut["zc0"] + cut["ecc"] * math.sin(cut["omega"] * cut["duration"])
    xc_end = cut["xc0"] + cut["V"] * cut["duration"] + cut["ecc"] * (math.cos(cut["omega"] * cut["duration"]) - 1)
    low = np.argmin(end[:, 2])
    assert end[low, 2] == pytest.approx(zc_end - cut["radius"] + d["shell_radius_m"], abs=0.2e-3)
    assert xc_end - 0.5e-3 < end[low, 0] < xc_end + 1.5e-3  # just ahead of the centre: the front part is in the block
    # and none is further than the margin (plus the sphere radius) from the block at every time
    assert d["shell_margin_m"] == pytest.approx(1e-3)


def test_shaft_sense_mirrors_the_eccentric_circle_and_the_spin(tmp_path):
    """kinematics.shaft_sense: forward (default) slides the disc's lowest point forward at V + e w + w R at the bottom of
    the circle; backward mirrors the circle (z = -e sin w t) and the spin, so that point moves at V - e w - w R."""
    import numpy as np

    from deckgen.deck import cutter_path, cutter_world_points
    from deckgen.liggghts import render_liggghts_cut
    from deckgen.spec import Case, SpecError, load_case

    base = load_case(ROOT / "cases/odc/reduced/odc_red_s16.yaml")
    R = base.cutter.diameter_mm * 1e-3 / 2
    k = base.kinematics
    V, e, w = k.speed_m_s, k.eccentricity_mm * 1e-3, 2 * math.pi * k.frequency_hz
    h = 1e-9
    for sense, z_sign, rim in (("forward", 1.0, V + e * w + w * R), ("backward", -1.0, V - e * w - w * R)):
        case = base.model_copy(update={"kinematics": k.model_copy(update={"shaft_sense": sense})})
        path = cutter_path(case, R)
        t_bottom = (0.75 if sense == "forward" else 0.25) * 2 * math.pi / w  # the centre at the bottom of its circle
        centre = cutter_world_points(np.zeros((1, 3)), path, t_bottom)[0]
        assert centre[2] == pytest.approx(path["zc0"] - e, abs=1e-12)
        assert cutter_world_points(np.zeros((1, 3)), path, 0.25 * 2 * math.pi / w)[0][2] == pytest.approx(
            path["zc0"] + z_sign * e, abs=1e-12)
        # the point of the disc that is lowest at that moment (offset rotated back by the spin angle)
        th = path["spin_rate"] * t_bottom
        rel = np.array([[R * math.sin(th), 0.0, -R * math.cos(th)]])
        assert cutter_world_points(rel, path, t_bottom)[0][2] == pytest.approx(path["zc0"] - e - R, abs=1e-9)
        vel = (cutter_world_points(rel, path, t_bottom + h) - cutter_world_points(rel, path, t_bottom - h)) / (2 * h)
        assert vel[0][0] == pytest.approx(rim, rel=1e-5) and vel[0][2] == pytest.approx(0.0, abs=1e-4)
        if sense == "backward":
            with pytest.raises(SpecError, match="shaft_sense backward is rendered for LAMMPS only"):
                render_liggghts_cut(case, tmp_path / "lig", bed="settle")
    with pytest.raises(ValueError, match="only mode oscillation has a shaft"):
        Case.model_validate({**base.model_dump(), "kinematics": {"mode": "linear", "speed_m_s": 2, "penetration_mm": 4,
                                                                 "travel_mm": 12, "shaft_sense": "backward"}})


def test_tilted_disc_path_carries_its_axis_tilt_and_refuses_what_is_not_rendered():
    """cutter_path: a tilted disc that spins or orbits carries axis_tilt (the axis angle from y about x); an untilted
    one, or a tilted disc that neither spins nor orbits, does not (their decks and spec.json stay as before); a tilted
    disc spinning on a rotary path is refused in one line."""
    import numpy as np

    from deckgen.deck import cutter_path
    from deckgen.spec import SpecError, load_case

    case = load_case(ROOT / "cases/odc/reduced/odc_red_s16.yaml")  # cone, clearance 9 deg, spin shaft, e 1 mm
    R = 0.01
    c9 = math.radians(9.0)
    p = cutter_path(case, R, axis=np.array([0.0, math.cos(c9), -math.sin(c9)]))
    assert p["axis_tilt"] == pytest.approx(-c9, abs=1e-15)
    assert "axis_tilt" not in cutter_path(case, R, axis=np.array([0.0, 1.0, 0.0]))
    assert "axis_tilt" not in cutter_path(case, R)
    straight = load_case(ROOT / "cases/odc/reduced/odc_red_s10.yaml")  # no oscillation, no spin
    assert "axis_tilt" not in cutter_path(straight, R, axis=np.array([0.0, math.cos(c9), -math.sin(c9)]))
    rot = load_case(ROOT / "tests/data/cases/tiny_rotary.yaml")
    with pytest.raises(SpecError, match="tilted disc .* spins in rotary is not rendered"):
        cutter_path(rot, 0.006, axis=np.array([0.0, math.cos(0.1), math.sin(0.1)]))
    with pytest.raises(SpecError, match="leaves the y-z plane"):
        cutter_path(case, R, axis=np.array([0.1, 0.99, 0.0]))


def test_orbit_lift_ratio_places_the_orbit_between_start_and_bottom():
    """kinematics.orbit_lift_ratio raises the centre path by ratio * e cos(tilt): 1 is penetration_at orbit_bottom, 0 the
    start; it is refused outside oscillation, beside penetration_at orbit_bottom and outside [0, 1]."""
    import numpy as np
    from pydantic import ValidationError

    from deckgen.deck import cutter_path
    from deckgen.spec import Case, load_case

    base = load_case(ROOT / "cases/odc/reduced/odc_red_s11.yaml")  # e 4 mm, clearance 9 deg
    k = base.kinematics
    assert "orbit_lift_ratio" not in base.model_dump(mode="json")["kinematics"]

    def with_kin(**upd):
        return base.model_copy(update={"kinematics": k.model_copy(update=upd)})

    c9 = math.radians(9.0)
    ax = np.array([0.0, math.cos(c9), -math.sin(c9)])
    z = {r: cutter_path(with_kin(orbit_lift_ratio=r), 0.01, axis=ax)["zc0"] for r in (0.0, 0.56, 1.0)}
    z_bottom = cutter_path(with_kin(penetration_at="orbit_bottom"), 0.01, axis=ax)["zc0"]
    z_start = cutter_path(base, 0.01, axis=ax)["zc0"]
    e = k.eccentricity_mm * 1e-3
    assert z[0.0] == z_start and z[1.0] == pytest.approx(z_bottom, abs=1e-15)
    assert z[0.56] - z_start == pytest.approx(0.56 * e * math.cos(c9), rel=1e-12)
    assert with_kin(orbit_lift_ratio=0.56).model_dump(mode="json")["kinematics"]["orbit_lift_ratio"] == 0.56
    data = base.model_dump()
    for kin, msg in [({**data["kinematics"], "penetration_at": "orbit_bottom", "orbit_lift_ratio": 0.5}, "set one of them"),
                     ({"mode": "linear", "speed_m_s": 2, "penetration_mm": 4, "travel_mm": 12, "orbit_lift_ratio": 0.5},
                      "only mode oscillation has an orbit"),
                     ({**data["kinematics"], "orbit_lift_ratio": 1.5}, "less than or equal to 1")]:
        with pytest.raises(ValidationError, match=msg):
            Case.model_validate({**data, "kinematics": kin})


def test_penetration_at_orbit_bottom_lifts_the_orbit_by_e():
    """kinematics.penetration_at: orbit_bottom raises the centre path by e cos(tilt), so the deepest point of the
    orbit (not the start) is p deep; the default (start) leaves the path as before and out of resolved cases."""
    import numpy as np

    from deckgen.deck import cutter_path, cutter_world_points
    from deckgen.spec import Case, load_case

    base = load_case(ROOT / "cases/odc/reduced/odc_red_s11.yaml")  # e 4 mm, clearance 9 deg
    k = base.kinematics
    assert "penetration_at" not in base.model_dump(mode="json")["kinematics"]
    low = base.model_copy(update={"kinematics": k.model_copy(update={"penetration_at": "orbit_bottom"})})
    c9 = math.radians(9.0)
    ax = np.array([0.0, math.cos(c9), -math.sin(c9)])
    p0, p1 = cutter_path(base, 0.01, axis=ax), cutter_path(low, 0.01, axis=ax)
    e = k.eccentricity_mm * 1e-3
    assert p1["zc0"] - p0["zc0"] == pytest.approx(e * math.cos(c9), rel=1e-12)
    w = p1["omega"]
    z_bottom = min(cutter_world_points(np.zeros((1, 3)), p1, t)[0][2] for t in np.linspace(0, 2 * math.pi / w, 721))
    assert z_bottom == pytest.approx(p0["zc0"], abs=1e-9)  # the centre's lowest point is the old start height
    with pytest.raises(ValueError, match="only mode oscillation has an orbit"):
        Case.model_validate({**base.model_dump(), "kinematics": {"mode": "linear", "speed_m_s": 2, "penetration_mm": 4,
                                                                 "travel_mm": 12, "penetration_at": "orbit_bottom"}})


@pytest.mark.parametrize("name, kinematics", [
    ("tiny_cut", None),  # eccentric oscillation, untilted
    ("tiny_cut", {"mode": "linear", "speed_m_s": 2, "penetration_mm": 1.5, "travel_mm": 3, "spin": "rolling"}),
    ("tiny_rotary", None),
])
def test_every_cutter_path_moves_the_shell_in_all_three_directions(tmp_path, name, kinematics):
    """``fix move variable`` integrates a component whose displacement and velocity are both NULL from the forces on
    each atom (as fix nve would): a NULL y let each shell sphere of the straight and eccentric paths drift sideways
    under the rock's push (session 34). Every branch of the deck now gives all six variables."""
    import re

    _render_tiny(tmp_path, name, lambda data: data.update(kinematics=kinematics or data["kinematics"]))
    moves = re.findall(r"^fix\s+move\s+cutter\s+move\s+variable\s+(.*)$", (tmp_path / "run" / "in.deck").read_text(), re.M)
    assert moves == ["v_dx v_dy v_dz v_vx v_vy v_vz"]
