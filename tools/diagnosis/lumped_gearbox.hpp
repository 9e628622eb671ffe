#pragma once
// A second, simpler gearbox model, written independently of model/dynamics, for testing
// the diagnosis on recordings its own model did not make (issue 14: "cases from a
// second, simpler generator written independently of the full model").
//
// Lumped torsional–lateral model, 12 degrees of freedom (vibration about the nominal
// rotation, SI units):
//   torsion  θc carrier, θs sun shaft (sun + g1), θi intermediate shaft (g2 + g3),
//            θh high-speed shaft (g4), θg generator (on a torsional coupling, held by a
//            weak converter spring, loaded by the reaction torque);
//   lateral  ys sun shaft, yi intermediate shaft, yh high-speed shaft, yr ring (one
//            direction: the sensors'); seat3 and seat5, the housing masses under b3 and
//            b5 that carry the sensors point2 and point1; rs, a sensor resonator that is
//            rigid to its seat unless a housing resonance is switched on.
//   meshes   the planetary stage as ONE equivalent carrier–sun mesh (spur: a large
//            single/double-contact stiffness fluctuation), the intermediate and high-speed
//            stages as helical pairs (small fluctuation), each with a static transmission
//            error at the mesh frequency; a mesh's deflection is r_a·θ_a − r_b·θ_b +
//            sin α·(y_a − y_b) (base radii of the description's gears).
//   bearings constant radial springs (b3, b5 to their seats, the others to ground).
// Integration: Newmark average acceleration with the stiffness of the end of each step,
// two steps per output sample.
//
// Effects (the diagnosis contract's ids), each in this model's own form:
//   tooth_crack        the cracked gear's mesh stiffness × (1 − loss) over the tooth's
//                      contact (a raised-cosine window ε/z of a revolution) once per gear
//                      revolution (sun: at each of the 3 planets per revolution relative
//                      to the carrier; planet: on the sun and the ring side);
//   gear_eccentricity  a transmission error e·sin(2π·gear angle) on its mesh;
//   bearing defects    half-sine impacts (0.25 ms) at the defect frequency with slip and a
//                      0.5 % random jitter, between the shaft and its seat (or ground);
//                      inner race: weighted by the load zone at the shaft speed; ball: at
//                      2·BSF weighted by the load zone at the cage speed;
//   shaft_unbalance    U·ω²·cos(shaft angle) on the shaft's lateral coordinate;
//   shaft_misalignment force F·(cos 2θ + 0.4 cos θ) lateral and 0.05 m·F·cos 2θ torque;
//   planet_pass_modulation  the planetary mesh's lateral force reaches the ring through a
//                      path whose gain follows the planets past the sensor side:
//                      1 + depth·(p(ψ) − p̄), p = Σ_n max(0, cos(ψ_n − ψ_s))⁸;
//   housing_resonance  the sensor on a light bracket of frequency f and damping ζ on the
//                      seat of its bearing (base-excited by the seat, too light to load it).
// Speed: the rotor angle is given as a function of time (a drifting speed); the dynamics
// are the perturbation about it.
// Host tool: allocates.

#include <functional>
#include <string>
#include <vector>

#include "model/drivetrain/description.hpp"

namespace tools::diagnosis {

struct LumpedEffect {
  std::string effect;     // contract id, "" for none
  std::string location;   // component id
  double severity = 0.0;  // crack: stiffness loss [-]; eccentricity [m]; bearing: impact force [N];
                          // unbalance [kg·m]; misalignment [N]; planet pass: depth [-];
                          // resonance: frequency [Hz]
  double slip = 0.01;     // [-] bearing defects
  double damping = 0.02;  // [-] housing resonance
};

struct LumpedOutput {
  std::vector<double> point1, point2;   // [m/s²] seat (or resonator) acceleration of b5, b3
  std::vector<double> hss_revolutions;  // nominal hss angle / 2π
};

/// Simulates `seconds` at `fs_hz` (after `settle_s` discarded) with the rotor angle
/// rotor_revs(t) [rev] and input torque `torque_nm`; `stiffness_scale` scales every mesh
/// and bearing stiffness (a parameter drift), `damping_scale` the damping.
LumpedOutput simulate_lumped(const model::Drivetrain& drivetrain,
                             const std::function<double(double)>& rotor_revs, double torque_nm,
                             double fs_hz, double seconds, double settle_s,
                             const std::vector<LumpedEffect>& effects, double stiffness_scale,
                             double damping_scale, unsigned seed);

}  // namespace tools::diagnosis
