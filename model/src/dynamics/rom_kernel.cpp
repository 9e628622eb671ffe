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
// Timed on the AVX-512 clone since (tools/dynamics_bench): removing the mesh solve made
// the step 1.3× faster and constant tables 1.1×, so those two were made lean (the
// factor-then-solve elimination below, one loop over contiguous tables with hardware
// gathers); the streamed matrices (~650 vector loads and ~550 vector FMAs a step) are
// what is left.
#include "rom_kernel.hpp"

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
// GCC 12's AVX-512 intrinsics start from _mm512_undefined_pd(), which -Wuninitialized
// reports at every use once inlined (a known false positive of that header).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#include <immintrin.h>
#endif

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

// I + A·G, A = diag(Δk_mesh), G = Wᵀ diag(b1q) W, by Gauss–Jordan elimination without
// pivoting on the matrix held by columns (col[j] is column j). Step k takes the pivot
// p_k and f_k = (column k without row k) / p_k, and subtracts f_k times row k's entry
// from every later column (the earlier ones are unit vectors by then). The solve applies
// the same row operations to the right-hand side, b ← b − f_k·b_k for k = 0..7, and
// divides row k by p_k: b = (I + A G)⁻¹ b. Compared with forming the inverse (as this
// kernel did before) that is half the vector operations (no inverse columns to update)
// for a solve of eight dependent steps instead of one 8×8 product.
// The factors depend on Δk only, so the step computes them first and the out-of-order
// core overlaps them with the predictor. Their critical path is the pivots: each is
// taken from the entries before the previous step's column update,
// p_{k+1} = M_{k+1,k+1} − M_{k,k+1}·M_{k+1,k}·(1/p_k), so it waits on one division, one
// multiplication and one subtraction, not on the whole update. One division per pivot:
// a second one (…/p_k instead of ·(1/p_k)) shortened the chain but cost 5 % of the
// step, the divider's throughput. |A·G| is the mesh stiffness fluctuation over the
// stiffness the mesh sees (< 1 for any real mesh: a pair cannot lose more than its own
// stiffness), so the diagonal dominates and pivoting buys nothing. Returns false on a
// pivot that is not positive (a non-physical table). Inlined so that each clone
// compiles it for its ISA.
struct MeshFactors {
  Mesh8 f[kM];      // f_k: step k's row multipliers M_ik/p_k (0 in row k)
  Mesh8 inv_pivot;  // 1/p_k
};
[[gnu::always_inline]] inline bool factor_mesh_system(Mesh8 (&col)[kM], MeshFactors& fac) noexcept {
  const Mesh8 ones = {1, 1, 1, 1, 1, 1, 1, 1};
  double p = col[0][0];
  bool ok = true;
#pragma GCC unroll 8
  for (int k = 0; k < kM; ++k) {
    ok &= p > 1e-12;
    const Mesh8 below_above = col[k] * (ones - kUnit[k]);  // column k without row k
    const double r = 1.0 / p;
    double p_next = 0.0;
    if (k + 1 < kM) {
      const int n = k + 1;
      p_next = col[n][n] - (col[k][n] * col[n][k]) * r;
    }
    fac.inv_pivot[k] = r;
    const Mesh8 f = below_above * r;
    fac.f[k] = f;
#pragma GCC unroll 8
    for (int j = k + 1; j < kM; ++j) col[j] -= f * col[j][k];
    p = p_next;
  }
  return ok;
}
[[gnu::always_inline]] inline void solve_mesh_system(const MeshFactors& fac, Mesh8& b) noexcept {
#pragma GCC unroll 8
  for (int k = 0; k < kM; ++k) b -= fac.f[k] * b[k];
  b *= fac.inv_pivot;
}

// Every term's shape at rotor angle `revs`: PeriodicTable::value's arithmetic (linear
// between samples) over RomData's contiguous term tables. The index wraps with a mask,
// so a phase that rounds up to a whole cycle reads sample 0 with weight 0 where value()
// reads sample 255 with weight 1 — the same number up to rounding.
// Portable version: two loops, the phase arithmetic vectorises (floor() is one
// instruction from SSE4.1 on), the table reads (a gather) stay scalar.
[[gnu::always_inline]] inline void lookup_shapes_portable(const RomKernelModel& m,
                                                          const double revs,
                                                          double* __restrict shape) noexcept {
  constexpr int kT = kKernelTerms;
  constexpr int kTable = kKernelTableSize;
  static_assert((kTable & (kTable - 1)) == 0, "the table index wraps with a mask");
  alignas(64) double weight[kT];
  alignas(64) int index[kT];
  for (int t = 0; t < kT; ++t) {
    const double x = m.term_order[t] * revs + m.term_phase_cycles[t];
    const double pos = (x - __builtin_floor(x)) * static_cast<double>(kTable);  // [0, kTable]
    const int i = static_cast<int>(pos);
    weight[t] = pos - static_cast<double>(i);
    index[t] = i;
  }
  for (int t = 0; t < kT; ++t) {
    const double* table = m.term_values + t * kTable;
    const double v0 = table[index[t] & (kTable - 1)];
    shape[t] = v0 + weight[t] * (table[(index[t] + 1) & (kTable - 1)] - v0);
  }
}

}  // namespace

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
// The look-ups as GCC function multiversions: GCC vectorises the phase arithmetic above
// but not the table reads, which it emulates with scalar loads and lane inserts (about
// 200 instructions, most of them on the ports the step's FMAs need). The AVX-512 version
// is the same arithmetic in 8-wide registers with two hardware gathers per 8 terms; same
// operations in the same order, so the same numbers as the portable version.
__attribute__((target("default"))) void lookup_shapes(const RomKernelModel& m, double revs,
                                                      double* shape) noexcept {
  lookup_shapes_portable(m, revs, shape);
}
__attribute__((target("arch=x86-64-v4"))) void lookup_shapes(const RomKernelModel& m, double revs,
                                                             double* shape) noexcept {
  constexpr int kTable = kKernelTableSize;
  static_assert(kKernelTerms % 8 == 0, "whole vectors of 8 terms");
  const __m512d rev = _mm512_set1_pd(revs);
  const __m512d size = _mm512_set1_pd(static_cast<double>(kTable));
  const __m256i mask = _mm256_set1_epi32(kTable - 1);
  const __m256i one = _mm256_set1_epi32(1);
  for (int h = 0; h < kKernelTerms / 8; ++h) {
    const __m512d x = _mm512_fmadd_pd(_mm512_loadu_pd(m.term_order + 8 * h), rev,
                                      _mm512_loadu_pd(m.term_phase_cycles + 8 * h));
    const __m512d fl = _mm512_roundscale_pd(x, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
    const __m512d pos = _mm512_mul_pd(_mm512_sub_pd(x, fl), size);  // [0, kTable]
    const __m256i i = _mm512_cvttpd_epi32(pos);
    const __m512d w = _mm512_sub_pd(pos, _mm512_cvtepi32_pd(i));
    // Table t starts at t·kTable.
    const __m256i base =
        _mm256_mullo_epi32(_mm256_setr_epi32(8 * h, 8 * h + 1, 8 * h + 2, 8 * h + 3, 8 * h + 4,
                                             8 * h + 5, 8 * h + 6, 8 * h + 7),
                           _mm256_set1_epi32(kTable));
    const __m256i i0 = _mm256_add_epi32(base, _mm256_and_si256(i, mask));
    const __m256i i1 = _mm256_add_epi32(base, _mm256_and_si256(_mm256_add_epi32(i, one), mask));
    const __m512d v0 = _mm512_i32gather_pd(i0, m.term_values, 8);
    const __m512d v1 = _mm512_i32gather_pd(i1, m.term_values, 8);
    _mm512_storeu_pd(shape + 8 * h, _mm512_fmadd_pd(w, _mm512_sub_pd(v1, v0), v0));
  }
}
#pragma GCC diagnostic pop
#else
inline void lookup_shapes(const RomKernelModel& m, double revs, double* shape) noexcept {
  lookup_shapes_portable(m, revs, shape);
}
#endif

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
  // The time-varying coefficients at t_{n+1}: every term's table at its phase.
  alignas(64) double shape[kKernelTerms];
  lookup_shapes(m, revs, shape);
  Mesh8 dk;  // Δk_mesh(t_{n+1}) = k̄ (shape − 1)
  for (int j = 0; j < kM; ++j) dk[j] = m.term_scale[j] * (shape[j] - 1.0);
  double k_bearing[kKernelBearings];
  double dk_bearing[kB];  // per W_b column
  for (int j = 0; j < kKernelBearings; ++j) {
    const double mean = m.term_scale[kM + j];
    k_bearing[j] = mean * shape[kM + j];
    dk_bearing[2 * j] = dk_bearing[2 * j + 1] = k_bearing[j] - mean;
  }
  double force[kKernelForces];
  for (int j = 0; j < kKernelForces; ++j) {
    const int t = kM + kKernelBearings + j;
    force[j] = (m.term_scale[t] + m.term_scale_per_nm[t] * input_torque_nm) * shape[t];
  }
  // Transmission-error forces s = k_mesh(t_{n+1}) ∘ e(t_{n+1}) along the mesh lines: a known
  // force at t_{n+1}, applied below through the mesh read-out (no extra pass over the modes).
  constexpr int kTe = kM + kKernelBearings + kKernelForces;
  Mesh8 te;
  for (int j = 0; j < kM; ++j) te[j] = (m.term_scale[j] + dk[j]) * shape[kTe + j];

  // The factors of I + A G first: they depend on the stiffness coefficients only.
  Mesh8 col[kM];  // I + A G by columns: col[j][i] = δ_ij + Δk_i G_ij
  // Left uninitialised on purpose (per step): the factorisation writes every member it reads.
  MeshFactors fac;  // NOLINT(cppcoreguidelines-pro-type-member-init)
  for (int j = 0; j < kM; ++j) {
    Mesh8 gj;
    __builtin_memcpy(&gj, m.g_mesh + j * kM, sizeof gj);
    col[j] = dk * gj + kUnit[j];
  }
  const bool invertible = factor_mesh_system(col, fac);

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
  // The predictor without the transmission-error force is r'; with it r = r' + b1q ∘ W s,
  // whose read-out is [W W_b]ᵀr = z' + [G; H] s (H = W_bᵀ diag(b1q) W).
  double tes[kM];
  __builtin_memcpy(tes, &te, sizeof tes);
  for (int j = 0; j < kM; ++j) {
    const double* column = m.readout_correction + j * kZpad;
    for (int b = 0; b < kZv; ++b) {
      Mesh8 cb;
      __builtin_memcpy(&cb, column + b * kM, sizeof cb);
      z[b] += cb * tes[j];
    }
  }

  // Implicit mesh fluctuation (Woodbury): y = (I + A G)⁻¹ A Wᵀ r, A = diag(Δk_mesh(t_{n+1})).
  // A non-physical table (a non-positive pivot) falls back to the explicit estimate A Wᵀ r.
  const Mesh8 rhs = dk * z[0];
  Mesh8 y = rhs;
  if (invertible) {
    solve_mesh_system(fac, y);
  }
  // The corrector and the deflections use W (y − s): q⁺ = r' − b1q ∘ W (y − s),
  // g⁺ = h − W (y − s) (h without the TE force), z⁺ = z − [G; H] y.
  const Mesh8 y_eff = y - te;
  double ys[kM];  // y − s in memory: the loops below broadcast its elements from there
  __builtin_memcpy(ys, &y_eff, sizeof ys);
  double yd[kM];  // y itself, for the deflections
  __builtin_memcpy(yd, &y, sizeof yd);

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
      z[b] -= cb * yd[j];
    }
  }
  double z_next[kZpad];
  __builtin_memcpy(z_next, z, sizeof z_next);
  for (int k = 0; k < kM; ++k) s.z_mesh[k] = z_next[k];
  for (int k = 0; k < kB; ++k) s.z_bearing[k] = z_next[kM + k];

  // Forces at t_{n+1}: k(t_{n+1}) times the deflection (a mesh's less its transmission error).
  for (int j = 0; j < kM; ++j) out.mesh_force_n[j] = (m.term_scale[j] + dk[j]) * z_next[j] - te[j];
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
  if (__builtin_cpu_supports("x86-64-v4")) return "x86-64-v4 (AVX-512) clone, gathered look-ups";
  if (__builtin_cpu_supports("x86-64-v3")) return "x86-64-v3 (AVX2, FMA) clone";
  return "x86-64 baseline (SSE2) clone";
#elif defined(__aarch64__)
  return "aarch64 (NEON)";
#else
  return "portable";
#endif
}

}  // namespace model::dynamics::detail
