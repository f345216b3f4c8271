"""LAMMPS data files: write a bonded bpm/sphere specimen, read atoms and bonds back, bad lines fail with file:line."""

from __future__ import annotations

import numpy as np
import pytest

from deckgen.datafile import read_bonds, write_bpm_data
from deckgen.parse.common import ParseError


def test_bonds_round_trip(tmp_path):
    x = np.array([[0, 0, 0], [1e-3, 0, 0], [2e-3, 0, 0]], dtype=float)
    p = write_bpm_data(tmp_path / "s.data", title="t", box=np.array([[-1e-3, 3e-3]] * 3), types=np.ones(3),
                       radius=np.full(3, 5e-4), density=np.full(3, 2650.0), x=x, n_atom_types=1,
                       bonds=np.array([[0, 1], [1, 2]]), bond_types=np.array([1, 2]), n_bond_types=2)
    assert read_bonds(p).tolist() == [[1, 2], [2, 3]]  # 1-based atom ids
    text = p.read_text()
    assert "3 atoms" in text and "2 bonds" in text and "Atoms # bpm/sphere" in text
    # id molecule type diameter density x y z
    assert "2 0 1 1.000000000e-03 2.650000000e+03 1.000000000e-03" in text


def test_bad_bond_line_names_file_and_line(tmp_path):
    p = tmp_path / "bad.data"
    p.write_text("title\n\n2 atoms\n1 bonds\n\nBonds\n\n1 1 x 2\n")
    with pytest.raises(ParseError, match=r"bad\.data:8: non-integer atom id"):
        read_bonds(p)
