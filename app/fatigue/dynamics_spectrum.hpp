#pragma once
// The dynamics model as the load source of the fatigue load spectrum: one ROM simulation
// (model/dynamics/simulate.hpp, simulate_rom) per (rotor torque, rotor speed) grid point,
// its mesh forces and bearing reactions converted to model::fatigue::LoadSample.
//
// Conversion (documented assumptions):
//   mesh: the ROM's force along the line of action F_bn (compression > 0) → ISO 6336's
//     transverse tangential force at the reference circle F_t = F_bn·cos α_t·cos β_b
//     (= F_bn·cos α_n·cos β, ISO 21771); a negative F_bn (teeth apart) loads nothing: 0.
//     Meshes are matched by order: ROM sun_planet_1..P, ring_planet_1..P, then one per
//     parallel stage — the ChannelSet's order; a count mismatch is an error.
//   bearings b1..b6: radial = |(F_x, F_y)| of the ROM, matched by id; axial (the ROM is
//     torsional-lateral) = the quasi-static helical thrust at the point's mean torque.
//   planet bearings pbk (not in the ROM): radial = F_t(sun–planet k) + F_t(planet k–ring),
//     the two tangential mesh forces the pin carries.
// A simulation whose mesh force leaves kDivergenceFactor × the quasi-static force fails
// the grid point with a message naming it (no damage figure from a diverged model).
// Window: the first `settle_s` are dropped (the ROM starts from the static deflection),
// then max(min_seconds, one carrier revolution, 10 planetary mesh periods) up to
// max_seconds are kept — a carrier revolution so that every planet position is seen.
//
// dynamics_grid(): the (torque, speed) grid for this source: speed spacing rated/12 with
// the rated speed itself a node (most operating time is spent there and the dynamic
// response changes quickly with speed), two nodes above rated; 31 torque nodes to 1.5·rated.
//
// Thread context: host / non-RT (allocates, runs the ROM).

#include <array>
#include <string>
#include <vector>

#include "model/drivetrain/description.hpp"
#include "model/dynamics/rom.hpp"
#include "model/fatigue/drivetrain_channels.hpp"
#include "model/fatigue/load_spectrum.hpp"

namespace app::fatigue {

/// Mesh forces beyond this multiple of the quasi-static force are taken as a diverged
/// simulation and refused (a dynamic factor of 10 is far beyond any K_v of ISO 6336-1).
inline constexpr double kDivergenceFactor = 10.0;

struct DynamicsSpectrumSettings {
  double sample_rate_hz = 8192.0;  // [Hz] ROM output (and step) rate
  double rom_cutoff_hz = 2200.0;   // [Hz] modes kept by the ROM: the ROM's own cut-off (rom.hpp:
                                   // 49 modes + 15 corrections fill kRomDofs; 2500 Hz needs 65)
  double settle_s = 0.25;          // [s] dropped at the start of each window
  double min_seconds = 2.0;        // [s] kept, at least
  double max_seconds = 16.0;       // [s] kept, at most
};

/// Converts one ROM output sample to the fatigue channels' LoadSample (the conversion
/// above). Built once (allocates); convert() is allocation-free.
class RomLoadConverter {
 public:
  RomLoadConverter(const model::Drivetrain& drivetrain, const model::fatigue::ChannelSet& channels,
                   const std::vector<std::string>& rom_mesh_ids,
                   const std::vector<std::string>& rom_bearing_ids);
  /// The same with the ids the ROM carries (RomData::mesh_ids, bearing_ids).
  RomLoadConverter(const model::Drivetrain& drivetrain, const model::fatigue::ChannelSet& channels,
                   const model::dynamics::RomData& rom);
  bool valid() const { return error_.empty(); }
  const std::string& error() const { return error_; }
  /// @param mesh_force_n ROM line-of-action forces [N]; fx, fy ROM bearing forces [N];
  /// @param mean_torque_nm the point's rotor torque (for the quasi-static axial thrust).
  void convert(const double* mesh_force_n, const double* fx, const double* fy,
               double mean_torque_nm, model::fatigue::LoadSample& out) const;
  /// Peak |F_bn| allowed at this torque before the simulation counts as diverged [N]:
  /// kDivergenceFactor × the mesh's quasi-static force at |torque| (at least a tenth of
  /// rated torque, so that a standstill is not held to a zero force).
  double divergence_limit_n(std::size_t mesh, double torque_nm) const;
  /// The same for every mesh at once (ROM mesh order), for a loop that checks every step:
  /// computed once per cycle, allocation-free.
  struct DivergenceLimits {
    std::array<double, model::fatigue::kMaxMeshes> mesh_force_n{};  // [N] |F_bn| bound
  };
  DivergenceLimits divergence_limits(double torque_nm) const noexcept;
  /// True while every mesh force F_bn [N] (ROM order) is finite and within its limit.
  bool within(const DivergenceLimits& limits, const double* mesh_force_n) const noexcept;

 private:
  const model::Drivetrain* drivetrain_;
  const model::fatigue::ChannelSet* channels_;
  std::array<int, model::fatigue::kMaxBearings> source_{};
  std::array<double, model::fatigue::kMaxMeshes> to_ft_{};
  std::size_t planets_ = 0;
  std::string error_;
};

/// The grid the dynamics spectrum uses (see above).
model::fatigue::SpectrumGrid dynamics_grid(const model::Drivetrain& drivetrain);

/// A LoadSimulator running simulate_rom on `drivetrain` (which must outlive it).
model::fatigue::LoadSimulator dynamics_simulator(const model::Drivetrain& drivetrain,
                                                 const model::fatigue::ChannelSet& channels,
                                                 const DynamicsSpectrumSettings& settings,
                                                 std::string* last_error);

}  // namespace app::fatigue
