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
// Equations in modal coordinates q (mass-normalised, Rayleigh damping diagonal):
//   q̈ + (η + ζω²)q̇ + ω²q = Φᵀf(t) − Σ_meshes W_j·(Δk_j(t)·W_jᵀq − k_j(t)·e_j(t))
//                          − W_b·diag(Δk_b(t))·W_bᵀq − W_p·diag(Δk_p(t))·W_pᵀq
// Time-varying stiffness is a low-rank update of the diagonal system: one column of W
// per mesh, two of W_b per bearing, one of W_p per path (effects: a planet-pass path); e
// the meshes' transmission error (an eccentric gear's run-out). k_j(t) is the mesh table
// times its modulation (a cracked tooth's window, a centre-distance change), each a table
// over its own order. A force term is an amplitude (constant, per N·m, per Hz² of rotor
// speed) times two tables times a + b cos ψ + c sin ψ (a force fixed in the housing seen
// from the carrier's axes).
//
// The carrier carries the planets round (full_model.hpp: the planetary stage and the sun
// shaft in the carrier's axes): the one element joining the two frames, the intermediate
// mesh, has a direction that turns with the carrier angle ψ, W_r(ψ) = c + cos ψ·a + sin ψ·b
// in fixed modal vectors. Its whole stiffness k_r(t) acts along W_r(ψ), and the modal
// diagonal's share of it — k̄_r along W_r(0) — is taken back by one extra implicit column
// W_r(0) with coefficient −k̄_r: the implicit mesh system stays 8×8 plus that column, solved
// by its Schur complement (two 8-vector solves with the same factors). The static
// correction vectors include K̄⁻¹a and K̄⁻¹b, so the mesh's quasi-static compliance is exact
// at every ψ. The turning axes' Coriolis and centripetal terms (≤ 2Ω = 3.1 rad/s, Ω² =
// 2.4 1/s² at rated, against ω ≥ 300 rad/s of the modes they couple) are left out; the full
// model keeps them (docs/dynamics.md measures what that costs).
//
// Time stepping, fixed Δt: each mode is advanced by its exact discrete propagator for
// a force varying linearly over the step (first-order-hold exponential integrator:
// the 4×4 matrix exponential of [q, q̇, f, ḟ], computed at build time). The mesh terms
// are implicit at t_{n+1} (Sherman–Morrison–Woodbury, one 8×8 solve per step); the bearing
// fluctuation terms are explicit (deflections of t_n).
// Stability. The modal part alone is exact, hence stable for any Δt. The stiffness changes
// are not: the first-order hold passes them between modes through the force samples at t_n
// and t_{n+1}, and for a mode the step cannot resolve (ω·Δt near or above π) that coupling
// amplifies (one mode, change δ: the step's map has spectral radius > 1 near ω·Δt = π for
// any δ > 0, e.g. 1.014 at δ = 0.1·ω², ω·Δt = 3.14). The turning mesh makes it matter: its whole
// stiffness along W_r(ψ), less the mean along W_r(0), is a change as large as the mesh stiffness
// and indefinite; with every Ritz mode dynamic the frozen-ψ step map had a spectral radius of
// 1.02–2.5 at ψ = π for 512–2048 Hz (cut-offs 60–2200 Hz), and the ROM diverged there.
// So a Ritz mode with ω·Δt > kRomQuasiStaticOmegaDt = π/2 (fewer than four steps per period:
// typically the correction vectors' Ritz modes, far above the cut-off) is advanced
// quasi-statically, q = f/ω² at t_{n+1} with no velocity (b1q = 1/ω², every other
// coefficient 0): static condensation inside the implicit mesh solve, unconditionally
// stable; what it leaves out, the mode's inertia under forcing at f, is a fraction
// (f/f_mode)² < (4·f·Δt)² of its response (f_mode > 1/(4Δt)). The frozen-ψ step map then has
// spectral radius ≤ 1 at every ψ for 512–8192 Hz (tests/model/dynamics/test_rom.cpp, RomStability:
// that map written from these equations, > 1 with every mode dynamic; and on the kernel, free
// vibration decays at 512–2048 Hz, a torque step's response converges to the 8192 Hz one as Δt
// halves). The
// explicit bearing part: for a quasi-static mode an explicit change δ gives q⁺ = −δq/ω², stable
// exactly while δ < ω², the bound build_rom() checks for every mode (δ the largest bearing and path
// swing it sees); for k_θ/k_a < 1 no bearing's fluctuation can exceed the modal stiffness it
// contributes to. Accuracy, not stability, sets
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
#include <numbers>
#include <string>
#include <string_view>
#include <vector>

#include "model/drivetrain/description.hpp"
#include "model/dynamics/full_model.hpp"
#include "model/dynamics/periodic_table.hpp"
#include "model/dynamics/rom_kernel_model.hpp"
#include "model/dynamics/rom_terms.hpp"

namespace model::dynamics {

/// Default cut-off: the third harmonic of the hss mesh at rated speed (3 × 660.7 Hz =
/// 1982 Hz) with 11 % margin.
inline constexpr double kRomDefaultCutoffHz = 2200.0;

/// Capacity of the ROM: paper-2mw with the carrier turning has 49 modes ≤ 2.2 kHz + static
/// corrections for the input torque (1), the meshes (8 + the turning mesh's 2) and the
/// bearings' static loads (6) = 66; effects add a housing mode, paths and force patterns.
/// The step runs over `RomData::dofs` of them (the count rounded up to the SIMD width of 8),
/// so an unused capacity costs memory, not time. build_rom() refuses a model that does not
/// fit (it names the count: lower the cut-off or raise this constant).
inline constexpr int kRomDofs = 80;
/// ω·Δt above which a Ritz mode is advanced quasi-statically (see "Stability" above).
inline constexpr double kRomQuasiStaticOmegaDt = std::numbers::pi / 2;
inline constexpr int kRomMeshes = 8;                  // 3 sun–planet, 3 ring–planet, 2 parallel
inline constexpr int kRomMeshBasis = kRomMeshes + 2;  // + the turning mesh's cos, sin parts
inline constexpr int kRomBearings = 6;                // b1..b6
inline constexpr int kRomBearingRank = 2 * kRomBearings;
inline constexpr int kRomPaths = 2;    // explicit rank-1 couplings (planet-pass paths)
inline constexpr int kRomForces = 12;  // input torque + effects' force terms
inline constexpr int kRomSensors = 2;  // point1, point2
/// Table look-ups a step can make (mesh shapes, bearings, paths, modulations, transmission
/// errors, force tables); a model uses RomData::lookups of them.
inline constexpr int kRomLookups = 48;
/// Rows of RomData::readout_by_dof: meshes 8, bearings 12, the turning mesh's a, b 2,
/// paths 2 — three whole SIMD vectors of 8 doubles.
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
  int dofs = 0;                // [-] modal coordinates the step runs over (multiple of 8)
  int lookups = 0;             // [-] table look-ups the step makes (multiple of 8)
  int quasi_static_modes = 0;  // [-] Ritz modes above kRomQuasiStaticOmegaDt / dt_s
  int mesh_count = 0, bearing_count = 0, path_count = 0, force_count = 0, sensor_count = 0;
  int turning_mesh = -1;     // the mesh whose direction turns with the carrier, −1: none
  bool excitation = false;   // some mesh has a transmission error
  double frame_order = 0.0;  // [-] carrier revolutions per rotor revolution (0: frozen)
  // Bearings whose x, y are the carrier frame's (reported turned into the housing frame).
  std::array<bool, kRomBearings> bearing_carrier_frame{};
  // The full model's ids of the slots [0, count): what each output index is
  // (full_model.hpp: sun_planet_1..3, ring_planet_1..3, intermediate, high_speed; b1..b6;
  // point1, point2 for paper-2mw).
  std::array<RomId, kRomMeshes> mesh_ids{};
  std::array<RomId, kRomBearings> bearing_ids{};
  std::array<RomId, kRomSensors> sensor_ids{};

  // The arrays step() streams are cache-line aligned (alignas(64)): the AVX-512 kernel
  // then never splits a load across two lines. Matrices are stored so that the kernel
  // reads contiguous columns of kRomDofs values (sensor_rows row-major).
  alignas(64) Vec omega_rad_s = Vec::Zero();  // [rad/s] Ritz frequencies (0: unused slot)
  alignas(64) Vec damping_1_s = Vec::Zero();  // [1/s] η + ζω² (+ an element's own damping)
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

  // The meshes' directions at ψ = 0 (for reports and tests: Φᵀu_j).
  Eigen::Matrix<double, kRomDofs, kRomMeshes> w_mesh = decltype(w_mesh)::Zero();
  // The step's mesh basis: column j = W_j (the turning mesh's: c), then its a and b.
  alignas(64) Eigen::Matrix<double, kRomDofs, kRomMeshBasis> w_basis = decltype(w_basis)::Zero();
  // G(ψ) = W(ψ)ᵀ diag(b1q) W(ψ) = g_mesh + cos ψ·g_mesh_cos + sin ψ·g_mesh_sin
  //        (+ g_turning_2psi·(cos 2ψ, sin 2ψ) on the turning mesh's diagonal).
  alignas(64) Eigen::Matrix<double, kRomMeshes, kRomMeshes> g_mesh = decltype(g_mesh)::Zero();
  alignas(64) Eigen::Matrix<double, kRomMeshes, kRomMeshes> g_mesh_cos =
      decltype(g_mesh_cos)::Zero();
  alignas(64) Eigen::Matrix<double, kRomMeshes, kRomMeshes> g_mesh_sin =
      decltype(g_mesh_sin)::Zero();
  std::array<double, 2> g_turning_2psi{};
  // W(ψ)ᵀ diag(b1q) W_r(0), the extra column: constant, cos ψ, sin ψ parts; and its own entry.
  alignas(64) Eigen::Matrix<double, kRomMeshes, 3> g_extra = decltype(g_extra)::Zero();
  double g_extra_self = 0.0;
  alignas(64) Eigen::Matrix<double, kRomDofs, kRomBearingRank> w_bearing =
      decltype(w_bearing)::Zero();
  alignas(64) Eigen::Matrix<double, kRomDofs, kRomPaths> w_path = decltype(w_path)::Zero();
  // The read-out R = [W_basis(0..7) W_b W_basis(8, 9) W_p]ᵀ by columns: the layout step()
  // streams (z = Σ_i r_i·column_i, one column per modal coordinate).
  alignas(64) Eigen::Matrix<double, kRomReadoutRows, kRomDofs> readout_by_dof =
      decltype(readout_by_dof)::Zero();
  // R·diag(b1q)·W_basis: the implicit mesh correction of the read-out (z⁺ = z − C·y).
  alignas(64) Eigen::Matrix<double, kRomReadoutRows, kRomMeshBasis> readout_correction =
      decltype(readout_correction)::Zero();
  alignas(64) Eigen::Matrix<double, kRomDofs, kRomForces> w_force = decltype(w_force)::Zero();
  alignas(64) Eigen::Matrix<double, kRomSensors, kRomDofs, Eigen::RowMajor> sensor_rows =
      decltype(sensor_rows)::Zero();

  // Look-ups: t < lookups reads table t at order·N_rotor + phase (rom_kernel.hpp: mesh shapes
  // [0, 8), bearings [8, 14), paths [14, 16), then the effects' and excitations' tables).
  alignas(64) std::array<double, kRomLookups> term_order{};         // [cycles/rev]
  alignas(64) std::array<double, kRomLookups> term_phase_cycles{};  // [cycles]
  // Table t at [t·PeriodicTable::kSize, (t+1)·PeriodicTable::kSize).
  alignas(64) std::array<double, kRomLookups * PeriodicTable::kSize> term_values{};
  // Consumers of the look-ups; an index kRomLookups reads 1, kRomLookups + 1 reads 0.
  std::array<double, kRomMeshes> mesh_mean_n_m{};  // [N/m]
  std::array<int, kRomMeshes> mesh_shape{};        // k_j = mean·v[shape]·v[modulation]
  std::array<int, kRomMeshes> mesh_modulation{};
  std::array<int, kRomMeshes> mesh_error0{};  // e_j = v[error0] + v[error1] [m]
  std::array<int, kRomMeshes> mesh_error1{};
  std::array<double, kRomBearings> bearing_mean_n_m{};  // [N/m]
  std::array<double, kRomPaths> path_mean_n_m{};        // [N/m]
  // Force j: (scale + per_nm·T + per_hz2·f_rotor²)·v[index0]·v[index1]·
  // (frame[3j] + frame[3j+1]·cos ψ + frame[3j+2]·sin ψ).
  std::array<double, kRomForces> force_scale{};
  std::array<double, kRomForces> force_per_nm{};
  std::array<double, kRomForces> force_per_hz2{};
  std::array<int, kRomForces> force_index0{};
  std::array<int, kRomForces> force_index1{};
  std::array<double, 3 * kRomForces> force_frame{};

  /// Value of look-up t (or the constants kRomLookups, kRomLookups + 1) at a rotor angle.
  double lookup(int t, double rotor_revolutions) const noexcept;
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
  std::array<double, kRomBearings> bearing_force_x_n{};  // [N] housing frame
  std::array<double, kRomBearings> bearing_force_y_n{};  // [N]
  std::array<double, kRomSensors> acceleration_m_s2{};   // [m/s²] point1, point2
};

class Rom {
 public:
  /// @param data must outlive the Rom (or its use until adopt() names another).
  explicit Rom(const RomData& data) noexcept;
  /// A copy runs on from the same state, independently of the original: the kernel's
  /// pointers into the Rom's own phases are bound to the copy's (a member-wise copy would
  /// leave them on the original's, or dangling once a temporary is gone). RT-safe.
  Rom(const Rom& other) noexcept;
  Rom& operator=(const Rom& other) noexcept;
  ~Rom() = default;

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
  alignas(64) RomData::Vec g_ = RomData::Vec::Zero();    // modal force at the current time
  alignas(64) std::array<double, kRomReadoutRows> z_{};  // the read-out R q
  // Sets the angle (whole + fraction, normalised to [0, 1)) and every look-up's phase and
  // the carrier angle at it.
  void set_angle(std::int64_t whole, double fraction) noexcept;
  void reset_at(const RomInputs& in, std::int64_t whole, double fraction, double t0,
                std::int64_t steps) noexcept;
  void bind_kernel() noexcept;

  double t0_ = 0.0;              // [s] time at the last reset
  std::int64_t steps_ = 0;       // [-] steps since
  std::int64_t whole_revs_ = 0;  // [rev] whole rotor revolutions
  double frac_revs_ = 0.0;       // [rev] in [0, 1)
  // frac(order·whole_revs_ + phase) per look-up [cycles] (RomData's look-up layout).
  alignas(64) std::array<double, kRomLookups> phase_base_{};
  // The carrier angle ψ at the current angle: cos, sin, and ψ/2π at the start of the
  // current revolution, frac(frame_order·whole_revs_) [cycles].
  double cos_psi_ = 1.0, sin_psi_ = 0.0, psi_base_ = 0.0;
  int steps_since_exact_ = 0;
  // Pointers into *data_ and phase_base_ for the kernel: bound by bind_kernel(), never
  // copied (a member added above must be added to the copy operations, rom.cpp).
  detail::RomKernelModel kernel_{};
};

}  // namespace model::dynamics
