"""Where the bonds of a cutting block broke: the table damage_depth.csv of this folder.

Usage: python damage_depth.py LABEL=PARSED_DIR [LABEL=PARSED_DIR ...] > damage_depth.csv

PARSED_DIR is the output of `deckgen parse RUN_DIR --out PARSED_DIR` (its damage.csv: per grain, its position and
its bonds at the start and at the end of the run). For each run the script gives the broken bond ends in the top
6 mm of the block (the cut is 3.2 mm deep), in its lower half, and beyond |y| = 14 mm (outside the neighbour
grooves at +-12.5 mm), each as a share of all broken bond ends, with the share of the grains in the same region.
Written here (not in deckgen.parse) because it serves this one comparison. damage_depth.csv: session 19, the
90 000-step runs of lin_cardA_h24, lin_cardC_h24, lin_h24_w66, lin_cardC_h24_w66, lin_h24_nogrooves and
lin_cardC_h24_nogrooves, lin_cardC_h24_nogrooves_d05 and lin_cardC_h24_nogrooves_v05 (the whole truncated run,
not only the first event). Session 20 appended three runs of the 12 mm family block (whose top 6 mm is half of
it): the card on the family packing (the family case itself) and with grains r 0.35-0.5 mm on two packings
(lin_fine_grains.yaml, lin_fine_grains_seed202.yaml).
"""
import sys

import pandas as pd

rows = []
for arg in sys.argv[1:]:
    label, _, folder = arg.partition("=")
    d = pd.read_csv(f"{folder}/damage.csv")
    z_mm, abs_y_mm = d["z_m"] * 1e3, d["y_m"].abs() * 1e3
    broken = d["bonds_initial"] - d["bonds_final"]
    top = z_mm > z_mm.max() - 6.0
    lower = z_mm < 0.5 * (z_mm.min() + z_mm.max())
    outer = abs_y_mm >= 14.0
    row = {"run": label, "grains": len(d), "broken_bond_ends": int(broken.sum()),
           "block_height_mm": round(float(z_mm.max() - z_mm.min()), 1)}
    for name, mask in (("top_6mm", top), ("lower_half", lower), ("abs_y_ge_14mm", outer)):
        row[f"broken_share_{name}_1"] = round(float(broken[mask].sum() / broken.sum()), 3)
        row[f"grain_share_{name}_1"] = round(float(mask.mean()), 3)
    rows.append(row)
pd.DataFrame(rows).to_csv(sys.stdout, index=False)
