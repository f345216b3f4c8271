"""LAMMPS data files: read the atoms a packing run wrote, write bonded specimens.

Written here because the files are small and the format narrow (``atom_style sphere`` and
``bpm/sphere`` atoms, bonds); the readers stream line by line and fail with file and line.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from deckgen.parse.common import ParseError, open_text


@dataclass
class Atoms:
    """Grains: ids (1-based), types, radii [m], densities [kg/m^3], positions [m]."""

    ids: np.ndarray
    types: np.ndarray
    radius: np.ndarray
    density: np.ndarray
    x: np.ndarray
    box: np.ndarray = field(default_factory=lambda: np.zeros((3, 2)))

    @property
    def mass(self) -> np.ndarray:
        return self.density * 4.0 / 3.0 * np.pi * self.radius**3

    def __len__(self) -> int:
        return len(self.ids)


def iter_section(path: Path, name: str):
    """Yield (line number, fields) of the data-file section ``name`` (e.g. "Atoms", "Bonds"), streamed."""
    inside = False
    with open_text(path) as fh:
        for lineno, raw in enumerate(fh, 1):
            line = raw.split("#", 1)[0].strip()
            if not line:
                continue
            if not inside:
                inside = line == name
                continue
            if line[0].isalpha():
                return
            yield lineno, line.split()


def read_sphere_data(path: str | Path) -> Atoms:
    """Read the Atoms section of a data file written by ``write_data`` with atom_style sphere.

    Columns: id type diameter density x y z [ix iy iz].
    """
    path = Path(path)
    natoms = None
    box = np.zeros((3, 2))
    with open_text(path) as fh:  # header, up to the first section (line 1 is a free-text title)
        next(fh, None)
        for raw in fh:
            parts = raw.split("#", 1)[0].split()
            if not parts:
                continue
            if parts[0][0].isalpha():
                break
            if len(parts) == 2 and parts[1] == "atoms":
                natoms = int(parts[0])
            elif len(parts) == 4 and parts[2][1:] == "lo" and parts[3][1:] == "hi":
                box["xyz".index(parts[2][0])] = (float(parts[0]), float(parts[1]))
    if natoms is None:
        raise ParseError(path, 1, "no 'N atoms' header line")
    rows: list[list[float]] = []
    lineno = 1
    for lineno, parts in iter_section(path, "Atoms"):
        if len(parts) < 7:
            raise ParseError(path, lineno, f"atom line needs 7 columns (id type diameter density x y z), got {len(parts)}")
        try:
            rows.append([float(v) for v in parts[:7]])
        except ValueError:
            raise ParseError(path, lineno, "non-numeric value in atom line") from None
    if len(rows) != natoms:
        raise ParseError(path, lineno, f"header says {natoms} atoms, Atoms section has {len(rows)}")
    a = np.array(rows)
    a = a[np.argsort(a[:, 0])]
    return Atoms(
        ids=a[:, 0].astype(np.int64),
        types=a[:, 1].astype(np.int64),
        radius=a[:, 2] / 2.0,
        density=a[:, 3],
        x=a[:, 4:7],
        box=box,
    )


def read_bonds(path: str | Path) -> np.ndarray:
    """Atom-id pairs of the Bonds section of a data file (streamed), as an (n, 2) array."""
    path = Path(path)
    pairs: list[tuple[int, int]] = []
    for lineno, parts in iter_section(path, "Bonds"):
        if len(parts) != 4:
            raise ParseError(path, lineno, f"bond line needs 4 columns (id type atom1 atom2), got {len(parts)}")
        try:
            pairs.append((int(parts[2]), int(parts[3])))
        except ValueError:
            raise ParseError(path, lineno, "non-integer atom id in bond line") from None
    return np.asarray(pairs, dtype=np.int64).reshape(-1, 2)


def write_bpm_data(
    path: str | Path,
    *,
    title: str,
    box: np.ndarray,
    types: np.ndarray,
    radius: np.ndarray,
    density: np.ndarray,
    x: np.ndarray,
    n_atom_types: int,
    bonds: np.ndarray,
    bond_types: np.ndarray,
    n_bond_types: int,
    extra_bond_per_atom: int = 0,
) -> Path:
    """Write an ``atom_style bpm/sphere`` data file (id molecule type diameter density x y z).

    ``bonds`` holds 0-based atom indices; bond reference states are set by LAMMPS at the first
    run, from these positions.
    """
    path = Path(path)
    n = len(radius)
    per_atom = np.bincount(bonds.ravel(), minlength=n).max() if len(bonds) else 0
    with open(path, "w") as fh:
        fh.write(f"{title}\n\n")
        fh.write(f"{n} atoms\n{n_atom_types} atom types\n")
        fh.write(f"{len(bonds)} bonds\n{n_bond_types} bond types\n")
        fh.write(f"{int(per_atom) + extra_bond_per_atom} extra bond per atom\n\n")
        for k, ax in enumerate("xyz"):
            fh.write(f"{box[k, 0]:.9e} {box[k, 1]:.9e} {ax}lo {ax}hi\n")
        fh.write("\nAtoms # bpm/sphere\n\n")
        for i in range(n):
            fh.write(
                f"{i + 1} 0 {int(types[i])} {2.0 * radius[i]:.9e} {density[i]:.9e} "
                f"{x[i, 0]:.9e} {x[i, 1]:.9e} {x[i, 2]:.9e}\n"
            )
        if len(bonds):
            fh.write("\nBonds\n\n")
            for k, ((i, j), t) in enumerate(zip(bonds, bond_types)):
                fh.write(f"{k + 1} {int(t)} {int(i) + 1} {int(j) + 1}\n")
    return path
