"""Tests for deckgen.geometry (disc-cutter meshes). Lengths in metres."""

from __future__ import annotations

import math

import numpy as np
import pytest
import trimesh
from stl import mesh as stl_mesh

from deckgen import geometry as g

# Representative cases (SI units). 17-inch V / CCS discs, seed 000's asymmetric
# disc, seed 003's 10/20 mm cone.
CASES = {
    "v_disc": dict(diameter=0.4318, edge_angle_deg=20.0, tip_radius=0.003, hub_width=0.06),
    "ccs_disc": dict(diameter=0.4318, tip_width=0.019, tip_radius=0.006, flank_angle_deg=10.0, hub_width=0.06),
    "asymmetric_disc": dict(diameter=0.150, blade_angle_deg=40.0, tip_radius=0.001, hub_width=0.02),
    "cone_disc": dict(small_diameter=0.010, large_diameter=0.020),
}
DIAM = {"v_disc": 0.4318, "ccs_disc": 0.4318, "asymmetric_disc": 0.150, "cone_disc": 0.020}
WIDTH = {
    "v_disc": 0.06,
    "ccs_disc": 0.06,
    "asymmetric_disc": 0.02,
    "cone_disc": 0.005 * math.tan(math.radians(60.0)),  # (D-d)/2 * tan(90-rake)
}


def rho_a(mesh: trimesh.Trimesh) -> tuple[np.ndarray, np.ndarray]:
    """(rho, a) of every vertex for a disc with its axis along +y."""
    v = np.asarray(mesh.vertices)
    return np.hypot(v[:, 0], v[:, 2]), v[:, 1]


def two_point_angle_deg(p_outer: tuple[float, float], p_inner: tuple[float, float]) -> float:
    """Inclination [deg] of the segment between two (rho, a) points to the radial plane."""
    return math.degrees(math.atan2(abs(p_inner[1] - p_outer[1]), abs(p_outer[0] - p_inner[0])))


@pytest.fixture(scope="module")
def meshes() -> dict[str, trimesh.Trimesh]:
    return {k: g.build_cutter(k, p) for k, p in CASES.items()}


# --------------------------------------------------------------------------- validity


@pytest.mark.parametrize("kind", list(CASES))
def test_mesh_is_closed_oriented_solid(meshes, kind):
    m = meshes[kind]
    assert m.is_watertight
    assert m.is_winding_consistent
    assert m.volume > 0
    assert m.area_faces.min() > 0  # no degenerate triangles (axis points collapsed)
    # every profile is convex, so every outward face normal points away from the centroid
    d = np.einsum("ij,ij->i", m.face_normals, m.triangles_center - m.center_mass)
    assert (d > 0).all()


@pytest.mark.parametrize("kind", list(CASES))
def test_bounding_box_diameter_and_width(meshes, kind):
    m = meshes[kind]
    ext = m.bounds[1] - m.bounds[0]
    D = DIAM[kind]
    assert ext[0] == pytest.approx(D, rel=1e-3)  # x
    assert ext[2] == pytest.approx(D, rel=1e-3)  # z (cut depth direction)
    assert ext[1] == pytest.approx(WIDTH[kind], rel=1e-9)  # y = disc axis
    assert m.bounds[0][2] == pytest.approx(-D / 2, rel=1e-12)  # lowest rim point is a vertex
    s = g.cutter_summary(m)
    assert s["diameter_m"] == pytest.approx(D, rel=1e-3)
    assert s["width_m"] == pytest.approx(WIDTH[kind], rel=1e-9)
    assert s["watertight"] is True and s["winding_consistent"] is True
    assert s["n_triangles"] == len(m.faces)
    assert s["volume_m3"] == pytest.approx(m.volume)


@pytest.mark.parametrize("axis, idx", [("x", 0), ("y", 1), ("z", 2)])
def test_axis_choice(axis, idx):
    m = g.build_cutter("asymmetric_disc", CASES["asymmetric_disc"], axis=axis)
    assert m.is_watertight and m.is_winding_consistent and m.volume > 0
    ext = m.bounds[1] - m.bounds[0]
    assert ext[idx] == pytest.approx(0.02, rel=1e-9)
    others = [ext[i] for i in range(3) if i != idx]
    assert others == pytest.approx([0.15, 0.15], rel=1e-9)
    assert g.cutter_summary(m)["width_m"] == pytest.approx(0.02, rel=1e-9)


def test_default_segments_meet_chord_tolerance():
    R = 0.4318 / 2
    n = g.segments_for_radius(R)
    assert n % 4 == 0 and 64 <= n <= 720
    assert R * (1 - math.cos(math.pi / n)) <= 2e-5
    assert R * (1 - math.cos(math.pi / (n - 4))) > 2e-5  # not wastefully fine
    assert g.segments_for_radius(0.01) == 64  # clipped at the low end
    assert g.segments_for_radius(100.0) == 720  # and at the high end
    m = g.build_cutter("v_disc", CASES["v_disc"])
    assert m.metadata["deckgen_n_segments"] == n


# --------------------------------------------------------------------------- shapes


def test_v_disc_flank_angle_from_vertices(meshes):
    m = meshes["v_disc"]
    rho, a = rho_a(m)
    w = 0.06
    for sign in (1.0, -1.0):
        s = sign * a
        hub_corner = (rho[np.isclose(s, w / 2, atol=1e-12)].max(), w / 2)
        flank_side = (s > 1e-12) & (s < w / 2 - 1e-9)  # tip arc above the mid-plane + tangent ring
        k = np.argmin(np.where(flank_side, rho, np.inf))
        tangent = (rho[k], s[k])
        half = two_point_angle_deg(tangent, hub_corner)
        assert 2 * half == pytest.approx(20.0, abs=0.5)
        assert 2 * half == pytest.approx(20.0, abs=1e-6)  # actually exact
    # rounded tip: the outermost vertex ring is at the mid-plane, the rim is not sharp
    assert np.all(np.abs(a[rho > 0.2159 - 1e-9]) < 1e-12)
    assert np.count_nonzero(rho > 0.2159 - 0.003) > 10 * 64


def test_asymmetric_disc_flat_face_and_bevel_angle(meshes):
    m = meshes["asymmetric_disc"]
    rho, a = rho_a(m)
    R, r = 0.075, 0.001
    a_min, a_max = a.min(), a.max()
    assert a_min == pytest.approx(-r, abs=1e-15)  # flat face at -tip_radius, edge plane at 0
    on_plane = np.abs(a - a_min) < 1e-12
    # the flat face is one plane from the axis out to where the tip arc starts
    assert rho[on_plane].min() == 0.0
    assert rho[on_plane].max() == pytest.approx(R - r, rel=1e-12)
    # faces facing -y are all in that plane and cover the disc pi*(R-r)^2
    facing = m.face_normals[:, 1] < -0.999999
    assert np.all(np.abs(a[m.faces[facing]] - a_min) < 1e-12)
    n = m.metadata["deckgen_n_segments"]
    polygon_area = 0.5 * n * (R - r) ** 2 * math.sin(2 * math.pi / n)
    assert m.area_faces[facing].sum() == pytest.approx(polygon_area, rel=1e-9)
    # bevel angle: hub-corner ring to the bevel end of the tip arc
    hub_corner = (rho[np.abs(a - a_max) < 1e-12].max(), a_max)
    bevel_side = (a > a_min + r) & (a < a_max - 1e-9)
    k = np.argmin(np.where(bevel_side, rho, np.inf))
    assert two_point_angle_deg((rho[k], a[k]), hub_corner) == pytest.approx(40.0, abs=0.5)
    assert two_point_angle_deg((rho[k], a[k]), hub_corner) == pytest.approx(40.0, abs=1e-6)


def test_asymmetric_disc_flat_side_plus_mirrors():
    p_minus = g.asymmetric_disc(0.16, 40.0, 0.001, 0.02, flat_side=-1)
    p_plus = g.asymmetric_disc(0.16, 40.0, 0.001, 0.02, flat_side=+1)
    m = g.revolve(p_plus)
    assert m.is_watertight and m.volume > 0
    assert m.bounds[1][1] == pytest.approx(0.001, abs=1e-15)  # flat face now at max y
    assert m.volume == pytest.approx(g.revolve(p_minus).volume, rel=1e-12)


def test_ccs_disc_tip_land_and_nominal_tip_width(meshes):
    m = meshes["ccs_disc"]
    rho, a = rho_a(m)
    R, W, r, phi, w = 0.2159, 0.019, 0.006, 10.0, 0.06
    land = a[rho > R - 1e-9]
    expected_land = W - 2 * r * math.tan(math.radians(45 - phi / 2))
    assert land.max() - land.min() == pytest.approx(expected_land, rel=1e-9)
    assert land.max() == pytest.approx(-land.min(), abs=1e-15)  # centred on the mid-plane
    # nominal tip width = flank lines (from vertices) extended to the rim cylinder
    hub_corner = (rho[np.abs(a - w / 2) < 1e-12].max(), w / 2)
    flank_side = (a > 0) & (a < w / 2 - 1e-9)
    k = np.argmin(np.where(flank_side, rho, np.inf))
    slope = (hub_corner[1] - a[k]) / (hub_corner[0] - rho[k])
    a_at_rim = a[k] + slope * (R - rho[k])
    assert 2 * a_at_rim == pytest.approx(W, rel=1e-6)
    assert two_point_angle_deg((rho[k], a[k]), hub_corner) == pytest.approx(phi, abs=1e-6)


def test_cone_disc_geometry_and_clearance_tilt():
    base = g.build_cutter("cone_disc", dict(small_diameter=0.01, large_diameter=0.02))
    rho, a = rho_a(base)
    assert rho[np.abs(a - a.max()) < 1e-12].max() == pytest.approx(0.005, rel=1e-12)  # small face
    assert rho[np.abs(a - a.min()) < 1e-12].max() == pytest.approx(0.010, rel=1e-12)  # large face = edge
    # cone generatrix at the rake angle (30 deg) to the axis -> 60 deg to the flat face
    assert two_point_angle_deg((0.010, a.min()), (0.005, a.max())) == pytest.approx(60.0, abs=1e-9)

    c = 9.0
    tilted = g.build_cutter("cone_disc", dict(small_diameter=0.01, large_diameter=0.02, clearance_angle_deg=c))
    assert tilted.is_watertight and tilted.is_winding_consistent
    assert tilted.volume == pytest.approx(base.volume, rel=1e-12)
    n_flat = np.array([0.0, -math.cos(math.radians(c)), math.sin(math.radians(c))])
    facing = tilted.face_normals @ n_flat > 1 - 1e-9
    n = tilted.metadata["deckgen_n_segments"]
    assert tilted.area_faces[facing].sum() == pytest.approx(0.5 * n * 0.01**2 * math.sin(2 * math.pi / n), rel=1e-9)
    # above the lowest rim point the clearance face recedes toward +y
    v = tilted.vertices
    low = v[np.argmin(v[:, 2])]
    assert low[1] == pytest.approx(-0.01 * math.sin(math.radians(c)), rel=1e-9)
    s = g.cutter_summary(tilted)  # uses the tilted disc axis from metadata
    assert s["diameter_m"] == pytest.approx(0.02, rel=1e-9)
    assert s["width_m"] == pytest.approx(WIDTH["cone_disc"], rel=1e-9)


# --------------------------------------------------------------------------- volumes


def test_volume_cone_matches_frustum():
    R, r, h = 0.01, 0.005, 0.005 * math.tan(math.radians(60))
    exact = math.pi * h / 3 * (R * R + R * r + r * r)
    assert g.build_cutter("cone_disc", CASES["cone_disc"]).volume == pytest.approx(exact, rel=5e-3)
    fine = g.build_cutter("cone_disc", CASES["cone_disc"], n_segments=720)
    assert fine.volume == pytest.approx(exact, rel=2e-4)
    assert fine.volume < exact  # inscribed polygon


def test_volume_sharp_v_disc_matches_pappus():
    D, ang, w = 0.4318, 20.0, 0.06
    R = D / 2
    rho_h = R - (w / 2) / math.tan(math.radians(ang / 2))
    hub = math.pi * rho_h**2 * w
    tri_area = 0.5 * w * (R - rho_h)
    tri_centroid = (2 * rho_h + R) / 3
    exact = hub + 2 * math.pi * tri_area * tri_centroid
    m = g.build_cutter("v_disc", dict(diameter=D, edge_angle_deg=ang, tip_radius=0.0, hub_width=w))
    assert m.is_watertight
    assert m.volume == pytest.approx(exact, rel=5e-3)


# --------------------------------------------------------------------------- offset


def test_offset_square_exact():
    sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    off = g.offset_profile(sq, 0.1)
    expected = {(0.0, 0.1), (0.9, 0.1), (0.9, 0.9), (0.0, 0.9)}  # axis edge stays on rho = 0
    assert {tuple(np.round(p, 12)) for p in off} == expected


def test_offset_rounded_tip_shrinks_rim_by_delta():
    prm = CASES["v_disc"]
    delta = 0.0005
    base, off = g.build_cutter("v_disc", prm), g.build_cutter("v_disc", prm, offset=delta)
    assert off.is_watertight and off.is_winding_consistent
    R0, R1 = g.cutter_summary(base)["diameter_m"] / 2, g.cutter_summary(off)["diameter_m"] / 2
    assert R0 - R1 == pytest.approx(delta, rel=1e-2)
    assert g.cutter_summary(off)["width_m"] == pytest.approx(0.06 - 2 * delta, rel=1e-9)
    assert off.volume < base.volume
    # removed shell ~ surface area * delta
    assert base.volume - off.volume == pytest.approx(base.area * delta, rel=2e-2)
    prof = g.offset_profile(g.v_disc(**prm), delta)
    assert prof[:, 0].min() == 0.0 and np.count_nonzero(prof[:, 0] == 0.0) == 2


def test_offset_larger_than_tip_radius_gives_sharp_apex():
    D, ang, r, w, delta = 0.15, 40.0, 0.0005, 0.02, 0.001
    off = g.offset_profile(g.v_disc(D, ang, r, w), delta)
    beta = math.radians(ang / 2)
    apex = D / 2 - r + r / math.sin(beta) - delta / math.sin(beta)
    assert off[:, 0].max() == pytest.approx(apex, rel=1e-9)
    assert np.count_nonzero(np.isclose(off[:, 0], apex, rtol=1e-9)) == 1  # arc collapsed to a point
    m = g.revolve(off)
    assert m.is_watertight and m.volume > 0


def test_offset_keeps_asymmetric_flat_face_flat():
    p = g.asymmetric_disc(**CASES["asymmetric_disc"])
    off = g.offset_profile(p, 0.0003)
    m = g.revolve(off)
    rho, a = rho_a(m)
    assert a.min() == pytest.approx(-0.001 + 0.0003, abs=1e-15)
    # the face ends where the (polygonal) tip arc starts: R - r, less a mitre of delta*tan(step/2)
    edge = rho[np.abs(a - a.min()) < 1e-12].max()
    assert edge == pytest.approx(0.075 - 0.001, abs=0.0003 * math.tan(math.radians(g.ARC_STEP_DEG / 2)) * 1.01)


def test_offset_too_large_raises():
    with pytest.raises(ValueError, match="delta"):
        g.offset_profile(g.v_disc(0.15, 40.0, 0.001, 0.02), 0.011)
    with pytest.raises(ValueError, match="delta"):
        g.offset_profile(g.v_disc(0.15, 40.0, 0.001, 0.02), -1e-3)


# --------------------------------------------------------------------------- STL


def test_stl_round_trip(tmp_path, meshes):
    m = meshes["asymmetric_disc"]
    path = g.write_stl(m, tmp_path / "sub" / "cutter.stl")
    assert path.exists()
    raw = path.read_bytes()
    assert not raw[:5].lower().startswith(b"solid")
    assert raw.startswith(b"deckgen binary STL")
    n = len(m.faces)
    assert int.from_bytes(raw[80:84], "little") == n
    assert len(raw) == 84 + 50 * n
    back = stl_mesh.Mesh.from_file(str(path))
    assert len(back.vectors) == n
    pts = back.vectors.reshape(-1, 3)
    assert np.allclose(pts.min(axis=0), m.bounds[0], atol=1e-7)
    assert np.allclose(pts.max(axis=0), m.bounds[1], atol=1e-7)
    tm = trimesh.load(path, file_type="stl")
    assert len(tm.faces) == n and tm.is_watertight
    assert tm.volume == pytest.approx(m.volume, rel=1e-5)


# --------------------------------------------------------------------------- API / errors


def test_build_cutter_accepts_dataclass_and_dict():
    a = g.build_cutter("v_disc", g.VDiscParams(**CASES["v_disc"]), n_segments=64)
    b = g.build_cutter("v_disc", CASES["v_disc"], n_segments=64)
    assert np.array_equal(a.vertices, b.vertices) and np.array_equal(a.faces, b.faces)
    assert set(g.CUTTER_KINDS) == {"v_disc", "ccs_disc", "asymmetric_disc", "cone_disc"}


@pytest.mark.parametrize(
    "call, name",
    [
        (lambda: g.v_disc(0.15, 40.0, 0.02, 0.02), "tip_radius"),  # arc wider than the hub
        (lambda: g.v_disc(0.15, 180.0, 0.001, 0.02), "edge_angle_deg"),
        (lambda: g.v_disc(0.15, 10.0, 0.001, 0.05), "hub_width"),  # flanks hit the axis
        (lambda: g.v_disc(431.8, 20.0, 0.001, 0.05), "millimetres"),
        (lambda: g.v_disc(0.15, 20.0, -0.001, 0.05), "tip_radius"),
        (lambda: g.ccs_disc(0.4318, 0.019, 0.02, 10.0, 0.06), "tip_radius"),
        (lambda: g.ccs_disc(0.4318, 0.019, 0.006, 0.0, 0.06), "flank_angle_deg"),
        (lambda: g.ccs_disc(0.4318, 0.019, 0.006, 10.0, 0.02), "hub_width"),
        (lambda: g.asymmetric_disc(0.15, 95.0, 0.001, 0.02), "blade_angle_deg"),
        (lambda: g.asymmetric_disc(0.15, 0.0, 0.001, 0.02), "blade_angle_deg"),
        (lambda: g.asymmetric_disc(0.15, 40.0, 0.001, 0.02, flat_side=0), "flat_side"),
        (lambda: g.cone_disc(0.02, 0.01), "small_diameter"),
        (lambda: g.cone_disc(0.01, 0.02, rake_angle_deg=90.0), "rake_angle_deg"),
        (lambda: g.build_cutter("x_disc", {}), "kind"),
        (lambda: g.build_cutter("v_disc", dict(CASES["v_disc"], colour=1)), "colour"),
        (lambda: g.build_cutter("cone_disc", dict(CASES["cone_disc"], clearance_angle_deg=95.0)), "clearance_angle_deg"),
        (lambda: g.build_cutter("cone_disc", dict(CASES["cone_disc"], clearance_angle_deg=9.0), axis="x"), "clearance_angle_deg"),
        (lambda: g.revolve(g.cone_disc(0.01, 0.02), axis="w"), "axis"),
        (lambda: g.revolve(g.cone_disc(0.01, 0.02), n_segments=2), "n_segments"),
        (lambda: g.revolve([[-0.1, 0.0], [0.1, 0.0], [0.1, 0.1]]), "rho"),
    ],
)
def test_bad_parameters_raise_named_value_error(call, name):
    with pytest.raises(ValueError, match=name):
        call()
