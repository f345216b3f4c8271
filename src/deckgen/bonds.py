r"""Parallel-bond inputs -> LAMMPS ``bond_style bpm/rotational`` coefficients, bond creation and
the stable time step.

Mapping (derivation)
--------------------
A parallel bond (Potyondy & Cundall 2004; seed 000 eqs. 7-16) between grains of radii
:math:`r_1, r_2` is a cement cylinder of radius :math:`\bar r = \lambda \min(r_1, r_2)` and length
:math:`L = |x_1 - x_2|` at bonding (:math:`\lambda` = ``radius_multiplier``, SFA in seed 000).
With area :math:`A = \pi \bar r^2`, bending moment of area :math:`I = \pi \bar r^4/4` and polar
moment :math:`J = \pi \bar r^4/2`, the bond has normal and shear stiffness per unit area
:math:`\bar k_n = E_b/L` and :math:`\bar k_s = \bar k_n/\kappa` (:math:`\kappa` =
``stiffness_ratio`` = :math:`k_n/k_s`). The bond resists

* stretch: :math:`F_n = \bar k_n A\,\Delta u_n`  ->  ``k_r`` = :math:`E_b A/L`  [N/m]
* shear:   :math:`F_s = \bar k_s A\,\Delta u_s`  ->  ``k_s`` = :math:`E_b A/(\kappa L)`  [N/m]
* twist:   :math:`M_t = \bar k_s J\,\Delta\theta_t`  ->  ``k_t`` = :math:`E_b J/(\kappa L)`  [N m/rad]
* bending: :math:`M_b = \bar k_n I\,\Delta\theta_b`  ->  ``k_b`` = :math:`E_b I/L`  [N m/rad]

LAMMPS computes exactly these linear laws (``f_r = k_r (r - r_0)``, shear and angular terms after
Wang 2009), so the four stiffnesses map one to one.

Strength. The parallel bond breaks when :math:`\sigma = F_n/A + |M_b|\bar r/I \ge \sigma_c` or
:math:`\tau = |F_s|/A + |M_t|\bar r/J \ge \tau_c` (seed 000 eqs. 15-16, tension positive).
LAMMPS breaks a bond when :math:`B = f_r/F_{r,c} + |f_s|/F_{s,c} + |\tau_b|/\tau_{b,c} +
|\tau_t|/\tau_{t,c} \ge 1`. Matching each pure load case gives

* pure tension   :math:`F_{r,c} = \sigma_c A`
* pure bending   :math:`\tau_{b,c} = \sigma_c I/\bar r`
* pure shear     :math:`F_{s,c} = \tau_c A`
* pure twist     :math:`\tau_{t,c} = \tau_c J/\bar r`

With these, tension + bending alone give :math:`B = \sigma/\sigma_c`, and shear + twist alone give
:math:`B = \tau/\tau_c`: both parallel-bond checks are reproduced exactly. Only when normal and
shear terms act together do the criteria differ: LAMMPS adds them (a linear interaction,
:math:`\sigma/\sigma_c + \tau/\tau_c \ge 1`), the parallel bond takes the larger. And because
``f_r`` is signed, a compressed bond (f_r < 0) gains shear capacity, like cohesion plus friction.
Both differences raise the macroscopic UCS/BTS ratio relative to the plain parallel bond; the
calibration (issue #3) absorbs them.

Damping. From the LAMMPS source: normal force :math:`\gamma_n \Delta v_n`, shear
:math:`\gamma_s \Delta v_s`, rolling torque :math:`\tfrac12\gamma_r L\,\Delta\omega_\perp`,
twisting torque :math:`\tfrac12\gamma_t\,\Delta\omega_\parallel`. For a damping ratio
:math:`\zeta` of the relative motion (effective mass :math:`m^* = m_1 m_2/(m_1+m_2)`, inertia
:math:`I^* = I_1 I_2/(I_1+I_2)`):
:math:`\gamma_n = 2\zeta\sqrt{m^* k_r}`, :math:`\gamma_s = 2\zeta\sqrt{m^* k_s}`,
:math:`\gamma_r = 4\zeta\sqrt{I^* k_b}/L`, :math:`\gamma_t = 4\zeta\sqrt{I^* k_t}`.

Clumps. Cho, Martin & Sego (2007, IJRMMS 44:997-1010) showed that a bonded-particle model of
clumped grains (non-breakable clusters of particles) reaches realistic UCS/BTS ratios and friction
angles, where round grains stay far below them. :func:`grow_clumps` groups grains into clumps of at
most ``clump_size`` bonded grains, deterministically from a seed; every bond between two grains of
one clump is an intra-clump bond with its own bond types, its strengths multiplied by the clump
strength factor (effectively unbreakable at 10-100) and its modulus by the clump stiffness factor.

Strength heterogeneity. A bond's cement is not everywhere equally good. With
``strength_weibull_modulus`` m > 0 every ordinary bond gets a strength factor w drawn from a Weibull
distribution of shape m scaled to mean 1 (:func:`weibull_strength_factors`, coefficient of variation
:func:`weibull_cov`: 0.52 at m = 2, 0.36 at m = 3, 0.23 at m = 5); its tensile, shear, bending and
twisting strengths are w times the values above, its stiffness is unchanged. Bonds are binned by w
too (quantile bins, ``bins_strength``), and a type carries the mean w of its bonds. Weibull-distributed
bond strengths are one way of giving a bonded-particle model the weakest-link flaws of real rock;
Potyondy & Cundall (2004, IJRMMS 41:1329-1364) give their parallel-bond strengths a mean and a standard
deviation for the same purpose. Intra-clump bonds keep factor 1.

Time step. Central-difference integration is stable for :math:`\Delta t < 2/\omega_{max}`. Each
grain gets its translational and rotational frequency from the sum over its bonds,
:math:`\omega_{tr}^2 = \sum k_r / m` and :math:`\omega_{rot}^2 = \sum (0.75 k_s L^2 + k_b)/I`
(the rotational form matched the trial runs in ENGINE_NOTES.md: with it, 0.4/omega was the
largest step at which an unloaded specimen kept all its bonds), and
:math:`\Delta t = s \cdot 2/\max\omega` with the safety factor s (default 0.2).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

COEFF_NAMES = (
    "k_r", "k_s", "k_t", "k_b", "F_rc", "F_sc", "tau_bc", "tau_tc",
    "gamma_n", "gamma_s", "gamma_r", "gamma_t",
)
COEFF_UNITS = ("N/m", "N/m", "N m/rad", "N m/rad", "N", "N", "N m", "N m",
               "N s/m", "N s/m", "N s", "N m s")


def section(r_bond: np.ndarray | float) -> tuple:
    """Area, bending and polar moments of a circular bond section of radius r_bond [m]."""
    r = np.asarray(r_bond, dtype=float)
    return math.pi * r**2, math.pi * r**4 / 4.0, math.pi * r**4 / 2.0


def bpm_coefficients(
    E_b: float,
    stiffness_ratio: float,
    sigma_c: float,
    tau_c: float,
    r_bond: np.ndarray | float,
    length: np.ndarray | float,
    m_eff: np.ndarray | float,
    I_eff: np.ndarray | float,
    damping_ratio: float,
    bending_factor: float = 1.0,
    twisting_factor: float = 1.0,
) -> dict[str, np.ndarray]:
    """The 12 bpm/rotational coefficients (SI) for bonds of radius ``r_bond`` and length ``length``.

    E_b [Pa], sigma_c, tau_c [Pa], r_bond, length [m], m_eff [kg], I_eff [kg m^2].
    Arrays broadcast; see the module docstring for the derivation. ``bending_factor`` and
    ``twisting_factor`` multiply the critical bending and twisting torques (1: the parallel-bond match).
    """
    A, I, J = section(r_bond)
    L = np.asarray(length, dtype=float)
    kn_area = E_b / L
    ks_area = kn_area / stiffness_ratio
    k_r = kn_area * A
    k_s = ks_area * A
    k_t = ks_area * J
    k_b = kn_area * I
    rb = np.asarray(r_bond, dtype=float)
    out = {
        "k_r": k_r,
        "k_s": k_s,
        "k_t": k_t,
        "k_b": k_b,
        "F_rc": sigma_c * A,
        "F_sc": tau_c * A,
        "tau_bc": bending_factor * sigma_c * I / rb,
        "tau_tc": twisting_factor * tau_c * J / rb,
        "gamma_n": 2.0 * damping_ratio * np.sqrt(m_eff * k_r),
        "gamma_s": 2.0 * damping_ratio * np.sqrt(m_eff * k_s),
        "gamma_r": 4.0 * damping_ratio * np.sqrt(I_eff * k_b) / L,
        "gamma_t": 4.0 * damping_ratio * np.sqrt(I_eff * k_t),
    }
    return {k: np.asarray(v, dtype=float) for k, v in out.items()}


def weibull_cov(modulus: float) -> float:
    """Coefficient of variation of a Weibull distribution of shape ``modulus``."""
    g1, g2 = math.gamma(1.0 + 1.0 / modulus), math.gamma(1.0 + 2.0 / modulus)
    return math.sqrt(g2 / g1**2 - 1.0)


def weibull_strength_factors(n: int, modulus: float, seed: int) -> np.ndarray:
    """``n`` bond strength factors, Weibull of shape ``modulus`` scaled to mean 1 (the distribution's mean,
    not the sample's). Drawn from a generator seeded with ``seed`` (the packing seed), offset so the draw
    does not repeat the clump or unbonded draws from the same seed. Deterministic."""
    if not modulus > 0:
        raise ValueError(f"Weibull modulus must be > 0, got {modulus}")
    w = np.random.default_rng([int(seed), 0x5EED, 2]).weibull(modulus, size=int(n))
    return w / math.gamma(1.0 + 1.0 / modulus)


def find_bond_pairs(x: np.ndarray, r: np.ndarray, gap_tolerance: float) -> np.ndarray:
    """Radius-aware neighbour pairs: i<j with |x_i - x_j| - (r_i + r_j) <= gap_tolerance * min(r_i, r_j).

    Overlapping pairs (negative gap) are always bonded. Returns an (n, 2) int array, sorted.
    """
    x = np.asarray(x, dtype=float)
    r = np.asarray(r, dtype=float)
    if len(x) < 2:
        return np.zeros((0, 2), dtype=np.int64)
    cutoff = 2.0 * r.max() * (1.0 + gap_tolerance)
    pairs = cKDTree(x).query_pairs(cutoff, output_type="ndarray")
    if len(pairs) == 0:
        return np.zeros((0, 2), dtype=np.int64)
    i, j = pairs[:, 0], pairs[:, 1]
    d = np.linalg.norm(x[i] - x[j], axis=1)
    gap = d - (r[i] + r[j])
    keep = gap <= gap_tolerance * np.minimum(r[i], r[j])
    out = np.sort(pairs[keep], axis=1)
    return out[np.lexsort((out[:, 1], out[:, 0]))].astype(np.int64)


def grow_clumps(pairs: np.ndarray, n: int, clump_size: int, seed: int, x: np.ndarray | None = None) -> np.ndarray:
    """Clump label (0..n_clumps-1) of each of ``n`` grains, clumps grown on the bond graph ``pairs``.

    Grains are visited in a random order drawn from ``seed``; each grain not yet in a clump starts
    one, which grows one grain at a time to at most ``clump_size`` grains by adding the free grain
    bonded to the most clump members (ties: nearest to the starting grain when ``x`` is given, then
    the lower index). A clump that runs out of free bonded neighbours stays smaller, so every grain
    is in exactly one clump and sizes are 1..clump_size. Deterministic for given inputs.
    """
    if clump_size < 1:
        raise ValueError(f"clump_size must be >= 1, got {clump_size}")
    pairs = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    if len(pairs) and (pairs.min() < 0 or pairs.max() >= n):
        raise ValueError(f"pairs refer to grains outside 0..{n - 1}")
    if clump_size == 1:
        return np.arange(n, dtype=np.int64)
    label = np.full(n, -1, dtype=np.int64)
    nbrs: list[list[int]] = [[] for _ in range(n)]
    for i, j in pairs:
        if i != j:
            nbrs[int(i)].append(int(j))
            nbrs[int(j)].append(int(i))
    order = np.random.default_rng(seed).permutation(n)
    nxt = 0
    for s0 in order:
        s0 = int(s0)
        if label[s0] >= 0:
            continue
        members = [s0]
        label[s0] = nxt
        links: dict[int, int] = {}  # free candidate -> bonds to clump members
        for k in nbrs[s0]:
            if label[k] < 0:
                links[k] = links.get(k, 0) + 1
        while len(members) < clump_size and links:
            if x is not None:
                d = {k: float(((x[k] - x[s0]) ** 2).sum()) for k in links}
                pick = min(links, key=lambda k: (-links[k], d[k], k))
            else:
                pick = min(links, key=lambda k: (-links[k], k))
            del links[pick]
            label[pick] = nxt
            members.append(pick)
            for k in nbrs[pick]:
                if label[k] < 0:
                    links[k] = links.get(k, 0) + 1
        nxt += 1
    return label


def unbonded_mask(n_pairs: int, fraction: float, seed: int, protect: np.ndarray | None = None) -> np.ndarray:
    """Mask of the bondable pairs left without a bond: ``round(fraction * n_eligible)`` of them.

    Eligible are the pairs not marked in ``protect`` (intra-clump bonds stay). The choice is a
    uniform draw without replacement from a generator seeded with ``seed`` (the packing seed), offset
    so it does not repeat the clump-growing order drawn from the same seed. Deterministic.
    """
    if not 0.0 <= fraction < 1.0:
        raise ValueError(f"unbonded fraction must be in [0, 1), got {fraction}")
    drop = np.zeros(n_pairs, dtype=bool)
    eligible = np.arange(n_pairs) if protect is None else np.flatnonzero(~np.asarray(protect, dtype=bool))
    k = int(round(fraction * len(eligible)))
    if k:
        pick = np.random.default_rng([int(seed), 0x5EED]).choice(eligible, size=k, replace=False)
        drop[pick] = True
    return drop


def clump_sizes(label: np.ndarray) -> dict[int, int]:
    """Clump-size distribution: {size: number of clumps of that size}."""
    if len(label) == 0:
        return {}
    sizes = np.bincount(np.asarray(label, dtype=np.int64))
    sizes = sizes[sizes > 0]
    u, c = np.unique(sizes, return_counts=True)
    return {int(a): int(b) for a, b in zip(u, c)}


def intra_clump(pairs: np.ndarray, label: np.ndarray) -> np.ndarray:
    """Mask of the bonds whose two grains belong to the same clump."""
    pairs = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    return label[pairs[:, 0]] == label[pairs[:, 1]]


@dataclass
class BondTable:
    """Bonds of a specimen, grouped into types whose coefficients are the bin means."""

    pairs: np.ndarray          # (n, 2) 0-based atom indices
    types: np.ndarray          # (n,) 1-based bond type
    coeffs: dict[str, np.ndarray]  # name -> (ntypes,) per-type coefficient
    r_bond: np.ndarray         # per-type mean bond radius [m]
    length: np.ndarray         # per-type mean bond length [m]
    per_atom: np.ndarray       # bonds per atom
    n_plain_types: int | None = None  # types 1..n_plain_types are ordinary bonds, the rest intra-clump (None: all)
    strength_factor: np.ndarray | None = None  # per-type mean strength factor of its bonds (1 without scatter)

    @property
    def intra_types(self) -> list[int]:
        """1-based bond types of intra-clump bonds (empty without clumps)."""
        n = self.ntypes if self.n_plain_types is None else self.n_plain_types
        return list(range(n + 1, self.ntypes + 1))

    @property
    def ntypes(self) -> int:
        return len(self.r_bond)

    def coeff_rows(self) -> list[tuple[int, list[float]]]:
        return [(t + 1, [float(self.coeffs[n][t]) for n in COEFF_NAMES]) for t in range(self.ntypes)]


def _bins(values: np.ndarray, nbins: int) -> np.ndarray:
    """Quantile bins 0..nbins-1 (fewer when values repeat)."""
    if nbins <= 1 or len(values) == 0:
        return np.zeros(len(values), dtype=np.int64)
    edges = np.unique(np.quantile(values, np.linspace(0, 1, nbins + 1)[1:-1]))
    return np.searchsorted(edges, values, side="right").astype(np.int64)


def make_bond_table(
    x: np.ndarray,
    r: np.ndarray,
    mass: np.ndarray,
    pairs: np.ndarray,
    *,
    E_b: float,
    stiffness_ratio: float,
    sigma_c: float,
    tau_c: float,
    radius_multiplier: float,
    damping_ratio: float,
    bins_radius: int,
    bins_length: int,
    intra: np.ndarray | None = None,
    clump_strength_factor: float = 1.0,
    clump_stiffness_factor: float = 1.0,
    bending_factor: float = 1.0,
    twisting_factor: float = 1.0,
    strength_factor: np.ndarray | None = None,
    bins_strength: int = 1,
    grain_class: np.ndarray | None = None,
) -> BondTable:
    """Bin bonds by (bond radius, bond length) into types and compute per-type coefficients.

    LAMMPS holds coefficients per bond type, so a polydisperse packing gets one type per
    (radius bin, length bin); the within-bin spread (a few per cent) is reported by
    :func:`binning_error`. ``intra`` (a mask over ``pairs``) marks intra-clump bonds: they are
    binned on their own into the types after the ordinary ones (``BondTable.n_plain_types``),
    with sigma_c and tau_c times ``clump_strength_factor`` and E_b times ``clump_stiffness_factor``.
    Without intra-clump bonds the table is the plain one. ``strength_factor`` (one per bond; None = 1)
    multiplies the strengths of the ordinary bonds: they are binned by it as well (``bins_strength``
    quantile bins) and each type gets the mean factor of its bonds. Intra-clump bonds ignore it.
    ``grain_class`` (one 0/1 per grain; None = all 0) marks the fine grains of a two-size packing
    (``packing.fine_zone``): fine-fine, fine-coarse and coarse-coarse bonds are binned apart, since quantile bins
    shared by two size populations would put bonds of both sizes into one type (on a tiny block with a band the
    largest stiffness error of a type rose from 0.10 to 0.67). Without it the table is the one-size one.
    """
    pairs = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    mask = np.zeros(len(pairs), bool) if intra is None else np.asarray(intra, dtype=bool)
    if mask.shape != (len(pairs),):
        raise ValueError(f"intra: expected a mask of {len(pairs)} bonds, got shape {mask.shape}")
    if clump_strength_factor <= 0 or clump_stiffness_factor <= 0:
        raise ValueError("clump_strength_factor and clump_stiffness_factor must be > 0")
    sf = np.ones(len(pairs)) if strength_factor is None else np.asarray(strength_factor, dtype=float)
    if sf.shape != (len(pairs),) or not np.all(sf > 0):
        raise ValueError(f"strength_factor: expected {len(pairs)} positive factors, got shape {sf.shape}")
    nbs = max(int(bins_strength), 1) if strength_factor is not None else 1
    i, j = pairs[:, 0], pairs[:, 1]
    rb = radius_multiplier * np.minimum(r[i], r[j])
    L = np.linalg.norm(x[i] - x[j], axis=1)
    inertia = 0.4 * mass * r**2
    m_eff = mass[i] * mass[j] / (mass[i] + mass[j])
    I_eff = inertia[i] * inertia[j] / (inertia[i] + inertia[j])
    # pair class of each bond: 0 coarse-coarse, 1 mixed, 2 fine-fine (all 0 without grain_class)
    gc = np.zeros(len(r), dtype=np.int64) if grain_class is None else np.asarray(grain_class, dtype=np.int64)
    pair_class = gc[i] + gc[j]
    span = max(int(bins_radius), 1) * max(int(bins_length), 1)
    types = np.zeros(len(pairs), dtype=np.int64)
    parts = []
    offset = 0
    for sel, e_f, s_f, nb_s in ((~mask, 1.0, 1.0, nbs), (mask, clump_stiffness_factor, clump_strength_factor, 1)):
        if not sel.any():
            continue
        # quantile bins within each pair class (one class, 0, without grain_class)
        pc, rb_s, L_s = pair_class[sel], rb[sel], L[sel]
        key = np.empty(len(pc), dtype=np.int64)
        for c in np.unique(pc):
            m = pc == c
            key[m] = c * span + _bins(rb_s[m], bins_radius) * max(bins_length, 1) + _bins(L_s[m], bins_length)
        if nb_s > 1:
            key = key * nb_s + _bins(sf[sel], nb_s)
        uniq, types0 = np.unique(key, return_inverse=True)
        nt = len(uniq)
        cnt = np.bincount(types0, minlength=nt)

        def mean(v: np.ndarray) -> np.ndarray:
            return np.bincount(types0, weights=v[sel], minlength=nt) / cnt

        rb_t, L_t = mean(rb), mean(L)
        w_t = mean(sf) if nb_s > 1 else np.ones(nt)  # the type's mean strength factor (ordinary bonds only)
        parts.append((rb_t, L_t, w_t, bpm_coefficients(E_b * e_f, stiffness_ratio, sigma_c * s_f * w_t, tau_c * s_f * w_t,
                                                   rb_t, L_t,
                                                   mean(m_eff), mean(I_eff), damping_ratio,
                                                   bending_factor=bending_factor, twisting_factor=twisting_factor)))
        types[sel] = types0 + 1 + offset
        offset += nt
    n_plain = len(parts[0][0]) if parts and (~mask).any() else 0
    if parts:
        coeffs = {k: np.concatenate([p[3][k] for p in parts]) for k in COEFF_NAMES}
        rb_all = np.concatenate([p[0] for p in parts])
        L_all = np.concatenate([p[1] for p in parts])
        w_all = np.concatenate([p[2] for p in parts])
    else:  # no bond at all: keep the shapes the plain path gave (empty types)
        coeffs = {k: np.zeros(0) for k in COEFF_NAMES}
        rb_all, L_all, w_all = np.zeros(0), np.zeros(0), np.zeros(0)
    per_atom = np.bincount(pairs.ravel(), minlength=len(r))
    return BondTable(pairs=pairs, types=types, coeffs=coeffs, r_bond=rb_all, length=L_all, per_atom=per_atom,
                     n_plain_types=n_plain, strength_factor=w_all)


def binning_error(x: np.ndarray, r: np.ndarray, table: BondTable, radius_multiplier: float) -> float:
    """Largest relative deviation of a bond's true k_r from its type's k_r."""
    i, j = table.pairs[:, 0], table.pairs[:, 1]
    rb = radius_multiplier * np.minimum(r[i], r[j])
    L = np.linalg.norm(x[i] - x[j], axis=1)
    true = rb**2 / L
    typ = table.r_bond[table.types - 1] ** 2 / table.length[table.types - 1]
    return float(np.max(np.abs(true / typ - 1.0))) if len(true) else 0.0


def stable_timestep(
    x: np.ndarray, r: np.ndarray, mass: np.ndarray, table: BondTable, safety: float
) -> dict[str, float]:
    """Stable time step from the stiffest translational and rotational bond modes of any grain.

    Returns dt [s] and the two limiting frequencies [rad/s].
    """
    i, j = table.pairs[:, 0], table.pairs[:, 1]
    t = table.types - 1
    k_r = table.coeffs["k_r"][t]
    k_rot = 0.75 * table.coeffs["k_s"][t] * table.length[t] ** 2 + table.coeffs["k_b"][t]
    n = len(r)
    sum_kr = np.bincount(i, weights=k_r, minlength=n) + np.bincount(j, weights=k_r, minlength=n)
    sum_krot = np.bincount(i, weights=k_rot, minlength=n) + np.bincount(j, weights=k_rot, minlength=n)
    inertia = 0.4 * mass * r**2
    w_tr = float(np.sqrt(np.max(sum_kr / mass))) if len(k_r) else 0.0
    w_rot = float(np.sqrt(np.max(sum_krot / inertia))) if len(k_r) else 0.0
    w = max(w_tr, w_rot)
    if w <= 0:
        raise ValueError("no bonds: cannot compute a stable time step from bond stiffness")
    return {"dt_s": safety * 2.0 / w, "omega_translational_rad_s": w_tr, "omega_rotational_rad_s": w_rot}


def contact_timestep(r_min: float, density: float, E: float, nu: float, safety: float = 0.2) -> float:
    """Rayleigh-wave time step for Hertz contacts of the smallest grain [s] (Thornton's estimate)."""
    G = E / (2.0 * (1.0 + nu))
    return safety * math.pi * r_min * math.sqrt(density / G) / (0.1631 * nu + 0.8766)
