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
inline constexpr int kKernelDofs = 80;  // capacity; a model uses RomKernelModel::dofs of them
inline constexpr int kKernelMeshes = 8;
/// Mesh basis columns: the meshes' directions (the turning mesh's ψ-independent part c in
/// its own slot) and the turning mesh's cos ψ and sin ψ parts a, b.
inline constexpr int kKernelMeshBasis = kKernelMeshes + 2;
inline constexpr int kKernelBearings = 6;
inline constexpr int kKernelBearingRank = 2 * kKernelBearings;
inline constexpr int kKernelPaths = 2;
inline constexpr int kKernelForces = 12;
inline constexpr int kKernelSensors = 2;
/// Rows of the read-out as the kernel stores it: meshes [0, 8), bearings [8, 20), the
/// turning mesh's a and b [20, 22), paths [22, 24) — whole vectors of 8.
inline constexpr int kKernelReadoutRows = 24;
inline constexpr int kKernelRowBearings = kKernelMeshes;
inline constexpr int kKernelRowTurning = kKernelMeshes + kKernelBearingRank;
inline constexpr int kKernelRowPaths = kKernelRowTurning + 2;
/// Table look-ups: capacity. Layout (rom.cpp): mesh shapes [0, 8), bearings [8, 14), paths
/// [14, 16), then what the model's effects and excitations need; RomKernelModel::lookups of
/// them are computed, rounded up to whole vectors of 8. Index kKernelLookups reads 1,
/// kKernelLookups + 1 reads 0 (a consumer without a table).
inline constexpr int kKernelLookups = 48;
inline constexpr int kKernelLookupOne = kKernelLookups;
inline constexpr int kKernelLookupZero = kKernelLookups + 1;
inline constexpr int kKernelLookupBearings = kKernelMeshes;
inline constexpr int kKernelLookupPaths = kKernelMeshes + kKernelBearings;
/// Samples per term table (PeriodicTable::kSize), a power of two.
inline constexpr int kKernelTableSize = 256;

/// Read-only model data, pointers into RomData's storage (no copy). Every array named
/// "[c][kKernelDofs]" holds c contiguous columns of kKernelDofs values, of which the first
/// `dofs` are used.
struct RomKernelModel {
  int dofs;     // modal coordinates in use, a multiple of 8
  int lookups;  // table look-ups in use, a multiple of 8
  int forces;   // force terms in use
  int turning_mesh;     // the mesh whose direction turns with the carrier, −1: none
  bool excitation;      // some mesh has a transmission error
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
  const double* w_path;       // [kKernelPaths][kKernelDofs]
  const double* w_basis;      // [kKernelMeshBasis][kKernelDofs]
  const double* readout_by_dof;      // [kKernelDofs][kKernelReadoutRows]: column i of the read-out
  const double* g_mesh;              // [kKernelMeshes][kKernelMeshes] G at ψ's constant part, col-major
  const double* g_mesh_cos;          // [kKernelMeshes][kKernelMeshes] its cos ψ part (turning row/col)
  const double* g_mesh_sin;          // [kKernelMeshes][kKernelMeshes] its sin ψ part
  const double* g_turning_2psi;      // [2] G_rr's cos 2ψ and sin 2ψ parts
  const double* g_extra;             // [3][kKernelMeshes] G's extra column: constant, cos ψ, sin ψ
  double g_extra_self;               // its own entry
  const double* readout_correction;  // [kKernelMeshBasis][kKernelReadoutRows]: R·diag(b1q)·W_basis
  const double* sensor_rows;         // [kKernelSensors][kKernelDofs]
  // Look-ups: order [cycles/rev], phase [cycles], tables [kKernelLookups][kKernelTableSize].
  const double* term_order;
  const double* term_phase_cycles;
  const double* term_values;
  // Meshes: mean stiffness [N/m]; look-up index of the shape, of the modulation, of two
  // transmission errors [m].
  const double* mesh_mean;
  const int* mesh_shape;
  const int* mesh_modulation;
  const int* mesh_error0;
  const int* mesh_error1;
  const double* bearing_mean;  // [kKernelBearings] [N/m]
  const double* path_mean;     // [kKernelPaths] [N/m]
  // Forces j < forces: (scale + per_nm·T + per_hz2·f_rotor²)·v[index0]·v[index1]·
  // (frame[3j] + frame[3j+1] cos ψ + frame[3j+2] sin ψ).
  const double* force_scale;
  const double* force_per_nm;
  const double* force_per_hz2;
  const int* force_index0;
  const int* force_index1;
  const double* force_frame;
};

/// Where the step writes its outputs (RomOutputs' arrays).
struct RomKernelOutputs {
  double* mesh_force_n;       // [kKernelMeshes]
  double* bearing_force_x_n;  // [kKernelBearings] in the bearing's axes (rom.cpp turns them)
  double* bearing_force_y_n;  // [kKernelBearings]
  double* acceleration_m_s2;  // [kKernelSensors]
};

/// The step's state, in and out (Rom's members).
struct RomKernelState {
  double* q;  // [kKernelDofs] modal displacement
  double* v;  // [kKernelDofs] modal velocity
  double* g;  // [kKernelDofs] modal force
  double* z;  // [kKernelReadoutRows] the read-out R q
};

/// Inputs held over the step.
struct RomKernelInputs {
  double rotor_revolutions_next;  // rotor angle at t_{n+1} [revolutions]
  double input_torque_nm;         // [N·m]
  double rotor_hz;                // [Hz]
  double cos_psi, sin_psi;        // carrier angle at t_{n+1}
};

/// Advances q, v, g, z by one step to t_{n+1} (equations in rom.hpp) and writes the outputs
/// at t_{n+1}.
void rom_step_kernel(const RomKernelModel& model, const RomKernelInputs& in,
                     const RomKernelState& state, const RomKernelOutputs& out) noexcept;

/// Which kernel the loader chose ("avx512", "avx2-fma", "baseline"): for benchmark reports.
const char* rom_step_kernel_isa() noexcept;

}  // namespace model::dynamics::detail
