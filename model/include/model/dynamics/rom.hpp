#pragma once
// Reduced-order model (ROM) of the drivetrain dynamics for the real-time loop.
//
// Reduction (built off the RT thread by build_rom()): every free-vibration mode of
// the full model (full_model.hpp) up to `cutoff_hz`, augmented by static correction
// vectors (residual flexibility, K̄⁻¹f − Σ φφᵀf/ω², for the input torque, each mesh's
// line of action and each bearing's static load direction — the "modal truncation
// augmentation" of Dickens, Nakagawa &
// Wittbrodt, Comput. Struct. 62 (1997)), M-orthonormalised and re-diagonalised
// (Rayleigh–Ritz). The retained modes stay exact; the static deflection under the
// input torque and every mesh's quasi-static compliance are exact too. Physical
// coordinates the loop needs are linear read-outs: mesh deflections Wᵀq, bearing
// deflections W_bᵀq, seat accelerations S q̈.
//
// Equations in modal coordinates q (mass-normalised, damping diagonal: c_i = φ_iᵀCφ_i,
// exactly 2ξ_iω_i for the retained modes since the full model's C is modal):
//   q̈ + c q̇ + ω²q = Φᵀf(t) − W·diag(Δk_mesh(t))·Wᵀq + W·(k_mesh(t) ∘ e_mesh(t))
//                    − W_b·diag(Δk_b(t))·W_bᵀq
// (e_mesh: each mesh's static transmission error, a known force k·e along its line).
// Time-varying stiffness is a low-rank update of the diagonal system: one column of W
// per mesh, two of W_b per bearing.
//
// Time stepping, fixed Δt: each mode is advanced by its exact discrete propagator for
// a force varying linearly over the step (first-order-hold exponential integrator:
// the 4×4 matrix exponential of [q, q̇, f, ḟ], computed at build time). The mesh terms
// are implicit at t_{n+1} (Sherman–Morrison–Woodbury, one 8×8 solve per step); the bearing
// fluctuation terms are explicit (deflections of t_n). Stability: the modal part is
// exact, hence stable for any Δt; the implicit mesh part is unconditionally stable;
// the explicit bearing part is stable while k_θ·|W_b column|²/ω_i² < 1 for every mode,
// which holds for k_θ/k_a < 1 because no bearing's fluctuation can exceed the modal
// stiffness it contributes to (checked by build_rom()). Accuracy, not stability, sets
// Δt: the force is interpolated linearly over a step, which scales a forcing harmonic
// at f by sinc²(π·f·Δt), sinc x = sin x / x — 2 % at 1.98 kHz (3× the rated hss mesh) for Δt = 1/25
// 600 s.
//
// How a step is computed (model/src/dynamics/rom_kernel.cpp; same equations, only the
// rounding differs): the table look-ups (one loop over the term_* arrays below; on
// AVX-512 CPUs with hardware gathers), then the factors of I + diag(Δk_mesh)·G by
// Gauss–Jordan elimination without pivoting (they depend on the stiffness only, so
// their chain of divisions runs alongside the predictor), the predictor r, the read-out
// [W W_b]ᵀr as a sum of the columns of readout_by_dof, y = (I + A G)⁻¹ A Wᵀr by the
// factors, and one fused corrector pass that also forms the seat accelerations. Plain
// fixed-length loops over the arrays below and 8-wide vectors for the 8×8 system; on
// x86-64 GCC builds the kernel three times
// (target_clones: x86-64-v4 = AVX-512, x86-64-v3 = AVX2 + FMA, baseline SSE2) and the
// loader picks one for the CPU (rom_step_isa() says which); on aarch64 it is the NEON
// baseline. The clones differ in rounding (FMA), not in the equations.
//
// Thread context: RomData is built on a non-RT thread (build_rom allocates, bounded by
// the full model's size: one n×n eigen-decomposition, n = 140 for paper-2mw; 6 ms CPU
// measured by tools/dynamics_bench).
// Rom is a pure step: fixed-size arrays, no allocation, no exceptions, no locks, no
// atomics, no clock (time is advanced by Δt per call). It knows nothing about threads:
// handing a newly built RomData (calibrated parameters) to the real-time thread and the
// old one back is the application's business (app/loop). A Rom switches model with
// adopt() (or a second Rom is reset() at the running one's time and rotor angle), which
// restarts from the new model's static equilibrium without restarting time or angle;
// rom_settle_time_s() says how long the start transient takes to decay.
//
// Time and rotor angle stay exact over the box's lifetime: time is an integer step count
// (t = t₀ + n·Δt), the rotor angle an integer count of whole revolutions plus a fraction in
// [0, 1), and every time-varying term's phase at the start of the current revolution,
// frac(order·whole + phase), is kept per term (recomputed, error-free, once per
// revolution). The step then evaluates order·fraction + that phase: a number below the
// order + 1 whatever the angle, so a speed of 15 rpm after 20 years (1.6e8 rev) advances
// the phases as exactly as on the first day. (Accumulating the angle in one double, its
// increment of ~1e-5 rev per step would be rounded to ulp(1.6e8 rev) = 3e-8 rev: a 0.3 %
// speed error, whole mesh cycles of phase lost per second.)

#include <Eigen/Dense>

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "model/drivetrain/description.hpp"
#include "model/dynamics/full_model.hpp"
#include "model/dynamics/periodic_table.hpp"
#include "model/dynamics/rom_terms.hpp"

namespace model::dynamics {

/// Default cut-off: the third harmonic of the hss mesh at rated speed (3 × 660.7 Hz =
/// 1982 Hz) with 11 % margin.
inline constexpr double kRomDefaultCutoffHz = 2200.0;

/// Capacity of the ROM, sized from paper-2mw: 49 modes ≤ 2.2 kHz + static corrections
/// for the input torque (1), the meshes (8) and the bearings' static loads (6) = 64, plus
/// room for the housing modes of the two measurement points (3 each, in band or not as
/// calibration moves them; DynamicsParameters), rounded to a multiple of the SIMD width.
/// build_rom() refuses a model that does not fit (it names the count: lower the cut-off
/// or raise this constant); unused slots are inert (zero).
inline constexpr int kRomDofs = 72;
inline constexpr int kRomMeshes = 8;    // 3 sun–planet, 3 ring–planet, 2 parallel
inline constexpr int kRomBearings = 6;  // b1..b6
inline constexpr int kRomBearingRank = 2 * kRomBearings;
inline constexpr int kRomForces = 2;   // input torque + one plug-in force
inline constexpr int kRomSensors = 2;  // point1, point2
/// Time-varying terms the step looks up: every mesh, bearing and force slot, then every
/// mesh's static transmission error.
inline constexpr int kRomTerms = kRomMeshes + kRomBearings + kRomForces + kRomMeshes;
/// Rows of RomData::readout_by_dof: the kRomMeshes + kRomBearingRank read-out rows
/// padded with zeros to whole SIMD vectors of 8 doubles.
inline constexpr int kRomReadoutRows = 24;

/// Longest mesh, bearing or sensor id a RomData carries (characters, without the
/// terminating zero). build_rom() refuses a longer id by name.
inline constexpr std::size_t kRomIdChars = 31;
/// A fixed-size, zero-terminated id ("sun_planet_1", "b5", "point1").
struct RomId {
  std::array<char, kRomIdChars + 1> chars{};
  std::string_view view() const noexcept { return std::string_view(chars.data()); }
};

/// Everything a ROM step reads: immutable after build_rom(), fixed size.
struct RomData {
  using Vec = Eigen::Matrix<double, kRomDofs, 1>;
  double dt_s = 0.0;           // [s] fixed time step
  double cutoff_hz = 0.0;      // [Hz] every full-model mode up to here is retained
  int eigenmodes = 0;          // [-] retained full-model modes
  int correction_vectors = 0;  // [-] static correction vectors
  int mesh_count = 0, bearing_count = 0, force_count = 0, sensor_count = 0;
  // The full model's ids of the slots [0, count): what each output index is
  // (full_model.hpp: sun_planet_1..3, ring_planet_1..3, intermediate, high_speed; b1..b6;
  // point1, point2 for paper-2mw).
  std::array<RomId, kRomMeshes> mesh_ids{};
  std::array<RomId, kRomBearings> bearing_ids{};
  std::array<RomId, kRomSensors> sensor_ids{};

  // The arrays step() streams are cache-line aligned (alignas(64)): the AVX-512 kernel
  // then never splits a load across two lines. Matrices are stored so that the kernel
  // reads contiguous columns of kRomDofs values (sensor_rows and readout row-major).
  alignas(64) Vec omega_rad_s = Vec::Zero();  // [rad/s] Ritz frequencies (0: unused slot)
  alignas(64) Vec damping_1_s = Vec::Zero();  // [1/s] φᵀCφ (2ξω; Rayleigh: η + ζω²)
  alignas(64) Vec omega2 = Vec::Zero();       // [1/s²]
  // First-order-hold propagators: q⁺ = pqq q + pqv v + b0q g + b1q g⁺ (same for v).
  alignas(64) Vec pqq = Vec::Zero();
  alignas(64) Vec pqv = Vec::Zero();
  alignas(64) Vec b0q = Vec::Zero();
  alignas(64) Vec b1q = Vec::Zero();
  alignas(64) Vec pvq = Vec::Zero();
  alignas(64) Vec pvv = Vec::Zero();
  alignas(64) Vec b0v = Vec::Zero();
  alignas(64) Vec b1v = Vec::Zero();

  alignas(64) Eigen::Matrix<double, kRomDofs, kRomMeshes> w_mesh = decltype(w_mesh)::Zero();
  Eigen::Matrix<double, kRomMeshes, kRomMeshes> g_mesh =
      decltype(g_mesh)::Zero();  // Wᵀ diag(b1q) W
  alignas(64) Eigen::Matrix<double, kRomDofs, kRomBearingRank> w_bearing =
      decltype(w_bearing)::Zero();
  // [W W_b]ᵀ stored row-major: both read-outs of a modal vector in one pass.
  Eigen::Matrix<double, kRomMeshes + kRomBearingRank, kRomDofs, Eigen::RowMajor> readout =
      decltype(readout)::Zero();
  // The same read-out by columns, zero-padded to kRomReadoutRows: the layout step()
  // streams (z = Σ_i r_i·column_i, one column per modal coordinate).
  alignas(64) Eigen::Matrix<double, kRomReadoutRows, kRomDofs> readout_by_dof =
      decltype(readout_by_dof)::Zero();
  // [G; H] = [W W_b]ᵀ diag(b1q) W, zero-padded like readout_by_dof: the implicit mesh
  // correction of the read-out (z⁺ = z − [G; H] y).
  alignas(64) Eigen::Matrix<double, kRomReadoutRows, kRomMeshes> readout_correction =
      decltype(readout_correction)::Zero();
  Eigen::Matrix<double, kRomBearingRank, kRomMeshes> h_bearing_mesh =
      decltype(h_bearing_mesh)::Zero();  // W_bᵀ diag(b1q) W
  alignas(64) Eigen::Matrix<double, kRomDofs, kRomForces> w_force = decltype(w_force)::Zero();
  alignas(64) Eigen::Matrix<double, kRomSensors, kRomDofs, Eigen::RowMajor> sensor_rows =
      decltype(sensor_rows)::Zero();

  std::array<RomStiffnessTerm, kRomMeshes> meshes{};
  std::array<RomStiffnessTerm, kRomBearings> bearings{};
  std::array<RomForceTerm, kRomForces> forces{};

  // The same kRomTerms time-varying terms (meshes, bearings, forces, then the meshes'
  // transmission errors) laid out
  // for the step's look-ups, copied by build_rom(): one loop over contiguous arrays and
  // tables instead of sixteen structs two kilobytes apart.
  alignas(64) std::array<double, kRomTerms> term_order{};         // [cycles/rev]
  alignas(64) std::array<double, kRomTerms> term_phase_cycles{};  // [cycles]
  // Mesh and bearing terms: the mean stiffness [N/m]; force terms: the amplitude if it is
  // not per N·m of input torque [N], else 0; transmission-error terms: 1 (tables in m).
  alignas(64) std::array<double, kRomTerms> term_scale{};
  // Force terms whose amplitude is per N·m of input torque: that amplitude [N/(N·m)]; else 0.
  alignas(64) std::array<double, kRomTerms> term_scale_per_nm{};
  // Term t's shape table at [t·PeriodicTable::kSize, (t+1)·PeriodicTable::kSize).
  alignas(64) std::array<double, kRomTerms * PeriodicTable::kSize> term_values{};
};

/// What build_rom() kept, for reports and tests.
struct RomBuildReport {
  std::vector<double> full_mode_hz;  // every full-model natural frequency [Hz], ascending
  std::vector<double> rom_mode_hz;   // the ROM's Ritz frequencies [Hz], ascending
  int eigenmodes = 0;
  int correction_vectors = 0;
};

/// Builds the ROM of `model` for time step `dt_s`, keeping every mode ≤ cutoff_hz.
/// nullptr with `error` set when the model does not fit the compile-time capacity
/// or the step/cut-off are invalid. Non-RT: allocates.
std::unique_ptr<RomData> build_rom(const FullModel& model, double dt_s, double cutoff_hz,
                                   std::string* error = nullptr, RomBuildReport* report = nullptr);

/// How the ROM of a drivetrain is built: its fixed step and its mode cut-off.
struct RomSettings {
  double dt_s = 1.0 / 25600.0;             // [s] fixed time step (1 / the ROM's sample rate)
  double cutoff_hz = kRomDefaultCutoffHz;  // [Hz] keep every full-model mode up to here
  StructuralParameters structure{};        // the full model's structural parameters
};

/// The ROM of `drivetrain` with its dynamics parameters replaced by `parameters` (e.g. a
/// calibration's result): build_full_model() then build_rom(). The ids of meshes,
/// bearings and sensors come with it (RomData::mesh_ids, ...).
/// nullptr with `error` set on an invalid description, parameters or settings.
/// Non-RT: allocates (a calibration's builder thread, start-up, host tools).
std::unique_ptr<RomData> build_rom(const Drivetrain& drivetrain,
                                   const DynamicsParameters& parameters,
                                   const RomSettings& settings, std::string* error = nullptr,
                                   RomBuildReport* report = nullptr);

/// Time for the slowest retained mode's free vibration to decay to `fraction` of its
/// start [s]: the start transient of reset()/adopt() (envelope e^{−c t/2} of
/// q̈ + c q̇ + ω² q = 0, c = η + ζω²; the slow root ω²/c… of an overdamped mode).
/// Non-RT or RT (no allocation); 0 for an empty model.
double rom_settle_time_s(const RomData& data, double fraction = 1e-3) noexcept;

/// The instruction set of the step kernel this process runs (x86-64: the target_clones
/// variant the loader picked for the CPU; aarch64: NEON). For benchmark reports.
const char* rom_step_isa() noexcept;

/// Inputs of one step, held over the step.
struct RomInputs {
  double rotor_speed_rpm = 0.0;  // [rpm]
  double input_torque_nm = 0.0;  // [N·m]
};

/// Outputs at the end of a step.
struct RomOutputs {
  std::array<double, kRomMeshes> mesh_force_n{};         // [N] compression > 0
  std::array<double, kRomBearings> bearing_force_x_n{};  // [N]
  std::array<double, kRomBearings> bearing_force_y_n{};  // [N]
  std::array<double, kRomSensors> acceleration_m_s2{};   // [m/s²] point1, point2
};

class Rom {
 public:
  /// @param data must outlive the Rom (or its use until adopt() names another).
  explicit Rom(const RomData& data) noexcept;

  /// Static equilibrium under the mean stiffness and `in` at rotor angle
  /// `rotor_revolutions` [rev] and time `time_s` [s] (both 0 at a first start; a
  /// replacement ROM takes the running one's). RT-safe.
  void reset(const RomInputs& in, double rotor_revolutions = 0.0, double time_s = 0.0) noexcept;
  /// The same at `at`'s exact time and rotor angle (a replacement started beside the running
  /// ROM: no rounding of a lifetime's angle through one double). RT-safe.
  void reset(const RomInputs& in, const Rom& at) noexcept;
  /// Switches to `next` (e.g. calibrated parameters; must outlive its use) and restarts
  /// from its static equilibrium under `in`, keeping time and rotor angle. The start
  /// transient decays within rom_settle_time_s(next). RT-safe (no allocation).
  void adopt(const RomData& next, const RomInputs& in) noexcept;
  /// Advances one fixed step Δt = data().dt_s. RT-safe.
  void step(const RomInputs& in, RomOutputs& out) noexcept;

  const RomData& data() const noexcept { return *data_; }
  /// [s] t₀ + steps·Δt (exact up to one rounding, at any age).
  double time_s() const noexcept { return t0_ + static_cast<double>(steps_) * data_->dt_s; }
  /// [rev] the rotor angle (for reports: one double; the step uses the exact split below).
  double rotor_revolutions() const noexcept {
    return static_cast<double>(whole_revs_) + frac_revs_;
  }
  std::int64_t whole_revolutions() const noexcept { return whole_revs_; }
  double revolution_fraction() const noexcept { return frac_revs_; }  // [rev] in [0, 1)
  std::int64_t steps() const noexcept { return steps_; }  // [-] steps since the last reset
  const RomData::Vec& modal_displacement() const noexcept { return q_; }
  const RomData::Vec& modal_velocity() const noexcept { return v_; }

 private:
  const RomData* data_;
  alignas(64) RomData::Vec q_ = RomData::Vec::Zero();
  alignas(64) RomData::Vec v_ = RomData::Vec::Zero();
  alignas(64) RomData::Vec g_ = RomData::Vec::Zero();  // modal force at the current time
  Eigen::Matrix<double, kRomBearingRank, 1> z_bearing_ = decltype(z_bearing_)::Zero();
  Eigen::Matrix<double, kRomMeshes, 1> z_mesh_ = decltype(z_mesh_)::Zero();
  // Sets the angle (whole + fraction, normalised to [0, 1)) and every term's phase at it.
  void set_angle(std::int64_t whole, double fraction) noexcept;
  void reset_at(const RomInputs& in, std::int64_t whole, double fraction, double t0,
                std::int64_t steps) noexcept;

  double t0_ = 0.0;              // [s] time at the last reset
  std::int64_t steps_ = 0;       // [-] steps since
  std::int64_t whole_revs_ = 0;  // [rev] whole rotor revolutions
  double frac_revs_ = 0.0;       // [rev] in [0, 1)
  // frac(order·whole_revs_ + phase) per term [cycles] (RomData's term layout).
  alignas(64) std::array<double, kRomTerms> phase_base_{};
};

}  // namespace model::dynamics
