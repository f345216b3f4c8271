"""packing.fine_zone: a band of finer grains along the cut of a LAMMPS cutting block (session 39). Checks that the
field is validated at the edge, leaves every other packing (key, insertion) as it was, places the band's radii in the
band, and that the engine packs such a block with the band still fine and in place."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from deckgen.packing import fine_zone_box, insert_grains, packing_inputs, packing_key, specimen_region
from deckgen.spec import SpecError, load_case

ROOT = Path(__file__).resolve().parents[1]
TINY_CUT = ROOT / "tests" / "data" / "cases" / "tiny_cut.yaml"
ZONE = {"radius_min_mm": 0.3, "radius_max_mm": 0.45, "half_width_mm": 3.0, "depth_mm": 3.0}


def _tiny(**zone):
    """tiny_cut (block 16 x 10 x 8 mm, grains r 0.6-0.9 mm) with a band |y| <= 3 mm, 3 mm deep, of r 0.3-0.45 mm
    grains and a shell fine enough for them."""
    return load_case(TINY_CUT, {"packing": {"fine_zone": {**ZONE, **zone}}, "cutter": {"shell_radius_mm": 0.14}})


def test_a_case_without_a_band_keeps_its_packing_key_and_grains():
    case = load_case(TINY_CUT)
    assert "fine_zone" not in packing_inputs(case)["packing"]
    assert "fine_zone" not in case.model_dump(mode="json")["packing"]
    # the key and the insertion of the plain tiny_cut as they were before the band existed (commit 0376bfe)
    assert packing_key(case) == "bb472c0b1fd76abf"
    x, r = insert_grains(case)
    assert len(r) == 454 and r.min() >= 0.6e-3 and r.max() <= 0.9e-3
    assert x[:2].round(9).tolist() == [[0.010936374, -0.000599274, 0.002086057], [0.005710892, -0.000178697, 0.001574844]]
    assert fine_zone_box(case) is None


def test_the_band_holds_the_fine_grains_and_fills_its_volume():
    case = _tiny()
    assert packing_key(case) != packing_key(load_case(TINY_CUT))
    box = fine_zone_box(case)
    assert box.ravel().tolist() == pytest.approx([0.0, 0.016, -0.003, 0.003, 0.005, 0.008])
    x, r = insert_grains(case)
    fine = r <= 0.45e-3
    inside = np.all((x >= box[:, 0]) & (x <= box[:, 1]), axis=1)
    assert (fine == inside).all()  # fine centres in the band, coarse centres outside it
    assert r[fine].min() >= 0.3e-3 and r[~fine].min() >= 0.6e-3
    # each part holds solid_fraction_target of its volume (to one grain)
    v_band = float(np.prod(box[:, 1] - box[:, 0]))
    v = specimen_region(case).volume_m3
    vol = 4.0 / 3.0 * np.pi * r**3
    assert vol[fine].sum() / v_band == pytest.approx(0.64, abs=4.0 / 3.0 * np.pi * 0.45e-3**3 / v_band)
    assert vol[~fine].sum() / (v - v_band) == pytest.approx(0.64, abs=4.0 / 3.0 * np.pi * 0.9e-3**3 / (v - v_band))
    assert fine.sum() > 2 * (~fine).sum()


@pytest.mark.parametrize("change, message", [
    ({"fine_zone": {"radius_max_mm": 0.7}}, r"packing\.fine_zone\.radius_max_mm: 0\.7 mm is more than the block's "
     r"smallest grain radius 0\.6 mm"),
    ({"fine_zone": {"depth_mm": 9}}, r"packing\.fine_zone\.depth_mm: 9 mm is more than the block height 8 mm"),
    ({"fine_zone": {"centre_y_mm": 3}}, r"packing\.fine_zone: the band \|y - 3\| <= 3 mm leaves the block"),
    ({"fine_zone": {"depth_mm": 1.5}}, r"packing\.fine_zone: the band is less than 4 of its grain radii thick"),
    ({"fine_zone": {"radius_min_mm": 0.5}}, r"radius_max_mm must be >= radius_min_mm"),
])
def test_a_band_that_cannot_be_packed_is_refused_with_the_field_and_the_fix(change, message):
    with pytest.raises(SpecError, match=message):
        load_case(TINY_CUT, {"packing": {"fine_zone": {**ZONE, **change["fine_zone"]}},
                             "cutter": {"shell_radius_mm": 0.14}})


def test_the_band_is_a_lammps_cutting_block_feature_and_sets_the_shell_limit():
    with pytest.raises(SpecError, match=r"packing\.fine_zone: .*LAMMPS cutting blocks only"):
        load_case(ROOT / "tests" / "data" / "cases" / "tiny_ucs.yaml", {"packing": {"fine_zone": ZONE}})
    # tiny_cut's shell (r 0.25 mm) suits its r 0.6-0.9 mm grains but not the band's r 0.3-0.45 mm
    with pytest.raises(SpecError, match=r"cutter\.shell_radius_mm: 0\.25 mm .*about 0\.147 mm"):
        load_case(TINY_CUT, {"packing": {"fine_zone": ZONE}})


@pytest.mark.engine
def test_the_engine_packs_a_block_with_its_band_fine_and_in_place(tmp_path):
    from deckgen.deck import render_case
    from deckgen.packing import ensure_packing, load_packing
    from deckgen.runner import engine_available

    if not engine_available():  # pragma: no cover
        pytest.skip("no LAMMPS binary (run `make setup`)")
    case = _tiny()
    atoms, info = load_packing(ensure_packing(case, tmp_path / "cache", progress=False))
    s = info["stats"]
    assert 0.9 < s["radius_scale"] < 1.0 and 0.55 < s["solid_fraction"] < 0.64
    r = atoms.radius / s["radius_scale"]
    fine = r <= 0.45e-3 + 1e-9
    x0, r0 = insert_grains(case)
    assert fine.sum() == (r0 <= 0.45e-3).sum() and len(r) == len(r0)
    # growth and deflation let the band's edge mix over about a coarse grain: on this block 10 % of the fine grains end
    # more than a fine radius outside the band, 4.6 % more than a fine diameter, none more than a coarse diameter;
    # no coarse grain gets a coarse radius deep into it, and its core (1 mm in from the sides and the bottom) is
    # all fine grains
    box = fine_zone_box(case)
    out = np.maximum(box[:, 0] - atoms.x, atoms.x - box[:, 1]).max(axis=1)  # > 0: outside the band by that much
    assert (out[fine] > 1.8e-3).sum() == 0 and (out[fine] > 0.9e-3).mean() < 0.1
    assert out[~fine].min() > -0.9e-3
    core = np.all((atoms.x >= box[:, 0] + [0, 1e-3, 1e-3]) & (atoms.x <= box[:, 1] - [0, 1e-3, 0]), axis=1)
    assert core.sum() > 300 and fine[core].all()
    # the deck's time step follows the band's smallest grain
    spec = render_case(case, tmp_path / "run", cache=tmp_path / "cache", progress=False)
    coarse = render_case(load_case(TINY_CUT, {"cutter": {"shell_radius_mm": 0.14}}), tmp_path / "run0",
                         cache=tmp_path / "cache", progress=False)
    assert spec["derived"]["dt_s"] < 0.7 * coarse["derived"]["dt_s"]
