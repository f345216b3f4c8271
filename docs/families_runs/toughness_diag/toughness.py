"""Readings of the toughness diagnostic's Brazilian discs: the table toughness.csv of this folder.

Usage: python toughness.py LABEL=PARSED_DIR=A_MM [...] > toughness.csv   (A_MM: crack half-length, 0 for an intact disc)

PARSED_DIR is `deckgen parse RUN_DIR --out PARSED_DIR` of a 40 mm disc: timeseries.csv (nominal stress 2P/(pi D t),
strain, broken bonds counted from the rendered case's bonds, so a cracked disc starts with its deleted bonds) and
summary.json. Per run:
- stress_onset: the nominal stress when 0.3 % of the disc's bonds have broken in the test (damage begins);
- stress_split: deckgen's split reading (summary.json split_stress_Pa, deckgen.results.split_onset), the reading the
  granite cards' Brazilian strength was calibrated with: the largest stress up to the sample where a diametral
  crack's worth of bonds near the loaded diameter has broken. A cracked disc has fewer bonds left there, so its count
  includes bonds off the line (split_localisation_1 about 0.4 instead of 0.8);
- the fraction of the disc's bonds broken in the test by the split;
- for a cracked disc, K_I = N_I sigma sqrt(pi a) at both readings: the cracked straight-through Brazilian disc loaded
  along its crack (Atkinson, Smelser and Sanchez 1982, Int J Fract 18, 279-291; the leading term is the centre's
  tension 2P/(pi D t) x sqrt(pi a)), with the geometry factor N_I of their tables for the loading angle 0: about
  1.06 at a/R = 0.4 and 1.15 at a/R = 0.6 (the disc's R is 20 mm).
The later rise of the load, while the jaws crush the split halves, is not read.
toughness.csv (session 21): 29 runs, rendered with `deckgen render CASE --out RUN --ranks 1` and run with
`deckgen run RUN --ranks 1`. Per card (coarse, fine, card_a, card_c): the packings 12345 (kic_<card>.yaml), 202 and
303 (kic_<card>_s<seed>.yaml), each intact and after `python notch.py RUN 8`; for coarse and fine also
kic_<card>.yaml after `python notch.py RUN 12`. Then the rows of cards A and C, and last three intact 80 mm discs of
the coarse card (kic_coarse_d80[_s<seed>].yaml; their decks' nchunks cut to 46 by hand, past the split).
Written here, not in deckgen.parse, because it serves this one diagnostic.
"""
import json
import math
import sys
from pathlib import Path

import numpy as np
import pandas as pd

R_M = 0.020
N_I = {0.4: 1.06, 0.6: 1.15}
ONSET_FRACTION = 0.003
rows = []
for arg in sys.argv[1:]:
    label, folder, a_mm = arg.split("=")
    a = float(a_mm) * 1e-3
    ts = pd.read_csv(f"{folder}/timeseries.csv")
    summary = json.loads(Path(folder, "summary.json").read_text())
    s, e, b = ts["stress_Pa"].to_numpy(), ts["strain_1"].to_numpy(), ts["bonds_broken"].to_numpy()
    n0 = float(ts["bonds_intact"].iloc[0])
    i_onset = int(np.argmax(b - b[0] >= ONSET_FRACTION * n0))
    i_split = int(np.flatnonzero(ts["step"].to_numpy() == summary["split_step"])[0])
    row = {"run": label, "crack_half_length_mm": float(a_mm), "bonds_initial": int(n0), "bonds_deleted": int(b[0]),
           "stress_onset_Pa": round(float(s[i_onset]), -3), "strain_onset_1": round(float(e[i_onset]), 6),
           "stress_split_Pa": round(float(summary["split_stress_Pa"]), -3),
           "strain_split_1": round(float(summary["split_strain_1"]), 6),
           "broken_fraction_split_1": round(float((b[i_split] - b[0]) / n0), 4),
           "split_localisation_1": round(float(summary["split_localisation_1"]), 2)}
    if a > 0:
        n_i = N_I[round(a / R_M, 1)]
        for key in ("onset", "split"):
            row[f"K_I_{key}_Pa_sqrt_m"] = round(n_i * row[f"stress_{key}_Pa"] * math.sqrt(math.pi * a), -3)
    rows.append(row)
pd.DataFrame(rows).to_csv(sys.stdout, index=False)
