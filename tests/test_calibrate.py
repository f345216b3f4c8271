"""Calibration machinery: material-card schema, the optimiser loop on the analytic stand-in
(convergence for the four rocks, injected failures, resume after an interrupt) and one tiny real
DEM evaluation (marked ``engine``)."""

from __future__ import annotations

import json
import math
import time
from pathlib import Path

import numpy as np
import pytest
import yaml

from deckgen.calibrate import (
    CardError,
    DemEvaluator,
    MaterialCard,
    MicroParams,
    ParameterSpace,
    StandInEvaluator,
    analytic_start,
    calibrate,
    load_card,
    main,
    read_table,
)

ROOT = Path(__file__).resolve().parents[1]
MATERIALS = ROOT / "cases" / "materials"
CONCRETE_BPM = ROOT / "tests" / "data" / "cards" / "concrete_bpm.yaml"  # a bpm/rotational card for the stand-in runs
ROCKS = ["savonniere_limestone", "concrete", "sandstone", "colorado_red_granite"]


def _card(rock: str) -> MaterialCard:
    return load_card(MATERIALS / f"{rock}.yaml")


# ------------------------------------------------------------------------------------ targets
def test_target_cards_match_rock_table():
    import csv

    table = Path("/work/shared/data/rocks.csv")  # the shared transcription of the seeds' tables
    rows = {}
    if table.is_file():
        rows = {r["rock"]: r for r in csv.DictReader(ln for ln in table.read_text().splitlines() if not ln.startswith("#"))}
    # the rocks' cards and the cutting families' cards (cases/materials/cutting/, read first by deckgen.families)
    paths = [MATERIALS / f"{rock}.yaml" for rock in ROCKS] + sorted((MATERIALS / "cutting").glob("*.yaml"))
    assert len(paths) > len(ROCKS)
    for path in paths:
        rock = path.stem
        card = load_card(path)
        assert card.rock == rock
        if card.provenance is not None:  # a calibrated card says whether it met its tolerance, and how
            a = card.provenance.achieved
            assert card.calibrated is not None
            within = max(abs(a.ucs_error), abs(a.bts_error), abs(a.youngs_modulus_error)) <= card.provenance.tolerance
            split = card.provenance.bts_max_broken_at_peak is None or a.bts_broken_at_peak <= card.provenance.bts_max_broken_at_peak
            assert card.provenance.converged == (within and split), path
            if not card.provenance.converged:
                assert "NOT converged" in path.read_text()
            assert a.ucs_MPa == pytest.approx(card.targets.ucs_MPa * (1 + a.ucs_error), rel=1e-3)
        assert "seed 00" in card.targets.citation
        if rows and path.parent == MATERIALS:  # the shared rock table is there: the rocks' cards transcribe it (a
            # cutting card may take other targets: granite's are CSM-equivalent, checked in test_families)
            r = rows[rock]
            t = card.targets
            assert (t.density_kg_m3, t.ucs_MPa, t.bts_MPa, t.youngs_modulus_GPa, t.poisson_ratio) == tuple(
                float(r[k]) for k in ("density_kg_m3", "ucs_MPa", "bts_MPa", "youngs_modulus_GPa", "poisson_ratio"))
    assert "12MPa" in (MATERIALS / "savonniere_limestone.yaml").read_text()  # the seed's unit typo is noted


# ------------------------------------------------------------------------------------ card schema
def test_card_round_trip_and_case_overrides(tmp_path):
    card = _card("sandstone")
    res = calibrate(StandInEvaluator(), card.targets, analytic_start(card.targets), tmp_path / "t.csv",
                    card=card, card_path=tmp_path / "card.yaml")
    assert res.converged
    back = load_card(tmp_path / "card.yaml")
    assert back == res.card
    assert back.provenance.converged and back.provenance.evaluations == res.n_evals
    assert abs(back.provenance.achieved.ucs_error) <= 0.05
    assert (tmp_path / "card.yaml").read_text().startswith("# deckgen material card")
    # the card's overrides make a valid case with the calibrated bonds
    from deckgen.spec import Case, deep_merge

    case = Case.model_validate(deep_merge(back.case_overrides(), {"specimen": {"kind": "ucs_cylinder"}}))
    assert case.bonds.youngs_modulus_GPa == back.calibrated.bonds["youngs_modulus_GPa"]
    assert case.material.density_kg_m3 == 2450 and case.contact.poisson_ratio == 0.21


@pytest.mark.parametrize("patch, expect", [
    ({"calibrated": {"bonds": {"youngs_modulus_GPA": 10.0}}}, "calibrated.bonds: unknown bonds field(s) youngs_modulus_GPA"),
    ({"calibrated": {"bonds": {"tensile_strength_MPa": -1.0}}}, "calibrated.bonds: tensile_strength_MPa"),
    ({"targets": {"ucs_MPa": -5}}, "targets.ucs_MPa: Input should be greater than 0"),
    ({"colour": "red"}, "colour: Extra inputs are not permitted (fix: remove it"),
    ({"calibration": {"parameters": ["log_E_b", "log_sigma_c"]}}, "need three free parameters"),
    ({"calibration": {"parameters": ["log_E_b", "log_tau_ratio", "gap_tolerance"]}}, "log_sigma_c is required"),
    ({"calibration": {"parameters": ["log_E_b", "log_sigma_c", "log_tau_ratio", "stiffness"]}}, "calibration.parameters.3"),
    ({"calibration": {"ucs_specimen": {"kind": "ucs_cylinder", "diameter_mm": 2}}}, "ucs_specimen / base"),
    ({"calibration": {"bounds": {"log_tau_ratio": [-2.0, 0.5]}}}, "bounds: log_tau_ratio is not in parameters"),
    ({"calibration": {"parameters": ["log_E_b", "log_sigma_c", "log_tau_ratio"], "bounds": {"log_tau_ratio": [0.5, -2.0]}}},
     "bounds: log_tau_ratio: need finite lower < upper"),
    ({"calibration": {"start_table": "medium"}}, "calibration.start_table: Input should be 'ratio', 'high_strain', 'flat_joint' or 'flat_joint_split'"),
    ({"calibrated": {"bonds": {"clump_size": 0}}}, "calibrated.bonds: clump_size"),
])
def test_bad_card_field_gives_clear_error(tmp_path, patch, expect):
    from deckgen.spec import deep_merge

    data = deep_merge(yaml.safe_load((CONCRETE_BPM).read_text()), patch)
    p = tmp_path / "concrete.yaml"
    p.write_text(yaml.safe_dump(data))
    with pytest.raises(CardError) as exc:
        load_card(p)
    msg = str(exc.value)
    assert msg.startswith(f"{p}: ") and expect in msg, msg


# ------------------------------------------------------------------------------------ analytic start
def test_analytic_start_reproduces_the_measured_points():
    from deckgen.calibrate import MICRO_MACRO, CardTargets

    for g, r, cE, cU, cB in MICRO_MACRO:
        if g > 0.4:  # the falling branch of UCS/BTS(g): the start takes the rising one
            continue
        t = CardTargets(density_kg_m3=2650, ucs_MPa=30 * cU, bts_MPa=30 * cB, youngs_modulus_GPa=40 * cE,
                        poisson_ratio=0.25, citation="calibration_studies ratio")
        names = ["log_E_b", "log_sigma_c", "log_tau_ratio"] if g == 0.05 else ["log_E_b", "log_sigma_c", "gap_tolerance"]
        p = analytic_start(t, {"bonds": {"gap_tolerance": 0.05}}, ParameterSpace(names))
        assert p.youngs_modulus_GPa == pytest.approx(40.0, rel=0.02), (g, r)
        assert p.tensile_strength_MPa == pytest.approx(30.0, rel=0.02), (g, r)
        assert p.tau_ratio == pytest.approx(r, rel=0.02) and p.gap_tolerance == pytest.approx(g, abs=0.005)


def test_analytic_start_uses_the_interaction_range_for_high_ratios():
    g = analytic_start(_card("colorado_red_granite").targets, None,
                       ParameterSpace(["log_E_b", "log_sigma_c", "gap_tolerance", "log_tau_ratio"]))
    c = analytic_start(_card("concrete").targets, None, ParameterSpace(["log_E_b", "log_sigma_c", "gap_tolerance"]))
    # UCS/BTS 23 (granite): the range of the highest measured ratio (g 0.4) and a lower shear ratio;
    # 10 (concrete): a moderate range
    assert 0.35 <= g.gap_tolerance <= 0.45 and g.tau_ratio < 0.5
    assert 0.2 < c.gap_tolerance < 0.45 and c.tau_ratio == 1.0


def test_analytic_start_high_strain_reproduces_the_measured_points():
    from deckgen.calibrate import (
        HIGH_STRAIN_CONTACT_RATIO,
        HIGH_STRAIN_GAP,
        MICRO_MACRO_HIGH_STRAIN,
        CardTargets,
        micro_macro_high_strain,
    )

    space = ParameterSpace(["log_E_b", "log_sigma_c", "log_tau_ratio"], bounds={"log_tau_ratio": (math.log(0.1), 1.0)})
    for strain, r, cE, cU, cB in MICRO_MACRO_HIGH_STRAIN:
        sigma_c = 20e3 * strain  # MPa at E_b 20 GPa
        t = CardTargets(density_kg_m3=2450, ucs_MPa=sigma_c * cU, bts_MPa=sigma_c * cB, youngs_modulus_GPa=20 * cE,
                        poisson_ratio=0.2, citation="calibration_studies ratio --set high-strain")
        p = analytic_start(t, None, space, table="high_strain")
        assert p.gap_tolerance == HIGH_STRAIN_GAP and p.contact_modulus_ratio == HIGH_STRAIN_CONTACT_RATIO
        # the table at the start's own failure strain gives the targets back
        s = min(max(p.tensile_strength_MPa / (p.youngs_modulus_GPa * 1e3), 3e-3), 6e-3)
        pE, pU, pB = micro_macro_high_strain(s, p.tau_ratio)
        assert p.youngs_modulus_GPa * pE == pytest.approx(t.youngs_modulus_GPa, rel=0.02), (strain, r)
        assert p.tensile_strength_MPa * pU == pytest.approx(t.ucs_MPa, rel=0.02), (strain, r)
        assert p.tensile_strength_MPa * pB == pytest.approx(t.bts_MPa, rel=0.02), (strain, r)
        if strain == 3e-3:  # where the fixed point starts: the measured point itself
            assert p.youngs_modulus_GPa == pytest.approx(20.0, rel=0.02), (strain, r)
            assert p.tensile_strength_MPa == pytest.approx(sigma_c, rel=0.02), (strain, r)
            assert p.tau_ratio == pytest.approx(r, rel=0.02), (strain, r)
        else:  # UCS/BTS follows tau_c/E_b: (6e-3, r) and (3e-3, ~2r) give nearly the same ratio
            assert p.shear_strength_MPa / p.youngs_modulus_GPa == pytest.approx(r * strain * 1e3, rel=0.35)


def test_high_strain_start_and_prior_for_sandstone():
    from deckgen.calibrate import prior_jacobian

    card = _card("sandstone")
    space = ParameterSpace(["log_E_b", "log_sigma_c", "log_tau_ratio"])
    p = analytic_start(card.targets, None, space, table="high_strain")
    # UCS/BTS 13.8 at UCS/E 0.86 %: the table's failure strains (3e-3 to 6e-3) need tau_c/sigma_c below the
    # measured 0.25; the start sits at the default bound 0.25 (1e-3 inside it), sigma_c/E_b above 6e-3
    assert p.tau_ratio == pytest.approx(0.25, rel=0.01)
    assert p.tensile_strength_MPa / (p.youngs_modulus_GPa * 1e3) > 6e-3
    J = prior_jacobian(space, "high_strain")
    k = space.names.index("log_tau_ratio")
    # lowering tau_c/sigma_c lowers BTS faster than UCS (the measured mechanism), and E a little
    assert J[1, k] > J[0, k] > J[2, k] > 0
    assert J.shape == (3, 3) and np.all(np.isfinite(J))
    with pytest.raises(ValueError, match="unknown table"):
        analytic_start(card.targets, None, space, table="nope")


def test_clump_fields_in_params_keys_and_overrides():
    import hashlib
    import json
    from dataclasses import asdict

    from deckgen.calibrate import CalibratedParams

    p = MicroParams(20.0, 60.0, 15.0, gap_tolerance=0.4, contact_modulus_ratio=4.0)
    # without clumps (and at the defaults of the later fields) the key is the one recorded before they existed
    later = ("unbonded_fraction", "bending_strength_factor", "twisting_strength_factor", "strength_weibull_modulus",
             "shrink_before_bonding", "flat_joint", "joint_friction", "moment_contribution", "face_sectors", "face_gap_tolerance",
             "stiffness_ratio", "bond_friction")
    old = {k: float(f"{v:.10g}") for k, v in asdict(p).items() if not k.startswith("clump_") and k not in later}
    assert p.key() == hashlib.sha1(json.dumps(old, sort_keys=True).encode()).hexdigest()[:16]
    assert "clump_size" not in p.overrides()["bonds"]
    q = MicroParams(20.0, 60.0, 15.0, clump_size=4, clump_strength_factor=50.0)
    assert q.key() != MicroParams(20.0, 60.0, 15.0).key()
    assert q.overrides()["bonds"]["clump_size"] == 4 and q.overrides()["bonds"]["clump_strength_factor"] == 50.0
    CalibratedParams(bonds={k: float(v) for k, v in q.overrides()["bonds"].items()})  # a valid card block
    assert not set(later) & set(q.overrides()["bonds"])
    u = MicroParams(20.0, 60.0, 15.0, unbonded_fraction=0.25, bending_strength_factor=10.0)
    assert u.key() not in (MicroParams(20.0, 60.0, 15.0).key(), MicroParams(20.0, 60.0, 15.0, unbonded_fraction=0.25).key())
    assert u.overrides()["bonds"]["unbonded_fraction"] == 0.25 and u.overrides()["bonds"]["bending_strength_factor"] == 10.0
    assert "twisting_strength_factor" not in u.overrides()["bonds"]
    CalibratedParams(bonds={k: float(v) for k, v in u.overrides()["bonds"].items()})


def test_parameter_space_round_trip_and_bounds():
    sp = ParameterSpace(["log_E_b", "log_sigma_c", "log_tau_ratio", "friction", "radius_multiplier"])
    p = MicroParams(20.0, 10.0, 35.0, friction=0.7, rolling_friction=0.1, radius_multiplier=1.2)
    q = sp.from_vector(sp.to_vector(p), p)
    assert q.key() == p.key()
    assert np.all(sp.lo < sp.to_vector(p)) and np.all(sp.to_vector(p) < sp.hi)
    with pytest.raises(ValueError, match="unknown parameter"):
        ParameterSpace(["log_E_b", "nope"])


def test_twisting_factor_parameter_moves_the_torque_strength_only():
    from deckgen.calibrate import prior_jacobian

    sp = ParameterSpace(["log_E_b", "log_sigma_c", "log_twisting_factor"])
    p = MicroParams(13.7, 19.0, 19.0, clump_size=16, twisting_strength_factor=2.0)
    x = sp.to_vector(p)
    assert x[2] == pytest.approx(math.log(2.0))
    q = sp.from_vector(x + np.array([0.0, 0.0, math.log(1.2)]), p)
    assert q.twisting_strength_factor == pytest.approx(2.4) and q.clump_size == 16
    assert (q.youngs_modulus_GPa, q.tensile_strength_MPa, q.shear_strength_MPa) == pytest.approx((13.7, 19.0, 19.0))
    assert q.overrides(True)["bonds"]["twisting_strength_factor"] == pytest.approx(2.4)
    # bounded to [1, 2.5]: at x3 clumped cylinders stopped failing within 4.3 % strain
    assert math.exp(sp.hi[2]) == pytest.approx(2.5) and math.exp(sp.lo[2]) == pytest.approx(1.0)
    # measured prior: UCS rises 0.8 per log unit of the factor, BTS 0.09, E not at all
    col = prior_jacobian(sp)[:, 2]
    assert col == pytest.approx([0.799, 0.085, 0.0], abs=2e-3)


def test_stand_in_reaches_real_ucs_bts_ratios():
    ev = StandInEvaluator(noise=0.0)
    ratio = {}
    for g, r in ((0.05, 1.0), (0.3, 1.0), (0.6, 1.0), (0.6, 0.5)):
        out = ev.evaluate(MicroParams(40.0, 30.0, 30.0 * r, gap_tolerance=g))
        ratio[g, r] = out["ucs_Pa"] / out["bts_Pa"]
    assert ratio[0.05, 1.0] < 8 and ratio[0.3, 1.0] > 9 and ratio[0.6, 1.0] > 19 and ratio[0.6, 0.5] > 24


# ------------------------------------------------------------------------------------ the loop
@pytest.mark.parametrize("rock", ROCKS)
def test_converges_on_stand_in(tmp_path, rock):
    card = _card(rock)
    ev = StandInEvaluator(noise=0.01)
    res = calibrate(ev, card.targets, analytic_start(card.targets), tmp_path / "t.csv", tol=0.05, max_evals=30)
    assert res.converged and res.stop_reason == "converged", res.errors
    assert res.n_evals <= 30 and ev.calls == res.n_evals
    assert all(abs(e) <= 0.05 for e in res.errors.values())
    rows = read_table(tmp_path / "t.csv")
    assert len(rows) == res.n_evals and [r["eval"] for r in rows] == list(range(res.n_evals))
    for r in rows:  # the ratios the mechanism studies read; the stand-in reports no strain at the peak
        assert r["ucs_to_bts_1"] == pytest.approx(r["ucs_Pa"] / r["bts_Pa"], rel=1e-12)
        assert r["ucs_to_E_pct"] == pytest.approx(100 * r["ucs_Pa"] / r["E_Pa"], rel=1e-12)
        assert math.isnan(r["ucs_strain_at_peak_1"])
    print(f"{rock}: {res.n_evals} evaluations, errors " + ", ".join(f"{k} {v:+.2%}" for k, v in res.errors.items()))


@pytest.mark.parametrize("rock", ROCKS)
def test_survives_injected_failures(tmp_path, rock):
    """30 % of points fail (lost atoms); tighter tolerance, so the search is longer."""
    card = _card(rock)
    fails = 0
    for seed in ("a", "b", "c", "d"):
        ev = StandInEvaluator(noise=0.005, fail_rate=0.3, seed=seed)
        res = calibrate(ev, card.targets, analytic_start(card.targets), tmp_path / f"{seed}.csv", tol=0.02,
                        max_evals=30)
        assert res.converged, (seed, res.errors, [e.error for e in res.evaluations])
        fails += sum(not e.ok for e in res.evaluations)
        rows = read_table(tmp_path / f"{seed}.csv")
        bad = [r for r in rows if not r["ok"]]
        assert all("injected failure" in r["error"] and math.isnan(r["ucs_Pa"]) for r in bad)
    assert fails > 0  # failures did happen and were carried through


def test_failing_start_moves_towards_a_running_point(tmp_path):
    card = _card("colorado_red_granite")  # start E_b ~ 137 GPa
    ev = StandInEvaluator(noise=0.0, fail_above_E_b_GPa=2000.0)
    start = analytic_start(card.targets)
    bad_start = MicroParams(400.0, start.tensile_strength_MPa, start.shear_strength_MPa)
    ev.fail_above = 300.0
    res = calibrate(ev, card.targets, bad_start, tmp_path / "t.csv", max_evals=30)
    assert not res.evaluations[0].ok and "unstable region" in res.evaluations[0].error
    assert res.converged and res.n_evals <= 30


class _Interrupting:
    """Delegates to a stand-in, raises KeyboardInterrupt at evaluation number ``stop_at``."""

    def __init__(self, inner: StandInEvaluator, stop_at: int) -> None:
        self.inner, self.stop_at, self.n = inner, stop_at, 0

    def evaluate(self, params):
        if self.n == self.stop_at:
            raise KeyboardInterrupt
        self.n += 1
        return self.inner.evaluate(params)


def test_resume_after_interrupt(tmp_path):
    card = _card("colorado_red_granite")
    start = analytic_start(card.targets)
    kw = dict(tol=0.02, max_evals=30)  # tighter tolerance: a longer path to interrupt
    full_ev = StandInEvaluator(noise=0.005, fail_rate=0.2, seed="r")
    full = calibrate(full_ev, card.targets, start, tmp_path / "full.csv", **kw)
    assert full.converged and full.n_evals >= 4, full.n_evals
    k = full.n_evals // 2

    inner = StandInEvaluator(noise=0.005, fail_rate=0.2, seed="r")
    with pytest.raises(KeyboardInterrupt):
        calibrate(_Interrupting(inner, k), card.targets, start, tmp_path / "part.csv", **kw)
    assert len(read_table(tmp_path / "part.csv")) == k

    again = StandInEvaluator(noise=0.005, fail_rate=0.2, seed="r")
    res = calibrate(again, card.targets, start, tmp_path / "part.csv", **kw)
    assert again.calls == full.n_evals - k  # only the new points were evaluated
    assert not set(again.keys) & set(inner.keys)  # no point repeated
    assert sum(e.replayed for e in res.evaluations) == k and res.new_evaluations == full.n_evals - k
    assert [e.key for e in res.evaluations] == [e.key for e in full.evaluations]
    assert res.best.key == full.best.key and res.errors == full.errors
    # a third run replays everything and evaluates nothing
    idle = StandInEvaluator(noise=0.005, fail_rate=0.2, seed="r")
    res3 = calibrate(idle, card.targets, start, tmp_path / "part.csv", **kw)
    assert idle.calls == 0 and res3.best.key == full.best.key


def test_table_written_before_the_ratio_columns_replays(tmp_path):
    """Tables recorded before ucs_to_bts_1, ucs_to_E_pct and ucs_strain_at_peak_1 existed still resume."""
    import pandas as pd

    card = _card("sandstone")
    start = analytic_start(card.targets)
    first = calibrate(StandInEvaluator(noise=0.01), card.targets, start, tmp_path / "t.csv", max_evals=5)
    old = pd.read_csv(tmp_path / "t.csv").drop(columns=["ucs_to_bts_1", "ucs_to_E_pct", "ucs_strain_at_peak_1"])
    old.to_csv(tmp_path / "t.csv", index=False)
    idle = StandInEvaluator(noise=0.01)
    again = calibrate(idle, card.targets, start, tmp_path / "t.csv", max_evals=5)
    assert idle.calls == 0 and [e.key for e in again.evaluations] == [e.key for e in first.evaluations]


def test_table_of_other_targets_is_refused(tmp_path):
    a, b = _card("concrete"), _card("sandstone")
    calibrate(StandInEvaluator(), a.targets, analytic_start(a.targets), tmp_path / "t.csv")
    with pytest.raises(ValueError, match="recorded for other targets"):
        calibrate(StandInEvaluator(), b.targets, analytic_start(b.targets), tmp_path / "t.csv")


def test_budget_stops_and_writes_unconverged_card(tmp_path):
    card = _card("sandstone")
    res = calibrate(StandInEvaluator(noise=0.01), card.targets, analytic_start(card.targets), tmp_path / "t.csv",
                    tol=1e-4, max_evals=5, card=card, card_path=tmp_path / "card.yaml")
    assert res.stop_reason == "budget" and res.n_evals == 5 and not res.converged
    back = load_card(tmp_path / "card.yaml")
    assert back.provenance.converged is False and back.calibrated is not None
    assert "NOT converged" in (tmp_path / "card.yaml").read_text()


def test_cli_with_stand_in(tmp_path, capsys):
    out = tmp_path / "out"
    assert main([str(CONCRETE_BPM), "--out", str(out), "--stand-in"]) == 0
    card = load_card(out / "card.yaml")
    assert card.provenance.converged and card.provenance.evaluator == "StandInEvaluator"
    assert "converged" in capsys.readouterr().out
    # resumable: a second call replays the table
    assert main([str(CONCRETE_BPM), "--out", str(out), "--stand-in"]) == 0
    assert load_card(out / "card.yaml").provenance.new_evaluations == 0


def test_card_start_fixes_a_mechanism_the_tables_do_not_cover(tmp_path):
    """calibration.start: clumps and a twisting factor held fixed (not optimiser parameters) reach the calibrated
    card; sigma_c alone keeps the analytic start's tau_c/sigma_c; unknown fields are refused by name."""
    import yaml

    from deckgen.calibrate import run_card

    d = yaml.safe_load((CONCRETE_BPM).read_text())
    d.setdefault("calibration", {})["start"] = {"clump_size": 16, "twisting_strength_factor": 10.0,
                                                "tensile_strength_MPa": 7.0}
    path = tmp_path / "c.yaml"
    path.write_text(yaml.safe_dump(d))
    res = run_card(path, tmp_path / "out", stand_in=True, quiet=True)
    card = load_card(tmp_path / "out" / "card.yaml")
    assert card.calibrated.bonds["clump_size"] == 16 and card.calibrated.bonds["twisting_strength_factor"] == 10.0
    assert card.provenance.start["clump_size"] == 16 and card.provenance.start["tensile_strength_MPa"] == 7.0
    plain = run_card(CONCRETE_BPM, tmp_path / "plain", stand_in=True, quiet=True)
    r0 = plain.card.provenance.start["shear_strength_MPa"] / plain.card.provenance.start["tensile_strength_MPa"]
    assert card.provenance.start["shear_strength_MPa"] == pytest.approx(7.0 * r0, rel=1e-5)
    assert res.n_evals >= 1
    d["calibration"]["start"] = {"clumps": 4}
    path.write_text(yaml.safe_dump(d))
    with pytest.raises(Exception, match=r"start: unknown field\(s\) \['clumps'\]"):
        load_card(path)


# ------------------------------------------------------------------------------------ one real DEM step
def _lmp_ok() -> bool:
    from deckgen.runner import engine_available

    return engine_available()


TINY_BASE = {"packing": {"radius_min_mm": 0.6, "radius_max_mm": 0.9, "steps_per_stage": 2000, "relax_steps": 4000}}
TINY_UCS = {"kind": "ucs_cylinder", "diameter_mm": 8, "height_mm": 16, "platen_speed_m_s": 0.2, "max_strain": 0.02}
TINY_BTS = {"kind": "brazilian_disc", "diameter_mm": 10, "thickness_mm": 5, "platen_speed_m_s": 0.2}


@pytest.mark.engine
@pytest.mark.skipif(not _lmp_ok(), reason="no LAMMPS binary (run `make setup`)")
def test_table_of_another_bts_reading_is_refused(tmp_path):
    card = _card("concrete")
    calibrate(StandInEvaluator(), card.targets, analytic_start(card.targets), tmp_path / "t.csv", max_evals=2)
    ev = StandInEvaluator()
    ev.bts_reading = "split"
    with pytest.raises(ValueError, match=r"recorded with bts_reading 'peak'.*reads 'split'.*--work"):
        calibrate(ev, card.targets, analytic_start(card.targets), tmp_path / "t.csv", max_evals=2)
    with pytest.raises(ValueError, match="bts_reading: 'middle'"):
        DemEvaluator({}, TINY_UCS, TINY_BTS, tmp_path / "w", bts_reading="middle")


def test_tiny_dem_evaluation_and_cache_hit(tmp_path):
    from deckgen.runner import engine_command

    p = MicroParams(10.0, 10.0, 20.0)
    ev = DemEvaluator(TINY_BASE, TINY_UCS, TINY_BTS, tmp_path / "work", cache=tmp_path / "cache",
                      command=engine_command(1), name="tiny")
    t0 = time.perf_counter()
    out = ev.evaluate(p)
    wall = time.perf_counter() - t0
    assert out["ok"], out["error"]
    for k in ("ucs_Pa", "bts_Pa", "E_Pa"):
        assert math.isfinite(out[k]) and out[k] > 0, (k, out)
    assert out["engine_runs"] == 2 and ev.engine_runs == 2
    assert 0.1e6 < out["bts_Pa"] < out["ucs_Pa"] < 100e6 and 0.1e9 < out["E_Pa"] < 50e9
    assert 0.1 * out["ucs_Pa"] / out["E_Pa"] < out["ucs_strain_at_peak_1"] < TINY_UCS["max_strain"]
    # split or crushed: the disc's bonds broken at its peak over its initial bonds, also read back from disk
    bts = json.loads((ev.used_folder(p, "bts") / "parsed" / "summary.json").read_text())
    assert 0 < bts["bonds_broken_at_peak"] < bts["n_bonds_initial"]
    assert out["bts_broken_at_peak_1"] == bts["bonds_broken_at_peak"] / bts["n_bonds_initial"] == ev.bts_broken_at_peak(p)
    print(f"tiny DEM: UCS {out['ucs_Pa'] / 1e6:.3g} MPa, BTS {out['bts_Pa'] / 1e6:.3g} MPa, "
          f"E {out['E_Pa'] / 1e9:.3g} GPa in {wall:.1f} s")
    # same params again: answered from the folder, no engine run (an engine that cannot run proves it)
    again = DemEvaluator(TINY_BASE, TINY_UCS, TINY_BTS, tmp_path / "work", cache=tmp_path / "cache",
                         command=["false"], name="tiny")
    out2 = again.evaluate(MicroParams(10.0, 10.0, 20.0))
    assert again.engine_runs == 0 and out2["engine_runs"] == 0
    assert {k: out2[k] for k in ("ucs_Pa", "bts_Pa", "E_Pa", "ok")} == {k: out[k] for k in ("ucs_Pa", "bts_Pa", "E_Pa", "ok")}
    # the split reading (docs/calibration.md, "BTS at the split") of the same runs, without an engine run; a summary
    # written before the split existed gets it from the parsed tables, to the same value
    split = DemEvaluator(TINY_BASE, TINY_UCS, TINY_BTS, tmp_path / "work", cache=tmp_path / "cache",
                         command=["false"], name="tiny", bts_reading="split")
    o3 = split.evaluate(p)
    assert split.engine_runs == 0 and o3["ucs_Pa"] == out["ucs_Pa"]
    assert o3["bts_Pa"] == bts["split_stress_Pa"] == o3["bts_split_Pa"] <= bts["peak_stress_Pa"] == out["bts_Pa"]
    assert bts["split_source"] in ("crack", "peak")
    summary = ev.used_folder(p, "bts") / "parsed" / "summary.json"
    summary.write_text(json.dumps({k: v for k, v in bts.items() if "split" not in k}))
    assert split.evaluate(p)["bts_Pa"] == o3["bts_Pa"]
    # a failing engine makes a failed point, not an exception
    broken = DemEvaluator(TINY_BASE, TINY_UCS, TINY_BTS, tmp_path / "work2", cache=tmp_path / "cache",
                          command=["false"], name="tiny")
    bad = broken.evaluate(p)
    assert bad["ok"] is False and "EngineError" in bad["error"] and math.isnan(bad["ucs_Pa"])


@pytest.mark.engine
@pytest.mark.skipif(not _lmp_ok(), reason="no LAMMPS binary (run `make setup`)")
def test_specimen_that_did_not_fail_is_run_longer_or_fails_the_point(tmp_path):
    """A UCS run cut by max_strain before its peak (here 0.002; the tiny cylinder peaks at a strain of
    0.0035) reports a lower bound, not a strength: the evaluator runs it again at 2.5x the strain, and
    without that retry the point fails with a message instead of entering the table."""
    from deckgen.runner import engine_command

    p = MicroParams(10.0, 10.0, 20.0)
    short = {**TINY_UCS, "max_strain": 0.002}
    strict = DemEvaluator(TINY_BASE, short, TINY_BTS, tmp_path / "strict", cache=tmp_path / "cache",
                          command=engine_command(1), name="tiny", extend_attempts=0)
    bad = strict.evaluate(p)
    assert bad["ok"] is False and "did not fail before max_strain 0.002" in bad["error"], bad
    cut = json.loads(next((tmp_path / "strict").rglob("ucs/parsed/summary.json")).read_text())
    assert cut["peak_reached"] is False and cut["strain_at_peak_1"] > 0.97 * cut["final_strain_1"]
    assert "no failure" in cut["notes"]

    ev = DemEvaluator(TINY_BASE, short, TINY_BTS, tmp_path / "work", cache=tmp_path / "cache",
                      command=engine_command(1), name="tiny")
    out = ev.evaluate(p)
    assert out["ok"], out["error"]
    assert ev.engine_runs == 3  # UCS, UCS again at max_strain 0.005, BTS
    assert ev.used_folder(p, "ucs").name == "ucs_long1" and ev.used_folder(p, "bts").name == "bts"
    long = json.loads(next((tmp_path / "work").rglob("ucs_long1/parsed/summary.json")).read_text())
    assert long["peak_reached"] is True and long["post_peak_drop_1"] >= 0.1
    assert 0.0025 < long["strain_at_peak_1"] < 0.005
    # the longer run's peak is the strength, above the cut run's lower bound
    assert out["ucs_Pa"] == pytest.approx(long["peak_stress_Pa"]) and out["ucs_Pa"] > cut["peak_stress_Pa"]


def test_results_table_names_the_bond_law_and_the_seed_scatter(tmp_path):
    """The issue-#3 table from the committed concrete card and its committed seed and speed studies."""
    import pandas as pd

    from deckgen.calibration_studies import results_table, scatter

    import shutil

    runs = ROOT / "docs" / "calibration_runs"
    studies = tmp_path  # the session-13 concrete card (crushed discs) with its own seed and speed studies
    for kind in ("seeds", "quasistatic"):
        shutil.copy(runs / f"{kind}_concrete_crushed.csv", studies / f"{kind}_concrete.csv")
    shutil.copy(runs / "seeds_savonniere_limestone_bpm.csv", studies / "seeds_savonniere_limestone.csv")
    text = results_table([runs / "concrete_flat_joint_crushed_card.yaml", MATERIALS / "cutting" / "savonniere_limestone.yaml"],
                         studies)
    concrete = next(ln for ln in text.splitlines() if ln.startswith("| concrete |"))
    limestone = next(ln for ln in text.splitlines() if ln.startswith("| savonniere_limestone |"))
    assert "| flat joint, β 0 |" in concrete and "| bpm/rotational |" in limestone
    assert concrete.startswith("| concrete | 0.8-1.333 | ") and limestone.startswith("| savonniere_limestone | 0.8-1.333 | ")
    s = scatter(pd.read_csv(studies / "seeds_concrete.csv"))
    card = load_card(runs / "concrete_flat_joint_crushed_card.yaml")
    assert f"{s['bts_Pa_mean'] / (card.targets.bts_MPa * 1e6) - 1:+.1%}" in concrete
    q = pd.read_csv(studies / "quasistatic_concrete.csv")
    assert f"{q['bts_change_at_half_speed_1'].iloc[1]:+.1%}" in concrete


# ------------------------------------------------------------------ split or crushed Brazilian discs
def test_a_point_with_crushed_discs_does_not_converge_and_the_card_says_so(tmp_path):
    """Stand-in whose discs crush (>20 % of bonds broken at the peak) above UCS/BTS ~8.9: concrete's 10.3 is met in
    numbers only with crushed discs, so the split check keeps the loop from calling it converged."""
    card = _card("concrete")
    start = analytic_start(card.targets)
    free = calibrate(StandInEvaluator(noise=0.0, crush_ratio=7.5), card.targets, start, tmp_path / "free.csv",
                     max_evals=30)
    assert free.converged and free.best.bts_broken > 0.2  # numbers met, discs crushed: the old verdict
    res = calibrate(StandInEvaluator(noise=0.0, crush_ratio=7.5), card.targets, start, tmp_path / "t.csv",
                    max_evals=30, card=card, card_path=tmp_path / "card.yaml", bts_max_broken=0.2)
    assert not res.converged and res.stop_reason in ("budget", "stalled")
    split = [ev for ev in res.evaluations if ev.ok and ev.bts_broken <= 0.2]
    assert split and res.best.bts_broken <= 0.2  # the best point is a split one
    assert abs(res.errors["ucs"]) > 0.05 or abs(res.errors["bts"]) > 0.05  # which cannot meet both strengths
    rows = read_table(tmp_path / "t.csv")
    assert [r["bts_broken_at_peak_1"] for r in rows] == pytest.approx([ev.bts_broken for ev in res.evaluations])
    written = load_card(tmp_path / "card.yaml")
    assert written.provenance.converged is False and written.provenance.bts_max_broken_at_peak == 0.2
    assert written.provenance.achieved.bts_broken_at_peak == pytest.approx(res.best.bts_broken, abs=1e-4)


def test_results_table_says_split_or_crushed_against_the_cards_limit():
    from deckgen.calibration_studies import _split_cell

    assert _split_cell(None, 0.2) == "peak: not recorded"
    assert _split_cell(0.634, 0.2) == "peak: 63% (crushed, limit 20%)"
    assert _split_cell(0.117, None) == "peak: 12% (split, limit 20%)"  # a card without a limit: the default
    assert _split_cell(0.25, 0.3) == "peak: 25% (split, limit 30%)"
    assert _split_cell(0.077, 0.2, "split") == "split: 8% (split, limit 20%)"


def test_split_check_passes_a_rock_whose_ratio_needs_no_crushing(tmp_path):
    card = _card("savonniere_limestone")  # UCS/BTS 9.2: 0.1 (9.2 / 10)^4 = 7 % broken at the peak
    res = calibrate(StandInEvaluator(noise=0.0, crush_ratio=10.0), card.targets, analytic_start(card.targets),
                    tmp_path / "t.csv", max_evals=30, bts_max_broken=0.2)
    assert res.converged and res.best.bts_broken < 0.2


def test_a_calibrated_card_calibrates_on_its_setup_base_not_on_its_result():
    """Re-running a calibrated card must find the runs its calibration recorded: same base, same setup key."""
    from deckgen.calibrate import quasi_static_specimens, setup_base

    card = _card("sandstone")
    assert card.calibrated is not None
    bare = card.model_copy(update={"calibrated": None})
    assert setup_base(card) == bare.case_overrides() != card.case_overrides()
    ucs, bts = quasi_static_specimens(card)
    keys = {DemEvaluator(b, ucs, bts, "unused").setup_key for b in (setup_base(card), setup_base(bare))}
    assert len(keys) == 1


def test_an_inactive_crushing_penalty_does_not_shrink_the_step(tmp_path):
    """A model that is exactly the split prior (log-linear) and whose discs always split (5 % broken): the first
    step is the Gauss-Newton step and lands on the targets. With the penalty's prior row kept while the penalty was
    inactive, the first step moved sigma_c +3 % instead of +18 % (the fine-sandstone calibration, session 16)."""
    from deckgen.calibrate import SPLIT_PRIOR, prior_jacobian

    card = _card("sandstone")
    space = ParameterSpace(["log_E_b", "log_sigma_c", "log_tau_ratio"])
    J = prior_jacobian(space, "flat_joint_split")
    start = MicroParams(youngs_modulus_GPa=15.1468, tensile_strength_MPa=5.75284, shear_strength_MPa=32.139,
                        gap_tolerance=0.4, contact_modulus_ratio=4.0, flat_joint=1, joint_friction=1.0,
                        moment_contribution=0.0)
    x0 = space.to_vector(start)
    t = card.targets.as_pa()
    r0 = np.log([1.133, 0.835, 1.069])  # the fine sandstone's first evaluation: +13.3 %, -16.5 %, +6.9 %

    class Linear:
        measures_split = True
        bts_reading = "split"

        def evaluate(self, p):
            r = r0 + J @ (space.to_vector(p) - x0)
            return {"ok": True, "ucs_Pa": t["ucs"] * math.exp(r[0]), "bts_Pa": t["bts"] * math.exp(r[1]),
                    "E_Pa": t["E"] * math.exp(r[2]), "bts_broken_at_peak_1": 0.05}

    assert set(SPLIT_PRIOR) >= set(space.names)  # the penalty row has entries in every moving parameter
    res = calibrate(Linear(), card.targets, start, tmp_path / "t.csv", max_evals=6, space=space, prior=J,
                    bts_max_broken=0.2)
    assert res.converged and len(res.evaluations) == 2
    step = res.best.params.tensile_strength_MPa / start.tensile_strength_MPa - 1
    assert step == pytest.approx(0.18, abs=0.02)  # trf's first step: most of the Gauss-Newton +19.6 %


def test_resolution_table_orders_by_grain_size_and_gives_ratios_to_the_coarse_card(tmp_path):
    from deckgen.calibrate import write_card
    from deckgen.calibration_studies import resolution_table

    coarse_path = ROOT / "docs" / "calibration_runs" / "sandstone_coarse_card.yaml"
    coarse = load_card(coarse_path)
    bonds = {**coarse.calibrated.bonds, "youngs_modulus_GPa": coarse.calibrated.bonds["youngs_modulus_GPa"] * 1.1}
    fine = coarse.model_copy(update={
        "calibrated": coarse.calibrated.model_copy(update={"bonds": bonds}),
        "provenance": coarse.provenance.model_copy(update={"radius_min_mm": 0.6, "radius_max_mm": 1.0})})
    write_card(fine, tmp_path / "fine.yaml")
    text = resolution_table([tmp_path / "fine.yaml", coarse_path])  # fine given first
    rows = [ln for ln in text.splitlines() if ln.startswith("| sandstone")]
    assert len(rows) == 2
    assert rows[0].startswith("| sandstone | 0.8-1.333 | 7.5 | 9.4 |") and "(×1.000)" in rows[0]
    assert rows[1].startswith("| sandstone | 0.6-1 | 10.0 | 12.5 |")
    assert f"{bonds['youngs_modulus_GPa']:.4g} (×1.100)" in rows[1] and rows[1].count("(×1.000)") == 2
    bare = fine.model_copy(update={"provenance": fine.provenance.model_copy(update={"radius_min_mm": None})})
    write_card(bare, tmp_path / "bare.yaml")
    with pytest.raises(CardError, match="radius_min_mm.*fix: re-run"):
        resolution_table([tmp_path / "bare.yaml"])


def test_analytic_start_leaves_fixed_fields_at_their_defaults():
    """Only the optimiser's parameters are moved inside their bounds: the twisting factor's bound is its default 1,
    and a margin on it put twisting_strength_factor 1.0009 into every start's key and deck."""
    for table in ("ratio", "high_strain"):
        p = analytic_start(_card("savonniere_limestone").targets, table=table)
        assert p.twisting_strength_factor == 1.0 and p.bending_strength_factor == 1.0
        assert "twisting" not in json.dumps(p.overrides())
    space = ParameterSpace(["log_E_b", "log_sigma_c", "log_twisting_factor"])
    p = analytic_start(_card("savonniere_limestone").targets, space=space)
    assert 1.0 < p.twisting_strength_factor < 1.01  # free: strictly inside its bounds for least_squares


def test_resolution_setups_are_the_recorded_calibrations():
    """cases/materials/{coarse,fine}/<rock>.yaml is what docs/calibration_runs/<rock>_{coarse,fine}_card.yaml was
    calibrated from, and differs from the rock's card only in the grain size (and the start and budget)."""
    setups = sorted((MATERIALS / "fine").glob("*.yaml")) + sorted((MATERIALS / "coarse").glob("*.yaml"))
    assert {(p.parent.name, p.stem) for p in setups} >= {("coarse", "sandstone"), ("fine", "colorado_red_granite")}
    for path in setups:
        setup = load_card(path)
        recorded = load_card(ROOT / "docs" / "calibration_runs" / f"{setup.rock}_{path.parent.name}_card.yaml")
        assert setup.calibrated is None and setup.calibration == recorded.calibration
        card = _card(setup.rock)
        assert setup.targets == card.targets
        same = {"start", "max_evals", "base"}
        assert setup.calibration.model_dump(exclude=same) == card.calibration.model_dump(exclude=same)
        r, card_r = setup.calibration.base["packing"], card.calibration.base["packing"]
        finer = path.parent.name == "fine"
        assert (r["radius_max_mm"] < card_r["radius_max_mm"]) == finer and r["radius_max_mm"] != card_r["radius_max_mm"]
        assert recorded.provenance.radius_max_mm == r["radius_max_mm"] and recorded.provenance.converged


def test_sandstone_card_is_its_fine_resolution_calibration():
    """Since session 17 the sandstone card is the one calibrated at r 0.6-1.0 mm (quasi-static to 3 %; the coarse one
    was not): the same card as the resolution record."""
    card = _card("sandstone")
    assert card == load_card(ROOT / "docs" / "calibration_runs" / "sandstone_fine_card.yaml")
    assert card.provenance.converged and card.provenance.radius_max_mm == 1.0


def test_study_point_of_a_flat_joint_card_carries_its_bond_law():
    from deckgen.calibration_studies import _card_setup

    _, p, base, _, _ = _card_setup(MATERIALS / "sandstone.yaml")
    assert (p.flat_joint, p.joint_friction, p.moment_contribution) == (1, 1.0, 0.0)
    assert p.overrides()["bonds"]["model"] == base["bonds"]["model"] == "flat_joint"
    _, p, _, _, _ = _card_setup(MATERIALS / "cutting" / "savonniere_limestone.yaml")
    assert p.flat_joint == 0 and "model" not in p.overrides()["bonds"]


def test_micro_params_from_overrides_inverts_overrides():
    """A calibrated card's bonds/contact blocks back to the point they came from, the bond law included."""
    from dataclasses import replace

    fj = MicroParams(youngs_modulus_GPa=14.9, tensile_strength_MPa=6.1, shear_strength_MPa=31.7, gap_tolerance=0.4,
                     contact_modulus_ratio=4.0, flat_joint=1, joint_friction=1.0, moment_contribution=0.0, face_sectors=3)
    clumps = replace(fj, flat_joint=0, joint_friction=0.5, moment_contribution=1.0, face_sectors=1, clump_size=8,
                     clump_strength_factor=50.0, twisting_strength_factor=2.0)
    for p in (fj, clumps):
        o = p.overrides()
        back = MicroParams.from_overrides(o["bonds"], o["contact"])
        assert back.key() == p.key() and back.contact_modulus_ratio == pytest.approx(p.contact_modulus_ratio)
        assert (back.flat_joint, back.joint_friction, back.face_sectors) == (p.flat_joint, p.joint_friction, p.face_sectors)


def test_recorded_half_speed_check_of_the_granite_cutting_card():
    """docs/calibration_runs/quasistatic_colorado_red_granite_bpm_cutting.csv (session 25): the bpm granite cutting card's
    point (the same bond values as its new-packing study) at its platen speeds and at half of them, 3 cylinders and 8
    discs each. UCS +2.1 % and E +0.8 % at half speed meet the 3 % check; BTS -9.1 % is within the discs' scatter."""
    import pandas as pd

    runs = ROOT / "docs" / "calibration_runs"
    q = pd.read_csv(runs / "quasistatic_colorado_red_granite_bpm_cutting.csv")
    seeds = pd.read_csv(runs / "seeds_colorado_red_granite_bpm_cutting.csv")
    point = ["youngs_modulus_GPa", "tensile_strength_MPa", "shear_strength_MPa", "gap_tolerance", "friction"]
    assert np.allclose(q[point].to_numpy(float), seeds[point].iloc[[0, 0]].to_numpy(float), rtol=1e-6)
    assert q["ucs_packings"].tolist() == [3, 3] and q["bts_packings"].tolist() == [8, 8]
    assert q["ucs_speed_m_s"].iloc[1] / q["ucs_speed_m_s"].iloc[0] == pytest.approx(0.5, abs=1e-3)
    for col, key in (("ucs_Pa", "ucs"), ("bts_Pa", "bts"), ("E_Pa", "E")):
        assert q[f"{key}_change_at_half_speed_1"].iloc[1] == pytest.approx(q[col].iloc[1] / q[col].iloc[0] - 1, abs=1e-9)
    assert q[["ucs_change_at_half_speed_1", "bts_change_at_half_speed_1", "E_change_at_half_speed_1"]].iloc[1].tolist() == \
        pytest.approx([0.0208, -0.0909, 0.0078], abs=1e-4)
    # the BTS change is 0.7 of the standard error of a difference of two 8-disc means
    se = np.hypot(*(q["bts_cv_1"] / np.sqrt(8)))
    assert abs(q["bts_change_at_half_speed_1"].iloc[1]) / se == pytest.approx(0.7, abs=0.05)
