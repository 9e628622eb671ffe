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

#include "model/dynamics/rom_kernel_model.hpp"

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
