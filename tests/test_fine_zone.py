"""packing.fine_zone: a band of finer grains along the cut of a LAMMPS cutting block (session 39). Checks that the
field is validated at the edge, leaves every other packing (key, insertion) as it was, places the band's radii in the
band, and that the engine packs such a block with the band still fine and in place."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from deckgen.packing import fine_zone_box, insert_grains, packing_inputs, packing_key, specimen_region
from deckgen.spec import SpecError, load_case

ROOT = Path(__file__).resolve().parents[1]
TINY_CUT = ROOT / "tests" / "data" / "cases" / "tiny_cut.yaml"
ZONE = {"radius_min_mm": 0.3, "radius_max_mm": 0.45, "half_width_mm": 3.0, "depth_mm": 3.0}
#: tiny_cut as a linear cut on a block 14 mm wide (so that 4 mm of its r 0.6-0.9 mm grains stay on each side of the
#: band), with a shell fine enough for the band's grains
LINEAR = {"kinematics": {"mode": "linear", "eccentricity_mm": 0, "frequency_hz": 0}, "specimen": {"width_mm": 14},
          "cutter": {"shell_radius_mm": 0.14}}


def _tiny(**zone):
    """The block of :data:`LINEAR` (16 x 14 x 8 mm, grains r 0.6-0.9 mm) with a band |y| <= 3 mm, 3 mm deep, of
    r 0.3-0.45 mm grains."""
    return load_case(TINY_CUT, {**LINEAR, "packing": {"fine_zone": {**ZONE, **zone}}})


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
    assert packing_key(case) != packing_key(load_case(TINY_CUT, LINEAR))
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
    assert fine.sum() > (~fine).sum()
    # deterministic
    x2, r2 = insert_grains(case)
    assert np.array_equal(x, x2) and np.array_equal(r, r2)


@pytest.mark.parametrize("change, message", [
    ({"radius_max_mm": 0.6}, r"packing\.fine_zone\.radius_max_mm: 0\.6 mm is not below the block's smallest grain "
     r"radius 0\.6 mm"),
    ({"radius_min_mm": 0.1}, r"packing\.fine_zone\.radius_min_mm: 0\.1 mm is less than a fifth"),
    ({"depth_mm": 9}, r"packing\.fine_zone: the band leaves the block below it \(height_mm - depth_mm\) by 1 mm"),
    ({"depth_mm": 6}, r"packing\.fine_zone: the band leaves a strip of 2 mm of the block's grains below it"),
    ({"half_width_mm": 5}, r"packing\.fine_zone: the band leaves a strip of 2 mm of the block's grains on its y min side"),
    ({"centre_y_mm": 3.5}, r"packing\.fine_zone: the band \|y - 3\.5\| <= 3 mm misses the cut"),
    ({"depth_mm": 1.5}, r"packing\.fine_zone\.depth_mm: 1\.5 mm does not reach below the cut"),
    ({"half_width_mm": 0.8}, r"packing\.fine_zone\.half_width_mm: the band is 1\.6 mm thick across its 2 x "
     r"half_width_mm, less than 4 of its largest grain radii \(1\.8 mm\)"),
    ({"depth_mm": 8, "half_width_mm": 7}, r"packing\.fine_zone: the band fills the whole block"),
    ({"radius_min_mm": 0.5}, r"tiny_cut\.yaml: packing\.fine_zone: radius_max_mm must be >= radius_min_mm \(swap them\)"),
])
def test_a_band_that_cannot_be_packed_is_refused_with_the_field_and_the_fix(change, message):
    with pytest.raises(SpecError, match=message):
        _tiny(**change)


def test_the_band_is_a_lammps_linear_cut_feature_and_sets_the_shell_limit(tmp_path, capsys):
    from deckgen.cli import main

    with pytest.raises(SpecError, match=r"packing\.fine_zone: .*LAMMPS linear cuts of a cutting block only"):
        load_case(ROOT / "tests" / "data" / "cases" / "tiny_ucs.yaml", {"packing": {"fine_zone": ZONE}})
    with pytest.raises(SpecError, match=r"packing\.fine_zone: .*LAMMPS linear cuts of a cutting block only"):
        load_case(TINY_CUT, {"packing": {"fine_zone": ZONE}, "specimen": {"width_mm": 14},
                             "cutter": {"shell_radius_mm": 0.14}})  # tiny_cut oscillates
    with pytest.raises(SpecError, match=r"packing\.fine_zone: .*LAMMPS linear cuts"):
        load_case(TINY_CUT, {**LINEAR, "engine": "liggghts", "packing": {"fine_zone": ZONE}})
    # nor can --engine liggghts take a band case past the check
    case = tmp_path / "band.yaml"
    import yaml

    case.write_text(yaml.safe_dump(_tiny().model_dump(mode="json")))
    assert main(["render", str(case), "--engine", "liggghts", "--out", str(tmp_path / "run")]) == 2
    assert "--engine liggghts: Value error, packing.fine_zone: a band" in capsys.readouterr().err
    # a shell fit for r 0.6-0.9 mm grains (r 0.25 mm) is too coarse for the band's r 0.3-0.45 mm
    with pytest.raises(SpecError, match=r"cutter\.shell_radius_mm: 0\.25 mm .*about 0\.147 mm"):
        load_case(TINY_CUT, {**LINEAR, "cutter": {"shell_radius_mm": 0.25}, "packing": {"fine_zone": ZONE}})


def test_the_packing_time_step_follows_the_band():
    from deckgen.packing import pack_context

    def dt(case):
        return next(v["value"] for v in pack_context(case)["variables"] if v["name"] == "dt")

    assert dt(_tiny()) == pytest.approx(0.5 * dt(load_case(TINY_CUT, LINEAR)), rel=1e-9)  # r_min 0.3 against 0.6 mm


def test_the_case_estimate_counts_the_band_grains_and_takes_its_time_step():
    """families.estimate (index.csv, the family sizing) on the 33 mm band case against its one render (session 39:
    5681 grains, dt 1.78e-8 s, 645 800 steps) and its coarse reference without the band (2488 grains rendered)."""
    from deckgen.families import estimate

    rec = ROOT / "docs" / "families_runs" / "linear_fn_vs_p"
    band = estimate(load_case(rec / "lin_red_s100_p7p6_unrel_band.yaml").model_dump())
    coarse = estimate(load_case(rec / "lin_red_s100_p7p6_unrel_s016.yaml").model_dump())
    assert band["n_grains_est"] == pytest.approx(5681, rel=0.1) and coarse["n_grains_est"] == pytest.approx(2488, rel=0.1)
    assert band["dt_est_s"] == pytest.approx(1.78e-8, rel=0.15) and band["dt_est_s"] == pytest.approx(0.5 * coarse["dt_est_s"], rel=0.01)
    assert band["steps_est"] == pytest.approx(645_800, rel=0.15)


@pytest.mark.engine
def test_the_engine_packs_a_block_with_its_band_fine_and_in_place(tmp_path):
    """The band after packing and the deck made from it: bond types binned per size class, the rolling constants of
    the block's own grains, the time step of the band's."""
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
    # growing the radii mixes the band's edge over about a coarse grain. Measured on this block (1344 grains, 813 of
    # them fine): 19 % of the fine centres end outside the band, 10 % by more than a fine radius, 4.3 % by more than a
    # fine diameter, 0.7 % (6 grains, slipped into the coarse grains' voids, up to 3.2 mm) by more than a coarse
    # diameter; 21 coarse centres end inside it, none deeper than 0.86 mm; the core is all fine grains
    box = fine_zone_box(case)
    out = np.maximum(box[:, 0] - atoms.x, atoms.x - box[:, 1]).max(axis=1)  # > 0: outside the band by that much
    assert (out[fine] > 0.45e-3).mean() < 0.15 and (out[fine] > 0.9e-3).mean() < 0.08
    assert (out[fine] > 1.8e-3).mean() < 0.02
    assert out[~fine].min() > -1.2e-3  # no coarse grain deeper into the band than about its radius
    core = np.all((atoms.x >= box[:, 0] + [0, 1.2e-3, 1.2e-3]) & (atoms.x <= box[:, 1] - [0, 1.2e-3, 0]), axis=1)
    assert core.sum() > 200 and fine[core].all()
    # the deck: the time step follows the band's smallest grain; bond types are binned per size class, so no type
    # mixes the two sizes; the rolling stiffness and damping are the block's own grains'
    spec = render_case(case, tmp_path / "run", cache=tmp_path / "cache", progress=False)
    plain = render_case(load_case(TINY_CUT, LINEAR), tmp_path / "run0", cache=tmp_path / "cache", progress=False)
    assert spec["derived"]["dt_s"] < 0.7 * plain["derived"]["dt_s"]
    assert spec["derived"]["bond_type_max_stiffness_error"] < 1.5 * plain["derived"]["bond_type_max_stiffness_error"]

    def deck_var(run, name):
        m = re.search(rf"^variable\s+{name}\s+index\s+(\S+)", (tmp_path / run / "in.deck").read_text(), re.M)
        return float(m.group(1))

    plain_atoms = load_packing(ensure_packing(load_case(TINY_CUT, LINEAR), tmp_path / "cache", progress=False))[0]
    r_block, r_plain = atoms.radius[~fine].mean(), plain_atoms.radius.mean()
    k_expected = deck_var("run0", "k_roll") * (r_block / r_plain)  # Hertz stiffness at a fixed relative overlap ~ r
    assert deck_var("run", "k_roll") == pytest.approx(k_expected, rel=1e-3)


def test_a_band_and_its_plain_block_of_one_seed_are_independent_draws():
    """With one seed, a block with a band and the same block without one draw the same first radii (the band block's
    coarse grains are the plain block's first draws), but how many radii are drawn depends on the volume they fill,
    which the band changes, so every later draw (the band's radii, then every position) comes from a different point
    of the random stream: no inserted grain sits where one of the other does, even outside the band, and the plain
    block's grains lie as far from the band block's as a plain block of another seed's do (session 46: the band/coarse
    pairs of docs/families_runs/shell_held are two independent packings, compare.band_over_coarse_unpaired)."""
    from scipy.spatial import cKDTree

    plain, band = load_case(TINY_CUT, LINEAR), _tiny()
    other = load_case(TINY_CUT, {**LINEAR, "packing": {"seed": plain.packing.seed + 1}})
    assert plain.packing.seed == band.packing.seed
    x0, r0 = insert_grains(plain)
    x1, r1 = insert_grains(band)
    coarse = r1 > 0.45e-3
    assert [len(r0), coarse.sum()] == [635, 531] and np.array_equal(r1[coarse], r0[:531])
    outside = np.abs(x0[:, 1]) > 4e-3
    tree = cKDTree(x1)
    d, _ = tree.query(x0[outside])
    assert outside.sum() > 100 and d.min() > 1e-5  # nowhere within 10 um
    x2, _ = insert_grains(other)
    d2, _ = tree.query(x2[np.abs(x2[:, 1]) > 4e-3])
    assert np.median(d) / np.median(d2) == pytest.approx(1, abs=0.2)  # as far as another seed's grains
