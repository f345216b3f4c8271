"""Give a rendered flat-joint cutting run an unbreakable base (session 20 diagnostic).

Usage: python frame_base.py RUN_DIR DEPTH_MM [TOP_MM]

Every bond whose two grains both lie more than DEPTH_MM below the block top (TOP_MM, default the highest grain
centre) gets a new bond type whose tensile strength and cohesion are 10^6 times the deck's, so the base stays
elastic while the top zone can break. The script edits RUN_DIR/specimen.data (the bond types) and RUN_DIR/in.deck
(one more bond_coeff line; nsteps cut to 90 000), and prints how many bonds it retyped. Written here, not as a case
field, because it serves this one test: does the top zone break up when the block below cannot fail as a whole?
Runs: lin_frame_ranks2.yaml and lin_cardC_frame_ranks2.yaml, each with `python frame_base.py RUN_DIR 6.4 12`.
"""
import re
import sys
from pathlib import Path

from deckgen.datafile import iter_section

run, depth = Path(sys.argv[1]), float(sys.argv[2]) * 1e-3
# rock grains (type 1) of the bpm/sphere Atoms section: id mol type diameter density x y z
z = {int(f[0]): float(f[7]) for _, f in iter_section(run / "specimen.data", "Atoms") if f[2] == "1"}
lines = (run / "specimen.data").read_text().splitlines()
i_bonds = lines.index("Bonds")
top = float(sys.argv[3]) * 1e-3 if len(sys.argv) > 3 else max(z.values())
z_cut = top - depth
i_types = next(k for k, line in enumerate(lines) if line.endswith("bond types"))
new = int(lines[i_types].split()[0]) + 1
lines[i_types] = f"{new} bond types"
retyped = total = 0
for k in range(i_bonds + 2, len(lines)):
    f = lines[k].split()
    if len(f) != 4:
        break
    total += 1
    a, b = int(f[2]), int(f[3])
    if a in z and b in z and z[a] < z_cut and z[b] < z_cut:
        lines[k] = f"{f[0]} {new} {a} {b}"
        retyped += 1
(run / "specimen.data").write_text("\n".join(lines) + "\n")
deck = (run / "in.deck").read_text()
m = re.search(r"^bond_coeff\s+\* (.*)$", deck, re.M)
c = m.group(1).split()  # E_b, k_n/k_s, radius multiplier, sigma_c, c, mu, damping, beta[, ...]
c[3], c[4] = repr(float(c[3]) * 1e6), repr(float(c[4]) * 1e6)
deck = deck.replace(m.group(0), m.group(0) + f"\nbond_coeff      {new} {' '.join(c)}   # frame_base.py: unbreakable base", 1)
deck = re.sub(r"^variable nsteps\s+index \d+", "variable nsteps             index 90000 ", deck, flags=re.M)
(run / "in.deck").write_text(deck)
print(f"top z {top * 1e3:.2f} mm, base below z {z_cut * 1e3:.2f} mm: {retyped} of {total} bonds made type {new}")
