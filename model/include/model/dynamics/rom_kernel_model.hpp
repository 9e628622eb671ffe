#pragma once
// The pointers and counts one Rom::step() hands its kernel (model/src/dynamics/rom_kernel.hpp):
// built once per model by Rom (rom.hpp) and kept with it, so that a step does not fill
// fifty fields again. Plain data, standard library only (the kernel is compiled without
// Eigen). Capacities and layouts are rom_kernel.hpp's.

namespace model::dynamics::detail {

/// Read-only model data, pointers into RomData's storage (no copy). Every array named
/// "[c][kKernelDofs]" holds c contiguous columns of kKernelDofs values, of which the first
/// `dofs` are used.
struct RomKernelModel {
  int dofs;           // modal coordinates in use, a multiple of 8
  int lookups;        // table look-ups in use, a multiple of 8
  int forces;         // force terms in use (≥ 1: the first is the input torque's)
  int paths;          // path couplings in use
  int turning_mesh;   // the mesh whose direction turns with the carrier, −1: none
  bool excitation;    // some mesh has a transmission error
  const double* pqq;  // [kKernelDofs] first-order-hold propagators (rom.hpp)
  const double* pqv;
  const double* b0q;
  const double* b1q;
  const double* pvq;
  const double* pvv;
  const double* b0v;
  const double* b1v;
  const double* damping_1_s;     // [kKernelDofs] [1/s]
  const double* omega2;          // [kKernelDofs] [1/s²]
  const double* w_force;         // [kKernelForces][kKernelDofs]
  const double* w_bearing;       // [kKernelBearingRank][kKernelDofs]
  const double* w_path;          // [kKernelPaths][kKernelDofs]
  const double* w_basis;         // [kKernelMeshBasis][kKernelDofs]
  const double* readout_by_dof;  // [kKernelDofs][kKernelReadoutRows]: column i of the read-out
  const double* g_mesh;      // [kKernelMeshes][kKernelMeshes] G at ψ's constant part, col-major
  const double* g_mesh_cos;  // [kKernelMeshes][kKernelMeshes] its cos ψ part (turning row/col)
  const double* g_mesh_sin;  // [kKernelMeshes][kKernelMeshes] its sin ψ part
  const double* g_turning_2psi;  // [2] G_rr's cos 2ψ and sin 2ψ parts
  const double* g_extra;         // [3][kKernelMeshes] G's extra column: constant, cos ψ, sin ψ
  double g_extra_self;           // its own entry
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

}  // namespace model::dynamics::detail
