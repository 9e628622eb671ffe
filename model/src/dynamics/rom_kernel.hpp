#pragma once
// The linear algebra of one Rom::step() (rom.hpp), as plain fixed-trip-count loops
// over contiguous arrays: private to model_dynamics.
//
// Why a separate translation unit without Eigen: on x86-64 the kernel is compiled
// several times (GCC target_clones: AVX-512, AVX2+FMA, baseline SSE2) and the loader
// picks the best one for the CPU once, at start-up. Eigen chooses its SIMD packets
// from the translation unit's macros, so Eigen code inside such a clone would still
// run at the baseline width, and Eigen instantiations compiled with different ISA in
// different translation units would break the one-definition rule. Plain loops have
// neither problem; GCC vectorises them for every clone, and for NEON on aarch64 (no
// clones there: NEON is the baseline).
//
// Thread context: the kernel runs on the real-time thread; it allocates nothing,
// throws nothing, takes no lock and reads no clock.

namespace model::dynamics::detail {

// Capacities (equal to kRomDofs etc. in rom.hpp; rom.cpp static_asserts that).
inline constexpr int kKernelDofs = 72;
inline constexpr int kKernelMeshes = 8;
inline constexpr int kKernelBearings = 6;
inline constexpr int kKernelBearingRank = 2 * kKernelBearings;
inline constexpr int kKernelForces = 2;
inline constexpr int kKernelSensors = 2;
/// Rows of the read-out [W W_b]ᵀ as the kernel stores it: the 8 + 12 rows padded with
/// zeros to a multiple of 8 (whole vectors).
inline constexpr int kKernelReadoutRows = 24;
/// Time-varying terms: kKernelMeshes meshes, kKernelBearings bearings, kKernelForces forces,
/// then kKernelMeshes transmission errors (one per mesh).
inline constexpr int kKernelTerms = kKernelMeshes + kKernelBearings + kKernelForces + kKernelMeshes;
/// Samples per term table (PeriodicTable::kSize), a power of two.
inline constexpr int kKernelTableSize = 256;

/// Read-only model data, pointers into RomData's Eigen storage (no copy). Every array
/// named "[c][kKernelDofs]" holds c contiguous columns of kKernelDofs values.
struct RomKernelModel {
  const double* pqq;  // [kKernelDofs] first-order-hold propagators (rom.hpp)
  const double* pqv;
  const double* b0q;
  const double* b1q;
  const double* pvq;
  const double* pvv;
  const double* b0v;
  const double* b1v;
  const double* damping_1_s;  // [kKernelDofs] [1/s]
  const double* omega2;       // [kKernelDofs] [1/s²]
  const double* w_force;      // [kKernelForces][kKernelDofs]
  const double* w_bearing;    // [kKernelBearingRank][kKernelDofs]
  const double* w_mesh;       // [kKernelMeshes][kKernelDofs]
  const double*
      readout_by_dof;    // [kKernelDofs][kKernelReadoutRows]: column i of [W W_b]ᵀ, zero-padded
  const double* g_mesh;  // [kKernelMeshes][kKernelMeshes], column-major
  const double* readout_correction;  // [kKernelMeshes][kKernelReadoutRows]: [G; H; 0] by columns
  const double* sensor_rows;         // [kKernelSensors][kKernelDofs]
  // The time-varying terms (RomData::term_*): meshes, bearings, forces, transmission errors.
  const double* term_order;         // [kKernelTerms] [cycles/rev]
  const double* term_phase_cycles;  // [kKernelTerms] [cycles]
  const double* term_scale;  // [kKernelTerms] mean stiffness [N/m] / fixed amplitude [N] / 1 (TE)
  const double* term_scale_per_nm;  // [kKernelTerms] amplitude per N·m of input torque
  const double* term_values;        // [kKernelTerms][kKernelTableSize] shape tables
};

/// Where the step writes its outputs (RomOutputs' arrays).
struct RomKernelOutputs {
  double* mesh_force_n;       // [kKernelMeshes]
  double* bearing_force_x_n;  // [kKernelBearings]
  double* bearing_force_y_n;  // [kKernelBearings]
  double* acceleration_m_s2;  // [kKernelSensors]
};

/// The step's state, in and out (Rom's members).
struct RomKernelState {
  double* q;          // [kKernelDofs] modal displacement
  double* v;          // [kKernelDofs] modal velocity
  double* g;          // [kKernelDofs] modal force
  double* z_bearing;  // [kKernelBearingRank] W_bᵀ q
  double* z_mesh;     // [kKernelMeshes] Wᵀ q
};

/// Advances q, v, g, z_bearing, z_mesh by one step to t_{n+1} (equations in rom.hpp)
/// and writes the outputs at t_{n+1}.
/// @param rotor_revolutions_next  rotor angle at t_{n+1} [revolutions]
/// @param input_torque_nm         input torque held over the step [N·m]
void rom_step_kernel(const RomKernelModel& model, double rotor_revolutions_next,
                     double input_torque_nm, const RomKernelState& state,
                     const RomKernelOutputs& out) noexcept;

/// Which kernel the loader chose ("avx512", "avx2-fma", "baseline"): for benchmark reports.
const char* rom_step_kernel_isa() noexcept;

}  // namespace model::dynamics::detail
