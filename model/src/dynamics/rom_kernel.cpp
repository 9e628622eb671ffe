// One Rom::step() of linear algebra (equations in rom.hpp, layout in rom_kernel.hpp).
//
// Written for the vectoriser: every loop over the modal coordinates has a compile-time
// trip count over contiguous arrays; products with the read-out matrices are sums of
// their columns (no horizontal sums), and the two sensor dot products keep kLanes
// partial sums in a fixed order, so the result does not depend on the vector width
// the compiler picks; the state arrays are `__restrict` (only the kernel touches them
// during a step), so the corrector updates them in place. The 8×8 mesh system uses 8-wide
// vectors (Mesh8) explicitly. This file is compiled with -O3 -ffp-contract=fast (FMA
// where the target has it: AVX2/AVX-512 clones, aarch64) — model/src/dynamics/CMakeLists.txt.
//
// Profile that shaped it (callgrind / perf on paper-2mw, 64 DOF): the old Eigen step
// spent 29 % in GEMV for W_b·f_b, W·y and the forces, 23 % in the 20×64 read-out,
// 23 % in element-wise updates, 14 % in a scalar 8×8 LU, 5–8 % in table look-ups.
#include "rom_kernel.hpp"

namespace model::dynamics::detail {
namespace {

constexpr int kN = kKernelDofs;
constexpr int kM = kKernelMeshes;
constexpr int kB = kKernelBearingRank;
constexpr int kZ = kM + kB;
constexpr int kZpad = kKernelReadoutRows;  // kZ rounded up to whole Mesh8 vectors
constexpr int kZv = kZpad / kM;
static_assert(kZpad % kM == 0 && kZpad >= kZ, "read-out rows must fill whole vectors");
constexpr int kLanes =
    8;  // partial sums per dot product: one AVX-512 / two AVX2 / four NEON registers
static_assert(kN % kLanes == 0, "kKernelDofs must be a multiple of the dot-product lanes");

[[gnu::always_inline]] inline double sum_lanes(const double (&acc)[kLanes]) noexcept {
  return ((acc[0] + acc[4]) + (acc[2] + acc[6])) + ((acc[1] + acc[5]) + (acc[3] + acc[7]));
}

// Eight doubles as one value (GCC/Clang vector extension): one AVX-512 register, two
// AVX2, four SSE2 or NEON registers. Used where the mesh count is the natural vector
// length, because there -O3's complete unrolling of the 8×8 loops runs before the loop
// vectoriser and leaves scalar code behind.
using Mesh8 = double __attribute__((vector_size(kM * sizeof(double))));
static_assert(sizeof(Mesh8) == kM * sizeof(double), "one Mesh8 per mesh vector");

// The identity's columns as whole vectors: setting one element of a vector in place
// goes through memory and stalls the next load of the whole vector (store forwarding).
constexpr Mesh8 kUnit[kM] = {{1, 0, 0, 0, 0, 0, 0, 0}, {0, 1, 0, 0, 0, 0, 0, 0},
                             {0, 0, 1, 0, 0, 0, 0, 0}, {0, 0, 0, 1, 0, 0, 0, 0},
                             {0, 0, 0, 0, 1, 0, 0, 0}, {0, 0, 0, 0, 0, 1, 0, 0},
                             {0, 0, 0, 0, 0, 0, 1, 0}, {0, 0, 0, 0, 0, 0, 0, 1}};

// (I + A·G)⁻¹, A = diag(Δk_mesh), G = Wᵀ diag(b1q) W, by Gauss–Jordan elimination
// without pivoting on the matrix held by columns (col[j] is column j; inv[j] becomes
// column j of the inverse): every elimination step is one vector operation per column.
// The inverse depends on Δk only, so the step computes it before the predictor: the
// out-of-order core overlaps its chain of eight divisions with the predictor's
// independent work, and applying it is one 8×8 product. |A·G| is the mesh stiffness
// fluctuation over the stiffness the mesh sees (< 1 for any real mesh: a pair cannot
// lose more than its own stiffness), so the diagonal dominates and pivoting buys
// nothing. Returns false on a pivot that is not positive (a non-physical table).
// Inlined so that each clone compiles it for its ISA.
[[gnu::always_inline]] inline bool invert_mesh_system(Mesh8 (&col)[kM], Mesh8 (&inv)[kM]) noexcept {
  const Mesh8 ones = {1, 1, 1, 1, 1, 1, 1, 1};
  double inv_pivot[kM];
#pragma GCC unroll 8
  for (int k = 0; k < kM; ++k) {
    const double p = col[k][k];
    if (!(p > 1e-12)) return false;
    const double r = 1.0 / p;
    inv_pivot[k] = r;
    // Row multipliers A(i,k)/A(k,k); row k keeps its own (multiplier 0).
    const Mesh8 f = col[k] * r * (ones - kUnit[k]);
    // Columns left of k are eliminated already (zero off the diagonal); the identity's
    // columns right of k are still untouched unit vectors (zero in row k).
#pragma GCC unroll 8
    for (int j = k + 1; j < kM; ++j) col[j] -= f * col[j][k];
#pragma GCC unroll 8
    for (int j = 0; j < k; ++j) inv[j] -= f * inv[j][k];
    inv[k] = kUnit[k] - f;
  }
  // Row i of the eliminated system still carries its pivot: divide it out.
  const Mesh8 row_scale = {inv_pivot[0], inv_pivot[1], inv_pivot[2], inv_pivot[3],
                           inv_pivot[4], inv_pivot[5], inv_pivot[6], inv_pivot[7]};
  static_assert(kM == 8, "row_scale lists the kM pivots");
  for (int j = 0; j < kM; ++j) inv[j] *= row_scale;
  return true;
}

}  // namespace

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
// One clone per x86-64 micro-architecture level; GCC's resolver picks the best at load time.
#define DRIVETWIN_ROM_KERNEL_CLONES \
  __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#else
#define DRIVETWIN_ROM_KERNEL_CLONES
#endif

namespace {
// The step proper. The state arrays are `__restrict`: the kernel reads and writes them
// only through these pointers, so the corrector writes them in place without the
// compiler guarding every store against the model data.
[[gnu::always_inline]] inline void step(const RomKernelModel& m, const double revs,
                                        const double input_torque_nm, double* __restrict q,
                                        double* __restrict v, double* __restrict g,
                                        const RomKernelState& s,
                                        const RomKernelOutputs& out) noexcept {
  // The time-varying coefficients at t_{n+1} from their tables (in the clone: the
  // look-ups' floor() is one instruction with SSE4.1 and later).
  double force[kKernelForces] = {};
  for (int j = 0; j < m.force_count; ++j) {
    const RomForceTerm& ft = m.forces[j];
    const double a = ft.per_newton_metre ? ft.amplitude * input_torque_nm : ft.amplitude;
    force[j] = a * ft.shape.value(ft.order * revs + ft.phase_cycles);
  }
  double k_bearing[kKernelBearings];
  double dk_bearing[kB];  // per W_b column
  for (int j = 0; j < kKernelBearings; ++j) {
    const RomStiffnessTerm& b = m.bearings[j];
    k_bearing[j] = b.mean_n_m * b.shape.value(b.order * revs + b.phase_cycles);
    dk_bearing[2 * j] = dk_bearing[2 * j + 1] = k_bearing[j] - b.mean_n_m;
  }
  Mesh8 dk;
  for (int j = 0; j < kM; ++j) {
    const RomStiffnessTerm& mt = m.meshes[j];
    dk[j] = mt.mean_n_m * (mt.shape.value(mt.order * revs + mt.phase_cycles) - 1.0);
  }

  // (I + A G)⁻¹ first: it depends on the stiffness coefficients only (see above).
  Mesh8 col[kM];  // I + A G by columns: col[j][i] = δ_ij + Δk_i G_ij
  Mesh8 inv[kM] = {};
  for (int j = 0; j < kM; ++j) {
    Mesh8 gj;
    __builtin_memcpy(&gj, m.g_mesh + j * kM, sizeof gj);
    col[j] = dk * gj + kUnit[j];
  }
  const bool invertible = invert_mesh_system(col, inv);

  // Explicit bearing fluctuation forces, at the deflections of t_n.
  double fb[kB];
  for (int j = 0; j < kB; ++j) fb[j] = dk_bearing[j] * s.z_bearing[j];

  // h = Φᵀf(t_{n+1}) − W_b·f_b and the predictor r (q⁺ without the implicit mesh term).
  alignas(64) double h[kN];
  alignas(64) double r[kN];
  for (int i = 0; i < kN; ++i) {
    double hi = 0.0;
    for (int j = 0; j < kKernelForces; ++j) hi += force[j] * m.w_force[j * kN + i];
    for (int j = 0; j < kB; ++j) hi -= fb[j] * m.w_bearing[j * kN + i];
    h[i] = hi;
    r[i] = m.pqq[i] * q[i] + m.pqv[i] * v[i] + m.b0q[i] * g[i] + m.b1q[i] * hi;
  }

  // z = [W W_b]ᵀ r, the mesh and bearing deflections of the predictor, as a sum of the
  // read-out matrix's columns (no horizontal sums); kSets independent partial sums
  // keep the floating-point adds from waiting on each other. Plain loops, not Mesh8
  // accumulators: twelve Mesh8 fit AVX-512's registers but spill on AVX2 and NEON
  // (callgrind: 2.2× the instructions of the whole step on the AVX2 clone).
  constexpr int kSets = 4;
  alignas(64) double z_sets[kSets][kZpad] = {};
  for (int i = 0; i < kN; i += kSets) {
    for (int set = 0; set < kSets; ++set) {
      const double ri = r[i + set];
      const double* column = m.readout_by_dof + (i + set) * kZpad;
      for (int k = 0; k < kZpad; ++k) z_sets[set][k] += ri * column[k];
    }
  }
  alignas(64) double z_sum[kZpad];
  for (int k = 0; k < kZpad; ++k)
    z_sum[k] = (z_sets[0][k] + z_sets[2][k]) + (z_sets[1][k] + z_sets[3][k]);
  Mesh8 z[kZv];
  __builtin_memcpy(z, z_sum, sizeof z);

  // Implicit mesh fluctuation (Woodbury): y = (I + A G)⁻¹ A Wᵀ r, A = diag(Δk_mesh(t_{n+1})).
  // A non-physical table (a non-positive pivot) falls back to the explicit estimate A Wᵀ r.
  const Mesh8 rhs = dk * z[0];
  Mesh8 y = rhs;
  if (invertible) {
    y = inv[0] * rhs[0];
    for (int j = 1; j < kM; ++j) y += inv[j] * rhs[j];
  }
  double ys[kM];  // y in memory: the loops below broadcast its elements from there
  __builtin_memcpy(ys, &y, sizeof ys);

  // Corrector: g⁺ = h − W y, q⁺ = r − b1q ⊙ W y, v⁺ from the propagators; the seat
  // accelerations S q̈⁺ = S (g⁺ − c ⊙ v⁺ − ω² ⊙ q⁺) in the same pass.
  double acc0[kLanes] = {};
  double acc1[kLanes] = {};
  const double* s0 = m.sensor_rows;
  const double* s1 = m.sensor_rows + kN;
  for (int ib = 0; ib < kN; ib += kLanes) {
    for (int l = 0; l < kLanes; ++l) {
      const int i = ib + l;
      double wy = 0.0;
      for (int j = 0; j < kM; ++j) wy += ys[j] * m.w_mesh[j * kN + i];
      const double gn = h[i] - wy;
      const double vn = m.pvq[i] * q[i] + m.pvv[i] * v[i] + m.b0v[i] * g[i] + m.b1v[i] * gn;
      const double qn = r[i] - m.b1q[i] * wy;
      const double qdd = gn - m.damping_1_s[i] * vn - m.omega2[i] * qn;
      acc0[l] += s0[i] * qdd;
      acc1[l] += s1[i] * qdd;
      q[i] = qn;
      v[i] = vn;
      g[i] = gn;
    }
  }
  static_assert(kKernelSensors == 2, "the corrector pass accumulates two sensor rows");
  out.acceleration_m_s2[0] = sum_lanes(acc0);
  out.acceleration_m_s2[1] = sum_lanes(acc1);

  // Deflections at t_{n+1}: [W W_b]ᵀq⁺ = [W W_b]ᵀr − [G; H] y (H = W_bᵀ diag(b1q) W).
  for (int j = 0; j < kM; ++j) {
    const double* column = m.readout_correction + j * kZpad;
    for (int b = 0; b < kZv; ++b) {
      Mesh8 cb;
      __builtin_memcpy(&cb, column + b * kM, sizeof cb);
      z[b] -= cb * ys[j];
    }
  }
  double z_next[kZpad];
  __builtin_memcpy(z_next, z, sizeof z_next);
  for (int k = 0; k < kM; ++k) s.z_mesh[k] = z_next[k];
  for (int k = 0; k < kB; ++k) s.z_bearing[k] = z_next[kM + k];

  // Forces at t_{n+1}: k(t_{n+1}) times the deflection.
  for (int j = 0; j < kM; ++j) out.mesh_force_n[j] = (m.meshes[j].mean_n_m + dk[j]) * z_next[j];
  for (int j = 0; j < kKernelBearings; ++j) {
    out.bearing_force_x_n[j] = k_bearing[j] * z_next[kM + 2 * j];
    out.bearing_force_y_n[j] = k_bearing[j] * z_next[kM + 2 * j + 1];
  }
}
}  // namespace

DRIVETWIN_ROM_KERNEL_CLONES
void rom_step_kernel(const RomKernelModel& m, const double revs, const double input_torque_nm,
                     const RomKernelState& s, const RomKernelOutputs& out) noexcept {
  step(m, revs, input_torque_nm, s.q, s.v, s.g, s, out);
}

const char* rom_step_kernel_isa() noexcept {
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
  // The same order as the resolver's: the highest level the CPU supports.
  __builtin_cpu_init();
  if (__builtin_cpu_supports("x86-64-v4")) return "x86-64-v4 (AVX-512) clone";
  if (__builtin_cpu_supports("x86-64-v3")) return "x86-64-v3 (AVX2, FMA) clone";
  return "x86-64 baseline (SSE2) clone";
#elif defined(__aarch64__)
  return "aarch64 (NEON)";
#else
  return "portable";
#endif
}

}  // namespace model::dynamics::detail
