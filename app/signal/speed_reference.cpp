#include "signal/speed_reference.hpp"

#include "model/dsp/order_tracking.hpp"
#include "model/dsp/spectrum.hpp"

namespace app::signal {

double SpeedReference::mean_hss_hz() const {
  if (pulses.size() >= 2) {
    return static_cast<double>(pulses.size() - 1) / (pulses.back() - pulses.front());
  }
  return hss_hz;
}

SpeedReference choose_speed_reference(const SpeedEvidence& e, const model::Kinematics& k) {
  const double ratio = k.overall_ratio();
  if (!e.hss_pulses_s.empty() && e.hss_pulses_s.size() >= e.min_pulses) {
    return {"tacho", e.hss_pulses_s, 0.0};
  }
  if (e.scada_rotor_rpm && *e.scada_rotor_rpm > 0.0) {
    return {"scada", {}, *e.scada_rotor_rpm / 60.0 * ratio};
  }
  const double nominal_hz = e.nominal_rotor_rpm / 60.0 * ratio;
  if (e.point1 != nullptr && e.samples > 0 && e.sample_rate_hz > 0.0) {
    const std::size_t stage = k.stage_count() - 1;
    // Mesh order of the last stage per hss revolution: its mesh frequency at 60 rpm of the
    // rotor over the hss frequency then (ratio Hz).
    const double mesh_order = k.mesh_hz(stage, 60.0) / ratio;
    model::dsp::SpectrumAnalyzer analyzer(kMeshLineFft);
    std::vector<double> work(analyzer.lines());
    const auto f =
        model::dsp::estimate_shaft_hz_from_mesh(e.point1, e.samples, e.sample_rate_hz, nominal_hz,
                                                mesh_order, kMeshLineSearch, analyzer, work.data());
    if (f) return {"mesh line", {}, *f};
  }
  return {"operating point", {}, nominal_hz};
}

}  // namespace app::signal
