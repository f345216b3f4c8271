"""Case files of the toughness diagnostic (session 21): a Brazilian disc and a cracked one per granite card.

Usage: python make_cases.py OUT_DIR [PACKING_SEED] [CARD ...]   (coarse, fine, card_a, card_c; default coarse fine)

For each calibrated granite card (the coarse one, grains r 0.8-1.333 mm, cases/materials/colorado_red_granite.yaml,
and the fine one, r 0.6-1.0 mm, docs/calibration_runs/colorado_red_granite_fine_card.yaml) it writes the case that
the card's calibration runs as its Brazilian test (same bonds, contact, packing, jaws, platen speed from
loading_transits, stop rule), but on a disc of 40 mm diameter and 10 mm thickness instead of 20 x 10 mm, so that a
central crack of 2a = 16 mm (a/R = 0.4) spans 6-10 grain diameters. The crack itself is cut by notch.py after
rendering (a case file cannot name bonds). Written here, not as a specimen kind, because it serves this one question:
the bonded granite's fracture toughness at the two grain sizes (docs/families.md, "The fracture toughness of the
granite cards").
With PACKING_SEED the same cases on another packing, named kic_<card>_s<seed> (0: the cards' own seed).
The cards card_a and card_c (A and C in docs/families.md) are the granite cards calibrated without the intact bond's
friction (docs/families.md, "Why the calibrated granite breaks up the reduced block"): same grains and targets as the
coarse card, cohesion 140 and 126 MPa instead of 70. CARD@D (e.g. coarse@80) writes a disc of D mm instead of 40,
named kic_<card>_d<D>[_s<seed>] (the size effect of the intact disc).
"""
import sys
from pathlib import Path

import yaml

from deckgen.calibrate import DemEvaluator
from deckgen.calibration_studies import _card_setup
from deckgen.spec import deep_merge

ROOT = Path(__file__).resolve().parents[3]
CARDS = {"coarse": ROOT / "cases/materials/colorado_red_granite.yaml",
         "fine": ROOT / "docs/calibration_runs/colorado_red_granite_fine_card.yaml",
         "card_a": ROOT / "docs/calibration_runs/colorado_red_granite_joint_friction0_card.yaml",
         "card_c": ROOT / "docs/calibration_runs/colorado_red_granite_intact_friction0_face0p5_card.yaml"}
out = Path(sys.argv[1])
seed = int(sys.argv[2]) if len(sys.argv) > 2 and sys.argv[2] != "0" else None
chosen = [arg.partition("@") for arg in sys.argv[3:] or ["coarse", "fine"]]
unknown = sorted({label for label, _, _ in chosen} - set(CARDS))
if unknown:
    raise SystemExit(f"make_cases.py: unknown card(s) {unknown} (fix: choose from {sorted(CARDS)})")
out.mkdir(parents=True, exist_ok=True)
for label, _, diameter in chosen:
    path = CARDS[label]
    card, p, base, ucs, bts = _card_setup(path)
    if seed is not None:
        base = deep_merge(base, {"packing": {"seed": seed}})
    disc = {**bts, "diameter_mm": float(diameter or 40.0), "thickness_mm": 10.0}
    ev = DemEvaluator(base, ucs, disc, out / "unused", name=f"kic_{label}", bts_reading=card.calibration.bts_reading)
    case = ev.case(p, "bts")
    name = f"kic_{label}" + (f"_d{float(diameter):g}" if diameter else "") + ("" if seed is None else f"_s{seed}")
    data = case.model_dump(mode="json", exclude_defaults=True)
    data["name"] = name
    data["specimen"] = {"kind": "brazilian_disc", **data["specimen"]}  # a default, but the discriminator
    head = (f"# toughness diagnostic (docs/families_runs/toughness_diag/make_cases.py): the Brazilian test of\n"
            f"# {path.relative_to(ROOT)} on a {disc['diameter_mm']:g} x 10 mm disc; notch.py cuts the crack after "
            f"rendering.\n")
    (out / f"{name}.yaml").write_text(head + yaml.safe_dump(data, sort_keys=False, width=120))
    print(out / f"{name}.yaml", case.packing.seed, disc)
