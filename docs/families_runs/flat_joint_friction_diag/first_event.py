"""First fracture event of truncated cutting runs: the table first_event.csv of this folder.

Usage: python first_event.py LABEL=PARSED_DIR [LABEL=PARSED_DIR ...] > first_event.csv

PARSED_DIR is the output of `deckgen parse RUN_DIR --out PARSED_DIR` (its timeseries.csv: the deck's series, every
100 steps, with named columns). For each run the script reports where the cutter first pushes more than 50 N, the
peak |F| over the first 2 mm after it and over the run, and the fraction of the initial bonds broken 0.5, 1 and
2 mm of cutter travel after that first contact and at the end of the (truncated) run. Written here (not in
deckgen.parse) because it serves this one comparison. The session-18 rows were made by an earlier version that
read the same three quantities (cutter x, force components, intact bonds) from RUN_DIR/series.txt by column index.

The first 16 rows were written in session 18 (their run folders are not kept); the last eight in session 19: the
24 mm blocks with the cards A and C (lin_cardA_h24.yaml, lin_cardC_h24.yaml), the 24 mm x 66 mm blocks with the
card and card C (lin_h24_w66.yaml, lin_cardC_h24_w66.yaml) and the 24 mm blocks without neighbour grooves
(lin_h24_nogrooves.yaml, lin_cardC_h24_nogrooves.yaml; with card C also at bond damping 0.5 and at 0.5 m/s,
lin_cardC_h24_nogrooves_d05.yaml, lin_cardC_h24_nogrooves_v05.yaml), appended with
`python first_event.py LABEL=PARSED_DIR ... | tail -n +2 >> first_event.csv`. Their packing has 22 677 initial bonds
against 22 638 in the session-18 24 mm runs; lin_h24.yaml, rendered again in session 19, also gives 22 677, so the
session-18 24 mm packing differed by 0.2 % of its bonds. Session 20 traced it: session 18 packed on 1 MPI rank and session
19 on 2 (the packing then took the run's ranks); those eight case files now set packing.ranks: 2.

Nine rows from session 20 (the family case lin_red_s100_p6p4, 12 mm block) follow: the card packed on 2 ranks
(lin_ranks2.yaml) and on packing seed 202 (lin_seed202.yaml), card C on the family packing (lin_cardC.yaml), the card
with moment_contribution 1 and with faces of 4 elements (lin_beta1_ranks2.yaml, lin_elem4_ranks2.yaml), and the card and
card C with an unbreakable base below 6.4 mm (lin_frame_ranks2.yaml, lin_cardC_frame_ranks2.yaml; frame_base.py).
Then two with grains r 0.35-0.5 mm on two packings (lin_fine_grains.yaml, lin_fine_grains_seed202.yaml; 175 000 steps).
The first granite row (the card, 1-rank packing) was reproduced exactly by the family case rendered in session 20.
The last five rows (session 22) are the linear trend cases with the bpm/rotational cutting card
(cases/materials/cutting/colorado_red_granite.yaml), full runs of the family cases through Snakemake.
"""
import sys

import numpy as np
import pandas as pd

rows = []
for arg in sys.argv[1:]:
    label, _, folder = arg.partition("=")
    ts = pd.read_csv(f"{folder}/timeseries.csv")
    x_mm = ts["cutter_x_m"].to_numpy() * 1e3
    force = ts["force_magnitude_N"].to_numpy()
    bonds = ts["bonds_intact"].to_numpy(dtype=float)
    hit = np.flatnonzero(force > 50.0)
    if hit.size == 0:
        raise SystemExit(f"{folder}/timeseries.csv: the cutter never pushes 50 N")
    x0 = x_mm[hit[0]]
    row = {"run": label, "bonds_initial": int(bonds[0]), "x_first_contact_mm": round(x0, 2),
           "force_magnitude_N_peak_2mm_after_contact": round(float(force[(x_mm >= x0) & (x_mm <= x0 + 2.0)].max()), 1),
           "force_magnitude_N_peak": round(float(force.max()), 1)}
    for after in (0.5, 1.0, 2.0):
        i = int(np.argmin(abs(x_mm - (x0 + after))))
        row[f"broken_fraction_{after:g}mm_after_contact_1"] = round(1 - bonds[i] / bonds[0], 3)
    row["x_end_mm"] = round(float(x_mm[-1]), 2)
    row["broken_fraction_end_1"] = round(1 - bonds[-1] / bonds[0], 3)
    row["steps"] = int(ts["step"].iloc[-1])
    rows.append(row)
pd.DataFrame(rows).to_csv(sys.stdout, index=False)
