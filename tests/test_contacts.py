"""The cutter-contact census (deckgen.contacts): Hertz force rebuilt from the dumps, split by body, chips and debris."""
from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from deckgen.chips import bond_components, initial_bonds, last_frame
from deckgen.cli import main as cli_main
from deckgen.contacts import census_of_parsed, frame_census, hertz_stiffness
from deckgen.results import parse_run
from deckgen.spec import SpecError

CUT = Path(__file__).parent / "data" / "runs" / "ref_cut"


@pytest.fixture(scope="module")
def cut_parsed(tmp_path_factory):
    out = tmp_path_factory.mktemp("ref_cut_parsed")
    return parse_run(CUT, out), out


def test_bond_components_drops_the_broken_pairs_in_either_order():
    bonds = np.array([[1, 2], [2, 3], [3, 6], [4, 5]])
    label, sizes, body = bond_components(bonds, np.array([[6, 3]]), np.array([1, 2, 3, 4, 5, 6]))
    assert sorted(sizes.tolist()) == [1, 2, 3]
    assert label[0] == label[1] == label[2] == body and sizes[body] == 3
    assert label[3] == label[4] != body and sizes[label[5]] == 1
    # nothing broken: 1-2-3-6 and 4-5
    label, sizes, body = bond_components(bonds, np.zeros((0, 2), int), np.array([1, 2, 3, 4, 5, 6]))
    assert sizes[body] == 4 and label[5] == body


def test_hertz_stiffness_is_four_thirds_of_the_two_material_modulus():
    case = {"contact": {"youngs_modulus_GPa": 10.0, "poisson_ratio": 0.25, "cutter_youngs_modulus_GPa": 210.0,
                        "cutter_poisson_ratio": 0.3}}
    e_star = 1.0 / ((1 - 0.25**2) / 10e9 + (1 - 0.3**2) / 210e9)
    assert hertz_stiffness(case) == pytest.approx(4.0 / 3.0 * e_star, rel=1e-12)
    assert hertz_stiffness(case) == pytest.approx(1.3594e10, rel=1e-4)


def test_one_contact_gives_the_hertz_force_along_the_line_of_centres():
    # a 1 mm grain at the origin, a 0.3 mm shell sphere 1.25 mm above it at 45 deg in x-z: 0.05 mm overlap
    u = np.array([1.0, 0.0, 1.0]) / math.sqrt(2.0)
    atoms = pd.DataFrame({"id": [1, 2, 3], "type": [1, 1, 2], "radius": [1e-3, 1e-3, 0.3e-3],
                          "x": [0.0, 0.01, 1.25e-3 * u[0]], "y": [0.0, 0.0, 0.0], "z": [0.0, 0.0, 1.25e-3 * u[2]]})
    k = 1.0e10
    reff, delta = 1e-3 * 0.3e-3 / 1.3e-3, 0.05e-3
    f = k * math.sqrt(reff * delta) * delta
    # grain 1 alone (debris), grain 2 the body (size 2 by label)
    out = frame_census(atoms, k, label=np.array([0, 1]), body=1, sizes=np.array([1, 2]))
    assert out["grains_touching"] == 1 and out["grains_touching_debris"] == 1 and out["grains_touching_body"] == 0
    assert out["force_z_hertz_N"] == pytest.approx(f * u[2], rel=1e-9)
    assert out["force_x_hertz_N"] == pytest.approx(f * u[0], rel=1e-9)
    assert out["force_z_hertz_debris_N"] == pytest.approx(out["force_z_hertz_N"]) and out["force_z_hertz_body_N"] == 0
    # the same grain as part of the body
    out = frame_census(atoms, k, label=np.array([0, 0]), body=0, sizes=np.array([2]))
    assert out["grains_touching_body"] == 1 and out["force_z_hertz_body_N"] == pytest.approx(f * u[2], rel=1e-9)
    # 0.1 mm apart: no contact, no force
    far = atoms.assign(z=[0.0, 0.0, 1.4e-3 * u[2]], x=[0.0, 0.01, 1.4e-3 * u[0]])
    assert frame_census(far, k, np.array([0, 1]), 1, np.array([1, 2]))["force_z_hertz_N"] == 0.0


def test_census_of_the_reference_cut_rebuilds_the_series_normal_force(cut_parsed):
    """ref_cut (real engine): 7 dumped steps. Where the disc presses hard (series F_z > 50 N) the Hertz normal force
    rebuilt from positions and radii is within 5 % of the force LAMMPS summed on the cutter; with any contact within
    25 % (the damping and tangential parts are not in the dumps)."""
    summary, out = cut_parsed
    t = census_of_parsed(CUT, out)
    assert list(t["step"]) == list(range(0, 42001, 7000))
    assert (t["grains_touching"] == t[["grains_touching_body", "grains_touching_chip",
                                        "grains_touching_debris"]].sum(axis=1)).all()
    parts = t[["force_z_hertz_body_N", "force_z_hertz_chip_N", "force_z_hertz_debris_N"]].sum(axis=1)
    assert parts.to_numpy() == pytest.approx(t["force_z_hertz_N"].to_numpy(), abs=1e-9)
    hard = t[t["force_z_series_N"] > 50]
    assert len(hard) == 2
    assert (hard["force_z_hertz_N"] / hard["force_z_series_N"]).to_numpy() == pytest.approx([1.0, 1.0], abs=0.05)
    touch = t[t["force_z_hertz_N"] > 0]
    assert len(touch) == 4
    assert ((touch["force_z_hertz_N"] / touch["force_z_series_N"] - 1).abs() < 0.25).all()
    # the steps before the disc reaches the block (0.2 mm clearance) have neither contact nor force
    assert (t.loc[t["step"] <= 14000, ["grains_touching", "force_z_series_N"]] == 0).all().all()
    # the body that presses at 21 000 and 28 000 steps; at the end a chip: the classes follow the broken bonds
    assert list(touch["grains_touching_body"]) == [1, 1, 1, 0] and touch["grains_touching_chip"].iloc[-1] == 1
    assert touch["detached_share_z_1"].iloc[-1] == 1.0 and (touch["detached_share_z_1"].iloc[:3] == 0).all()
    # the final step's body is the chips analysis' body
    broken = pd.read_parquet(out / "broken.parquet")[["id1", "id2"]].to_numpy()
    atoms = last_frame(CUT)
    _, sizes, body = bond_components(initial_bonds(CUT), broken, atoms.loc[atoms["type"] == 1, "id"].to_numpy())
    assert sizes[body] == summary["body_grains"]


def test_the_census_command_writes_the_table_and_refuses_a_wall_cutter(cut_parsed, tmp_path, capsys):
    _, out = cut_parsed
    assert cli_main(["contacts", str(CUT), "--parsed", str(out), "--out", str(tmp_path / "c.csv")]) == 0
    assert len(pd.read_csv(tmp_path / "c.csv")) == 7
    assert "4 with contact" in capsys.readouterr().out
    run = tmp_path / "wall"
    shutil.copytree(CUT, run)
    spec = json.loads((run / "spec.json").read_text())
    spec["derived"]["n_shell"] = 0
    (run / "spec.json").write_text(json.dumps(spec))
    with pytest.raises(SpecError, match="no shell spheres"):
        census_of_parsed(run, out)
    assert cli_main(["contacts", str(run), "--parsed", str(out), "--out", str(tmp_path / "w.csv")]) == 2
    assert "no shell spheres" in capsys.readouterr().err
    assert cli_main(["contacts", str(CUT), "--parsed", str(tmp_path), "--out", str(tmp_path / "w.csv")]) == 2
    assert "broken.parquet: missing" in capsys.readouterr().err
