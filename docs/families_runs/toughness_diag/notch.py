"""Cut a central straight crack into a rendered Brazilian disc (session 21 toughness diagnostic).

Usage: python notch.py RUN_DIR HALF_LENGTH_MM

The disc's axis is y and the jaws load it along z (deckgen's brazilian_disc). The crack lies in the plane x = x_c
through the disc's centre (x_c, z_c: the middle of the grains' extent), along the loaded diameter, over
|z - z_c| < a, through the whole thickness: every bond whose two grains lie on opposite sides of that plane and whose
midpoint is within a of the centre is deleted from RUN_DIR/specimen.data. Loaded along its plane, this is the
cracked straight-through Brazilian disc (CSTBD) of Atkinson et al. (1982), in mode I. Prints the centre, the
deleted bonds and the grains the crack faces touch. Written here, not as a specimen kind, because it serves this
one diagnostic (docs/families.md, "The fracture toughness of the granite cards").
"""
import sys
from pathlib import Path

from deckgen.datafile import iter_section

run, a = Path(sys.argv[1]), float(sys.argv[2]) * 1e-3
data = run / "specimen.data"
# rock grains (type 1) of the bpm/sphere Atoms section: id mol type diameter density x y z
pos = {int(f[0]): (float(f[5]), float(f[7])) for _, f in iter_section(data, "Atoms") if f[2] == "1"}
xs, zs = [p[0] for p in pos.values()], [p[1] for p in pos.values()]
xc, zc = 0.5 * (min(xs) + max(xs)), 0.5 * (min(zs) + max(zs))
kept, cut, faces = [], 0, set()
for _, f in iter_section(data, "Bonds"):
    i, j = int(f[2]), int(f[3])
    (xi, zi), (xj, zj) = pos[i], pos[j]
    if (xi - xc) * (xj - xc) < 0 and abs(0.5 * (zi + zj) - zc) < a:
        cut += 1
        faces.update((i, j))
        continue
    kept.append(f"{len(kept) + 1} {f[1]} {i} {j}")
lines = data.read_text().splitlines()
i_bonds = lines.index("Bonds")
total = len(kept) + cut
i_count = next(k for k, line in enumerate(lines) if line.endswith(" bonds"))
lines[i_count] = f"{len(kept)} bonds"
lines = lines[:i_bonds + 2] + kept
data.write_text("\n".join(lines) + "\n")
print(f"centre x {xc * 1e3:.3f} mm, z {zc * 1e3:.3f} mm (R {0.5 * (max(zs) - min(zs)) * 1e3:.2f} mm to grain centres); "
      f"crack 2a = {2 * a * 1e3:.1f} mm: {cut} of {total} bonds deleted, {len(faces)} grains on its faces")
