"""Where the front of the contact chord is, along the reduced rotary path, relative to the block's faces (session 27).

The reduced rotary cases (cases/rotary/reduced) start the disc centre at x = -(half chord + clearance), so the front of
the chord (a half chord ahead of the centre along the heading, at the block top) touches the block face x = 0 at the
start; the centre runs on a circle of radius r about (x_start, r) and the disc yaws with it. The path is the deck's
own: deckgen.deck.cutter_path and cutter_world_points (the motion of the deck's ``fix move variable`` block), with the
chord front carried as a point fixed to the cutter that does not spin.
The block's xmax face is held fixed: grains within 2 r_max (1.96 mm for r_max 0.98 mm) of x = L. This prints, for
each case given (default: the four radii of packing 12345 and the 40 mm block diagnostics), the distance from the
chord front to the fixed grains and to the free side face y = W/2 at fractions of the travel, and how far the chord
front stands outside the path circle (the groove the front cuts lies that much outward of the one the disc bottom runs
in: the groove is wider than the tip by about this much), in mm and in tip widths. The offset is the same all along
the travel; to first order it is (half chord)^2 / 2r.

    python docs/families_runs/rotary_fixed_face.py [case.yaml ...]
"""
from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

from deckgen.deck import cutter_path, cutter_world_points
from deckgen.spec import MM, Case, load_case

ROOT = Path(__file__).resolve().parents[2]
FIXED_SLAB_MM = 2 * 0.982  # 2 r_max of the packings (the decks' fix_xmax region: x >= L - 1.964 mm)
FRACTIONS = (0.3, 0.65, 1.0)


def front_path(case: Case, f: float) -> tuple[float, float, float]:
    """(x, y, heading deg) of the chord front at fraction ``f`` of the travel, in mm (block face x = 0, centre line y = 0)."""
    path = cutter_path(case, case.cutter.diameter_mm * MM / 2)
    half_chord = -path["xc0"] - case.kinematics.start_clearance_mm * MM  # the deck starts the front at the clearance
    t = f * path["duration"]
    front = cutter_world_points(np.array([[half_chord, 0.0, 0.0]]), {**path, "spin_rate": 0.0}, t)[0]
    return front[0] / MM, front[1] / MM, math.degrees(path["yaw_rate"] * t)


def groove_offset_mm(case: Case) -> float:
    """Distance (mm) by which the chord front stands outside the rotary path circle (0 for a straight cut)."""
    path = cutter_path(case, case.cutter.diameter_mm * MM / 2)
    if not path["rotary_radius"]:
        return 0.0
    x, y, _ = front_path(case, 0.5)
    return math.hypot(x * MM - path["axis_x"], y * MM - path["axis_y"]) / MM - path["rotary_radius"] / MM


def main(paths: list[str]) -> None:
    if not paths:
        paths = [str(ROOT / "cases" / "rotary" / "reduced" / f"rot_red_r{r}.yaml") for r in (250, 500, 1000, 3000)]
        paths += sorted(str(p) for p in (ROOT / "docs" / "families_runs" / "rotary_block40").glob("diagnostic_*_k606_*.yaml"))
    print("case, block L mm, " + ", ".join(f"at {f:g}: gap to fixed grains mm / gap to free side mm / yaw deg" for f in FRACTIONS)
          + ", groove offset")
    for p in paths:
        case = load_case(p)
        L, W = case.specimen.length_mm, case.specimen.width_mm
        cells = []
        for f in FRACTIONS:
            x, y, yaw = front_path(case, f)
            cells.append(f"{L - FIXED_SLAB_MM - x:5.1f} / {W / 2 - y:5.1f} / {yaw:4.1f}")
        off = groove_offset_mm(case)
        cells.append(f"front outside the path {off:.2f} mm = {off / case.cutter.tip_width_mm:.2f} tip widths")
        print(f"{case.name}, {L:g}, " + ", ".join(cells))


if __name__ == "__main__":
    main(sys.argv[1:])
