"""Parallel-bond -> bpm/rotational mapping, radius-aware bonding, stable time step."""

from __future__ import annotations

import math

import numpy as np
import pytest

from deckgen.bonds import (
    bpm_coefficients,
    find_bond_pairs,
    make_bond_table,
    section,
    stable_timestep,
)

E, RATIO, SIG, TAU = 40e9, 2.5, 30e6, 60e6
RB, L = 0.8e-3, 1.6e-3


@pytest.fixture()
def c():
    return {k: float(v) for k, v in bpm_coefficients(E, RATIO, SIG, TAU, RB, L, 1e-5, 1e-12, 0.1).items()}


def lammps_B(c, f_r=0.0, f_s=0.0, t_b=0.0, t_t=0.0):
    """LAMMPS bpm/rotational breaking criterion (bond_bpm_rotational doc)."""
    return max(0.0, f_r / c["F_rc"] + abs(f_s) / c["F_sc"] + abs(t_b) / c["tau_bc"] + abs(t_t) / c["tau_tc"])


def test_stiffness_mapping_matches_parallel_bond(c):
    A, I, J = (float(v) for v in section(RB))
    assert A == pytest.approx(math.pi * RB**2)
    assert c["k_r"] == pytest.approx(E * A / L)            # F_n = (E/L) A du
    assert c["k_s"] == pytest.approx(E * A / L / RATIO)    # F_s = (E/L)/kappa A du
    assert c["k_t"] == pytest.approx(E * J / L / RATIO)    # M_t = k_s_bar J dtheta
    assert c["k_b"] == pytest.approx(E * I / L)            # M_b = k_n_bar I dtheta
    # numbers for the record: a 0.8 mm bond of 40 GPa over 1.6 mm is 5.03e7 N/m
    assert c["k_r"] == pytest.approx(5.0265e7, rel=1e-4)


def test_strength_mapping_reproduces_both_parallel_bond_checks(c):
    A, I, J = (float(v) for v in section(RB))
    rng = np.random.default_rng(1)
    for _ in range(200):
        # tension + bending only: B equals sigma_max / sigma_c (seed 000 eq. 15)
        Fn, Mb = rng.uniform(0, 30), rng.uniform(0, 0.01)
        sigma = Fn / A + Mb * RB / I
        assert lammps_B(c, f_r=Fn, t_b=Mb) == pytest.approx(sigma / SIG, rel=1e-12)
        # shear + twist only: B equals tau_max / tau_c (eq. 16)
        Fs, Mt = rng.uniform(0, 30), rng.uniform(0, 0.01)
        tau = Fs / A + Mt * RB / J
        assert lammps_B(c, f_s=Fs, t_t=Mt) == pytest.approx(tau / TAU, rel=1e-12)
    # the pure limits break exactly at the strengths
    assert lammps_B(c, f_r=SIG * A) == pytest.approx(1.0)
    assert lammps_B(c, f_s=TAU * A) == pytest.approx(1.0)
    # combined: linear interaction, stricter than the parallel bond's max()
    assert lammps_B(c, f_r=0.5 * SIG * A, f_s=0.5 * TAU * A) == pytest.approx(1.0)
    # compression (f_r < 0) adds shear capacity
    assert lammps_B(c, f_r=-0.5 * SIG * A, f_s=TAU * A) == pytest.approx(0.5)


def test_damping_is_the_requested_fraction_of_critical():
    m, inertia, zeta = 2e-5, 5e-12, 0.3
    c = bpm_coefficients(E, RATIO, SIG, TAU, RB, L, m, inertia, zeta)
    assert float(c["gamma_n"]) == pytest.approx(2 * zeta * math.sqrt(m * float(c["k_r"])))
    # twisting torque = 0.5 gamma_t dw: critical 2 sqrt(I k_t) -> gamma_t = 4 zeta sqrt(I k_t)
    assert 0.5 * float(c["gamma_t"]) == pytest.approx(zeta * 2 * math.sqrt(inertia * float(c["k_t"])))
    # rolling torque = 0.5 gamma_r L dw
    assert 0.5 * float(c["gamma_r"]) * L == pytest.approx(zeta * 2 * math.sqrt(inertia * float(c["k_b"])))


def test_bond_pairs_are_radius_aware():
    # big pair with a gap of 4 % of the smaller radius: bonded at tolerance 5 %
    # small-big pair with the same absolute gap is > 5 % of the small radius: not bonded
    r = np.array([1.0e-3, 1.0e-3, 0.5e-3])
    gap = 0.04e-3
    x = np.array([[0, 0, 0], [2e-3 + gap, 0, 0], [-(1.5e-3 + gap), 0, 0]], dtype=float)
    pairs = find_bond_pairs(x, r, 0.05)
    assert pairs.tolist() == [[0, 1]]
    pairs = find_bond_pairs(x, r, 0.09)
    assert pairs.tolist() == [[0, 1], [0, 2]]


def test_bond_pairs_match_brute_force():
    rng = np.random.default_rng(7)
    x = rng.uniform(0, 10e-3, (300, 3))
    r = rng.uniform(0.5e-3, 1e-3, 300)
    pairs = find_bond_pairs(x, r, 0.1)
    brute = []
    for i in range(300):
        for j in range(i + 1, 300):
            gap = np.linalg.norm(x[i] - x[j]) - r[i] - r[j]
            if gap <= 0.1 * min(r[i], r[j]):
                brute.append([i, j])
    assert pairs.tolist() == brute
    assert len(brute) > 100


def _chain(density=2650.0, E_b=E):
    r = np.full(3, 0.5e-3)
    x = np.array([[0, 0, 0], [1e-3, 0, 0], [2e-3, 0, 0]], dtype=float)
    mass = density * 4 / 3 * math.pi * r**3
    pairs = np.array([[0, 1], [1, 2]])
    t = make_bond_table(x, r, mass, pairs, E_b=E_b, stiffness_ratio=RATIO, sigma_c=SIG, tau_c=TAU,
                        radius_multiplier=1.0, damping_ratio=0.05, bins_radius=1, bins_length=1)
    return x, r, mass, t


def test_stable_timestep_from_the_stiffest_mode():
    x, r, mass, t = _chain()
    dt = stable_timestep(x, r, mass, t, safety=0.2)
    k_r, k_s, k_b = (float(t.coeffs[n][0]) for n in ("k_r", "k_s", "k_b"))
    inertia = 0.4 * mass[1] * r[1] ** 2
    # the middle grain has two bonds
    w_tr = math.sqrt(2 * k_r / mass[1])
    w_rot = math.sqrt(2 * (0.75 * k_s * 1e-6 + k_b) / inertia)
    assert dt["omega_translational_rad_s"] == pytest.approx(w_tr)
    assert dt["omega_rotational_rad_s"] == pytest.approx(w_rot)
    assert dt["dt_s"] == pytest.approx(0.2 * 2 / max(w_tr, w_rot))
    # rotation limits for mm grains (ENGINE_NOTES: the rotational mode sets dt)
    assert w_rot > w_tr
    # scaling: dt ~ sqrt(density) and ~ 1/sqrt(stiffness)
    x4, r4, m4, t4 = _chain(density=4 * 2650.0)
    assert stable_timestep(x4, r4, m4, t4, 0.2)["dt_s"] == pytest.approx(2 * dt["dt_s"])
    xs, rs, ms, ts = _chain(E_b=E / 4)
    assert stable_timestep(xs, rs, ms, ts, 0.2)["dt_s"] == pytest.approx(2 * dt["dt_s"])


def test_bond_types_are_bin_means():
    rng = np.random.default_rng(3)
    n = 400
    x = rng.uniform(0, 8e-3, (n, 3))
    r = rng.uniform(0.5e-3, 0.9e-3, n)
    mass = 2650 * 4 / 3 * math.pi * r**3
    pairs = find_bond_pairs(x, r, 0.3)
    t = make_bond_table(x, r, mass, pairs, E_b=E, stiffness_ratio=RATIO, sigma_c=SIG, tau_c=TAU,
                        radius_multiplier=1.0, damping_ratio=0.05, bins_radius=3, bins_length=2)
    assert 1 < t.ntypes <= 6
    assert set(np.unique(t.types)) == set(range(1, t.ntypes + 1))
    for k in range(t.ntypes):
        sel = t.pairs[t.types == k + 1]
        rb = np.minimum(r[sel[:, 0]], r[sel[:, 1]]).mean()
        assert t.r_bond[k] == pytest.approx(rb)
        assert float(t.coeffs["F_rc"][k]) == pytest.approx(SIG * math.pi * rb**2)
    assert t.per_atom.sum() == 2 * len(pairs)


def test_concurrent_jobs_make_a_shared_packing_once(tmp_path, monkeypatch):
    """Two jobs needing the same packing: the second waits for the first and reuses its folder (no shared .tmp)."""
    import json
    import threading
    import time
    from pathlib import Path

    from deckgen import packing as pk
    from deckgen.spec import load_case

    case = load_case(Path(__file__).resolve().parent / "data" / "cases" / "tiny_ucs.yaml")
    calls = []

    def fake_make(case, folder, *, progress, command):
        calls.append(threading.get_ident())
        time.sleep(0.5)
        folder.mkdir(parents=True)
        (folder / "packed.data").write_text("x")
        (folder / "packing.json").write_text(json.dumps({"key": "k"}))
        return folder

    monkeypatch.setattr(pk, "_make_packing", fake_make)
    out = []
    threads = [threading.Thread(target=lambda: out.append(pk.ensure_packing(case, tmp_path, progress=False))) for _ in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert len(calls) == 1 and len(out) == 2 and out[0] == out[1] == pk.packing_dir(case, tmp_path)
