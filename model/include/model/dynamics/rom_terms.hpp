#pragma once
// The time-varying terms of the reduced-order model (rom.hpp): a stiffness or a force
// whose value is a periodic table of the rotor angle. Standard library only, so that
// the ROM's step kernel (model/src/dynamics/rom_kernel.cpp, compiled without Eigen)
// reads them in place.
//
// Thread context: built off the real-time thread by build_rom(); read-only afterwards.

#include "model/dynamics/periodic_table.hpp"

namespace model::dynamics {

/// A time-varying stiffness in the ROM: k = mean·shape(order·N_rotor + phase).
struct RomStiffnessTerm {
  double mean_n_m = 0.0;      // [N/m]
  double order = 0.0;         // [cycles per rotor revolution]
  double phase_cycles = 0.0;  // [cycles]
  PeriodicTable shape = PeriodicTable::constant(1.0);
};

/// A force pattern's amplitude: (per_newton_metre ? amplitude·T_in : amplitude)·
/// shape(order·N_rotor + phase), T_in the input torque [N·m].
struct RomForceTerm {
  bool per_newton_metre = false;
  double amplitude = 0.0;     // [N or N/(N·m)]
  double order = 0.0;         // [cycles per rotor revolution]
  double phase_cycles = 0.0;  // [cycles]
  PeriodicTable shape = PeriodicTable::constant(1.0);
};

}  // namespace model::dynamics
