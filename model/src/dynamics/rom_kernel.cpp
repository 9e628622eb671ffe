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
// reports at every use once inlined (a known false positive of that header; in a loop with
// a run-time trip count it reports it as -Wmaybe-uninitialized).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <immintrin.h>
#endif

namespace model::dynamics::detail {
namespace {

constexpr int kN = kKernelDofs;
constexpr int kM = kKernelMeshes;
constexpr int kMB = kKernelMeshBasis;
constexpr int kB = kKernelBearingRank;
constexpr int kZpad = kKernelReadoutRows;  // read-out rows, whole Mesh8 vectors
constexpr int kZv = kZpad / kM;
static_assert(kZpad % kM == 0 && kKernelRowPaths + kKernelPaths == kZpad,
              "read-out rows must fill whole vectors");
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
constexpr Mesh8 kOnes = {1, 1, 1, 1, 1, 1, 1, 1};
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
  constexpr int kTable = kKernelTableSize;
  static_assert((kTable & (kTable - 1)) == 0, "the table index wraps with a mask");
  alignas(64) double weight[kKernelLookups];
  alignas(64) int index[kKernelLookups];
  const int n = m.lookups;
  for (int t = 0; t < n; ++t) {
    const double x = m.term_order[t] * revs + m.term_phase_cycles[t];
    const double pos = (x - __builtin_floor(x)) * static_cast<double>(kTable);  // [0, kTable]
    const int i = static_cast<int>(pos);
    weight[t] = pos - static_cast<double>(i);
    index[t] = i;
  }
  for (int t = 0; t < n; ++t) {
    const double* table = m.term_values + t * kTable;
    const double v0 = table[index[t] & (kTable - 1)];
    shape[t] = v0 + weight[t] * (table[(index[t] + 1) & (kTable - 1)] - v0);
  }
}

}  // namespace

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__SANITIZE_THREAD__)
// (Not under ThreadSanitizer: see DRIVETWIN_ROM_KERNEL_CLONES below.)
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
  static_assert(kKernelLookups % 8 == 0, "whole vectors of 8 terms");
  const __m512d rev = _mm512_set1_pd(revs);
  const __m512d size = _mm512_set1_pd(static_cast<double>(kTable));
  const __m256i mask = _mm256_set1_epi32(kTable - 1);
  const __m256i one = _mm256_set1_epi32(1);
  for (int h = 0; h < m.lookups / 8; ++h) {
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

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__SANITIZE_THREAD__)
// One clone per x86-64 micro-architecture level; GCC's resolver picks the best at load time.
// Not under ThreadSanitizer: the resolver runs during relocation, before the TSan runtime is
// up, and its instrumented code crashed every binary linking the ROM at load.
#define DRIVETWIN_ROM_KERNEL_CLONES \
  __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#else
#define DRIVETWIN_ROM_KERNEL_CLONES
#endif

namespace {
// The step proper. The state arrays are `__restrict`: the kernel reads and writes them
// only through these pointers, so the corrector writes them in place without the
// compiler guarding every store against the model data.
// h = the forces − W_b·f_b − W_p·f_p (h holds the forces after the first when kMore) and
// the predictor r, in one pass with the fixed number of bearing and path columns.
template <int kP, bool kMore>
[[gnu::always_inline]] inline void predictor(const RomKernelModel& m, const int n_dofs,
                                             const double force0, const double* __restrict fb,
                                             const double* __restrict fp,
                                             const double* __restrict q, const double* __restrict v,
                                             const double* __restrict g, double* __restrict h,
                                             double* __restrict rp) noexcept {
  for (int i = 0; i < n_dofs; ++i) {
    double hi = force0 * m.w_force[i];
    if constexpr (kMore) hi += h[i];
    for (int j = 0; j < kB; ++j) hi -= fb[j] * m.w_bearing[j * kN + i];
    for (int j = 0; j < kP; ++j) hi -= fp[j] * m.w_path[j * kN + i];
    h[i] = hi;
    rp[i] = m.pqq[i] * q[i] + m.pqv[i] * v[i] + m.b0q[i] * g[i] + m.b1q[i] * hi;
  }
}

// kTurning: a mesh turns with the carrier (its a, b basis columns and the extra column);
// kPaths: the model has explicit path couplings. Both fixed per model: four instantiations,
// so a model without them streams none of their columns.
template <bool kTurning, bool kPaths>
[[gnu::always_inline]] inline void step(const RomKernelModel& m, const RomKernelInputs& in,
                                        double* __restrict q, double* __restrict v,
                                        double* __restrict g, double* __restrict zs,
                                        const RomKernelOutputs& out) noexcept {
  constexpr int kBasis = kTurning ? kMB : kM;
  constexpr int kP = kPaths ? kKernelPaths : 0;
  const int n_dofs = m.dofs;
  if (n_dofs % kLanes != 0 || n_dofs > kN) __builtin_unreachable();  // rom.cpp: whole vectors
  const int r = kTurning ? m.turning_mesh : 0;  // the turning mesh (kTurning only)
  if (r < 0 || r >= kM) __builtin_unreachable();
  const double cpsi = in.cos_psi, spsi = in.sin_psi;
  // The time-varying coefficients at t_{n+1}: every look-up at its phase; two constants.
  alignas(64) double val[kKernelLookups + 2];
  lookup_shapes(m, in.rotor_revolutions_next, val);
  val[kKernelLookupOne] = 1.0;
  val[kKernelLookupZero] = 0.0;
  Mesh8 k_mesh, dk, err;  // k(t), the implicit coefficient A, e(t)
  for (int j = 0; j < kM; ++j) {
    k_mesh[j] = m.mesh_mean[j] * val[m.mesh_shape[j]] * val[m.mesh_modulation[j]];
    dk[j] = k_mesh[j] - m.mesh_mean[j];
  }
  if (m.excitation) {
    for (int j = 0; j < kM; ++j) err[j] = val[m.mesh_error0[j]] + val[m.mesh_error1[j]];
  } else {
    err = Mesh8{};
  }
  // The turning mesh carries its whole stiffness along its direction at ψ, and the extra
  // column takes back the mean along the direction at ψ = 0 that the modal diagonal holds.
  if constexpr (kTurning) dk[r] = k_mesh[r];
  double k_bearing[kKernelBearings];
  double dk_bearing[kB];  // per W_b column
  for (int j = 0; j < kKernelBearings; ++j) {
    const double mean = m.bearing_mean[j];
    k_bearing[j] = mean * val[kKernelLookupBearings + j];
    dk_bearing[2 * j] = dk_bearing[2 * j + 1] = k_bearing[j] - mean;
  }
  double dk_path[kKernelPaths] = {};
  for (int j = 0; j < kP; ++j) dk_path[j] = m.path_mean[j] * (val[kKernelLookupPaths + j] - 1.0);
  double force[kKernelForces] = {};  // force[0]: the input torque (rom.cpp); 0 if none
  const double hz2 = in.rotor_hz * in.rotor_hz;
  for (int j = 0; j < m.forces; ++j) {
    const double* fr = m.force_frame + 3 * j;
    force[j] =
        (m.force_scale[j] + m.force_per_nm[j] * in.input_torque_nm + m.force_per_hz2[j] * hz2) *
        val[m.force_index0[j]] * val[m.force_index1[j]] * (fr[0] + fr[1] * cpsi + fr[2] * spsi);
  }

  // The factors of I + A G first: they depend on the stiffness coefficients only.
  Mesh8 col[kM];  // I + A G by columns: col[j][i] = δ_ij + A_i G_ij
  // Left uninitialised on purpose (per step): the factorisation writes every member it reads.
  MeshFactors fac;  // NOLINT(cppcoreguidelines-pro-type-member-init)
  Mesh8 g_extra{};  // the extra column of G at ψ (turning mesh only)
  if constexpr (!kTurning) {
    for (int j = 0; j < kM; ++j) {
      Mesh8 gj;
      __builtin_memcpy(&gj, m.g_mesh + j * kM, sizeof gj);
      col[j] = dk * gj + kUnit[j];
    }
  } else {
    // Only row and column r turn: G_rj(ψ) = G0_rj + cos ψ·Gc_rj + sin ψ·Gs_rj.
    const double c2 = cpsi * cpsi - spsi * spsi, s2 = 2.0 * spsi * cpsi;
    for (int j = 0; j < kM; ++j) {
      Mesh8 gj;
      __builtin_memcpy(&gj, m.g_mesh + j * kM, sizeof gj);
      const double turn = cpsi * m.g_mesh_cos[j * kM + r] + spsi * m.g_mesh_sin[j * kM + r];
      col[j] = dk * gj + kUnit[j] + (dk[r] * turn) * kUnit[r];
    }
    {
      Mesh8 gc, gs;
      __builtin_memcpy(&gc, m.g_mesh_cos + r * kM, sizeof gc);
      __builtin_memcpy(&gs, m.g_mesh_sin + r * kM, sizeof gs);
      // Column r: its turning parts (the diagonal's cos ψ, sin ψ terms are in gc, gs at row r,
      // already added by the loop above; here the off-diagonal ones and the 2ψ terms).
      col[r] += dk * ((cpsi * gc + spsi * gs) * (kOnes - kUnit[r]) +
                      (c2 * m.g_turning_2psi[0] + s2 * m.g_turning_2psi[1]) * kUnit[r]);
    }
    Mesh8 e0, ec, es;
    __builtin_memcpy(&e0, m.g_extra, sizeof e0);
    __builtin_memcpy(&ec, m.g_extra + kM, sizeof ec);
    __builtin_memcpy(&es, m.g_extra + 2 * kM, sizeof es);
    g_extra = e0 + cpsi * ec + spsi * es;
  }
  const bool invertible = factor_mesh_system(col, fac);

  // Explicit bearing fluctuation and path forces, at the read-out of t_n.
  double fb[kB];
  for (int j = 0; j < kB; ++j) fb[j] = dk_bearing[j] * zs[kKernelRowBearings + j];
  double fp[kKernelPaths] = {};
  for (int j = 0; j < kP; ++j) fp[j] = dk_path[j] * zs[kKernelRowPaths + j];

  // h = Φᵀf(t_{n+1}) − W_b·f_b − W_p·f_p and the predictor r (q⁺ without the implicit
  // mesh term and the transmission error).
  // The forces first, a column at a time (their count is the model's); then one fused pass
  // with the fixed number of bearing and path columns, which the compiler unrolls.
  alignas(64) double h[kN];
  alignas(64) double rp[kN];
  const bool more_forces = m.forces > 1;
  if (more_forces) {
    for (int i = 0; i < n_dofs; ++i) h[i] = force[1] * m.w_force[kN + i];
    for (int j = 2; j < m.forces; ++j) {
      const double fj = force[j];
      const double* column = m.w_force + j * kN;
      for (int i = 0; i < n_dofs; ++i) h[i] += fj * column[i];
    }
  }
  if (more_forces) {
    predictor<kP, true>(m, n_dofs, force[0], fb, fp, q, v, g, h, rp);
  } else {
    predictor<kP, false>(m, n_dofs, force[0], fb, fp, q, v, g, h, rp);
  }

  // z = R r, the read-out of the predictor, as a sum of the read-out matrix's columns (no
  // horizontal sums); kSets independent partial sums keep the floating-point adds from
  // waiting on each other. Plain loops, not Mesh8 accumulators: twelve Mesh8 fit AVX-512's
  // registers but spill on AVX2 and NEON (callgrind: 2.2× the instructions of the whole
  // step on the AVX2 clone).
  constexpr int kSets = 4;
  alignas(64) double z_sets[kSets][kZpad] = {};
  for (int i = 0; i < n_dofs; i += kSets) {
    for (int set = 0; set < kSets; ++set) {
      const double ri = rp[i + set];
      const double* column = m.readout_by_dof + (i + set) * kZpad;
      for (int k = 0; k < kZpad; ++k) z_sets[set][k] += ri * column[k];
    }
  }
  alignas(64) double z_sum[kZpad];
  for (int k = 0; k < kZpad; ++k)
    z_sum[k] = (z_sets[0][k] + z_sets[2][k]) + (z_sets[1][k] + z_sets[3][k]);
  Mesh8 z[kZv];
  __builtin_memcpy(z, z_sum, sizeof z);

  // The transmission error's known force W·(k ⊙ e), in basis coefficients, enters through
  // the read-out: z += C·kn (C = R·diag(b1q)·W_basis).
  double kn[kMB] = {};
  if (m.excitation) {
    for (int j = 0; j < kM; ++j) kn[j] = k_mesh[j] * err[j];
    if constexpr (kTurning) {
      kn[kM] = cpsi * kn[r];
      kn[kM + 1] = spsi * kn[r];
    }
    for (int j = 0; j < kBasis; ++j) {
      const double* column = m.readout_correction + j * kZpad;
      for (int b = 0; b < kZv; ++b) {
        Mesh8 cb;
        __builtin_memcpy(&cb, column + b * kM, sizeof cb);
        z[b] += cb * kn[j];
      }
    }
  }

  // Implicit mesh stiffness (Woodbury): y = (I + A G)⁻¹ A Wᵀ r, A = diag(Δk(t_{n+1})), with
  // the turning mesh's direction at ψ, and for it the extra column by its Schur complement.
  // A non-physical table (a non-positive pivot) falls back to the explicit estimate A Wᵀ r.
  Mesh8 z8 = z[0];
  double z9 = 0.0;
  if constexpr (kTurning) {
    const double zc = z[0][r], za = z[kKernelRowTurning / kM][kKernelRowTurning % kM],
                 zb = z[kKernelRowTurning / kM][kKernelRowTurning % kM + 1];
    z8 += (cpsi * za + spsi * zb) * kUnit[r];
    z9 = zc + za;
  }
  Mesh8 y = dk * z8;
  if (invertible) solve_mesh_system(fac, y);
  double y9 = 0.0;
  if (kTurning && invertible) {
    const double d9 = -m.mesh_mean[r];
    Mesh8 s = dk * g_extra;
    solve_mesh_system(fac, s);
    double gu = 0.0, gs = 0.0;
    for (int j = 0; j < kM; ++j) {
      gu += g_extra[j] * y[j];
      gs += g_extra[j] * s[j];
    }
    y9 = d9 * (z9 - gu) / (1.0 + d9 * m.g_extra_self - d9 * gs);
    y -= s * y9;
  }
  // Basis coefficients of the mesh forces, less the transmission error's.
  double ys[kMB];
  for (int j = 0; j < kM; ++j) ys[j] = y[j];
  ys[kM] = ys[kM + 1] = 0.0;
  if constexpr (kTurning) {
    ys[kM] = cpsi * y[r] + y9;
    ys[kM + 1] = spsi * y[r];
    ys[r] = y[r] + y9;
  }
  double eff[kMB];
  for (int j = 0; j < kMB; ++j) eff[j] = ys[j] - kn[j];

  // Corrector: g⁺ = h − W eff, q⁺ = r − b1q ⊙ W eff, v⁺ from the propagators; the seat
  // accelerations S q̈⁺ = S (g⁺ − c ⊙ v⁺ − ω² ⊙ q⁺) in the same pass.
  double acc0[kLanes] = {};
  double acc1[kLanes] = {};
  const double* s0 = m.sensor_rows;
  const double* s1 = m.sensor_rows + kN;
  for (int ib = 0; ib < n_dofs; ib += kLanes) {
    for (int l = 0; l < kLanes; ++l) {
      const int i = ib + l;
      double wy = 0.0;
      for (int j = 0; j < kBasis; ++j) wy += eff[j] * m.w_basis[j * kN + i];
      const double gn = h[i] - wy;
      const double vn = m.pvq[i] * q[i] + m.pvv[i] * v[i] + m.b0v[i] * g[i] + m.b1v[i] * gn;
      const double qn = rp[i] - m.b1q[i] * wy;
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

  // Read-out at t_{n+1}: R q⁺ = z − C ys (z includes C·kn).
  for (int j = 0; j < kBasis; ++j) {
    const double* column = m.readout_correction + j * kZpad;
    for (int b = 0; b < kZv; ++b) {
      Mesh8 cb;
      __builtin_memcpy(&cb, column + b * kM, sizeof cb);
      z[b] -= cb * ys[j];
    }
  }
  double z_next[kZpad];
  __builtin_memcpy(z_next, z, sizeof z_next);
  for (int k = 0; k < kZpad; ++k) zs[k] = z_next[k];

  // Forces at t_{n+1}: k(t_{n+1}) times the deflection.
  for (int j = 0; j < kM; ++j) out.mesh_force_n[j] = k_mesh[j] * (z_next[j] - err[j]);
  if constexpr (kTurning) {
    out.mesh_force_n[r] = k_mesh[r] * (z_next[r] + cpsi * z_next[kKernelRowTurning] +
                                       spsi * z_next[kKernelRowTurning + 1] - err[r]);
  }
  for (int j = 0; j < kKernelBearings; ++j) {
    out.bearing_force_x_n[j] = k_bearing[j] * z_next[kKernelRowBearings + 2 * j];
    out.bearing_force_y_n[j] = k_bearing[j] * z_next[kKernelRowBearings + 2 * j + 1];
  }
}
}  // namespace

DRIVETWIN_ROM_KERNEL_CLONES
void rom_step_kernel(const RomKernelModel& m, const RomKernelInputs& in, const RomKernelState& s,
                     const RomKernelOutputs& out) noexcept {
  const bool turning = m.turning_mesh >= 0, paths = m.paths > 0;
  if (turning) {
    if (paths) {
      step<true, true>(m, in, s.q, s.v, s.g, s.z, out);
    } else {
      step<true, false>(m, in, s.q, s.v, s.g, s.z, out);
    }
  } else if (paths) {
    step<false, true>(m, in, s.q, s.v, s.g, s.z, out);
  } else {
    step<false, false>(m, in, s.q, s.v, s.g, s.z, out);
  }
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
