#include "fatigue/spectrum_cache.hpp"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <vector>

#include "config/drivetrain_file.hpp"

namespace app::fatigue {
namespace {

namespace mf = model::fatigue;
namespace fs = std::filesystem;

constexpr char kSpectrumMagic[8] = {'D', 'T', 'S', 'P', 'E', 'C', '0', '1'};
constexpr std::uint64_t kFnvOffset = 1469598103934665603ull;

std::uint64_t fnv1a(std::uint64_t h, const void* data, std::size_t n) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
  return h;
}

}  // namespace

std::uint64_t spectrum_key(const model::Drivetrain& d, const mf::ChannelSet& cs,
                           const mf::SpectrumGrid& g, mf::SpectrumSource source,
                           std::uint32_t code_version, double rom_rate_hz, double rom_cutoff_hz) {
  const mf::ChannelOptions& o = cs.options();
  std::uint64_t h = kFnvOffset;
  const std::string tag = "drivetwin-spectrum";
  h = fnv1a(h, tag.data(), tag.size());
  h = fnv1a(h, &code_version, sizeof code_version);
  const mf::LoadSample rated = cs.quasi_static_loads(d.turbine.rated_torque_nm);
  for (std::size_t c = 0; c < cs.channel_count(); ++c) {
    const mf::Channel& ch = cs.channel(c);
    for (std::size_t k = 0; k < ch.source_count; ++k) {
      const double v[] = {cs.stress(c, k, rated),
                          ch.sources[k].cycles_per_rotor_rev,
                          ch.curve.m,
                          ch.curve.c,
                          ch.curve.n_ref,
                          ch.curve.knee_cycles};
      h = fnv1a(h, v, sizeof v);
    }
  }
  const std::string toml = app::config::to_toml(d);
  h = fnv1a(h, toml.data(), toml.size());
  const double nums[] = {o.k_a,
                         o.rating.k_h_beta_override,
                         o.rating.face_load.f_ma_factor,
                         o.rating.face_load.pinion_offset_ratio,
                         o.rating.c_gamma_n_mm_um,
                         o.rating.rack.addendum,
                         o.rating.rack.dedendum,
                         o.rating.rack.root_radius,
                         g.torque_max_nm,
                         g.speed_min_rpm,
                         g.speed_max_rpm,
                         o.lubrication.enabled ? 1.0 : 0.0,
                         o.lubrication.viscosity_40c_mm2_s,
                         o.lubrication.viscosity_100c_mm2_s,
                         o.lubrication.temperature_c,
                         o.lubrication.contamination_factor};
  h = fnv1a(h, nums, sizeof nums);
  const int ints[] = {o.rating.accuracy_grade,
                      static_cast<int>(o.branch),
                      static_cast<int>(g.torque_points),
                      static_cast<int>(g.speed_points),
                      static_cast<int>(source),
                      static_cast<int>(o.rating.face_load.lead),
                      o.rating.face_load.case_hardened ? 1 : 0,
                      o.rating.face_load.contact_pattern_verified ? 1 : 0};
  h = fnv1a(h, ints, sizeof ints);
  if (rom_rate_hz > 0.0 || rom_cutoff_hz > 0.0) {
    const double rom[] = {rom_rate_hz, rom_cutoff_hz};
    h = fnv1a(h, rom, sizeof rom);
  }
  return h;
}

fs::path spectrum_cache_file(const fs::path& dir, std::uint64_t key) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(key));
  return dir / (std::string("spectrum-") + buf + ".bin");
}

fs::path default_spectrum_cache_dir() {
  if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x) return fs::path(x) / "drivetwin";
  if (const char* h = std::getenv("HOME"); h && *h) return fs::path(h) / ".cache" / "drivetwin";
  return fs::temp_directory_path() / "drivetwin-cache";
}

bool load_cached_spectrum(const fs::path& path, std::uint64_t key, std::size_t channels,
                          mf::LoadSpectrum& s) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  char magic[8];
  std::uint64_t k = 0, n = 0, check = 0;
  in.read(magic, 8);
  in.read(reinterpret_cast<char*>(&k), sizeof k);
  in.read(reinterpret_cast<char*>(&n), sizeof n);
  if (!in || std::memcmp(magic, kSpectrumMagic, 8) != 0 || k != key) return false;
  const std::size_t expect =
      static_cast<std::size_t>(s.grid.torque_points) * s.grid.speed_points * channels;
  if (n != expect) return false;
  std::vector<double> v(n);
  in.read(reinterpret_cast<char*>(v.data()), static_cast<std::streamsize>(n * sizeof(double)));
  in.read(reinterpret_cast<char*>(&check), sizeof check);
  if (!in || check != fnv1a(kFnvOffset, v.data(), n * sizeof(double))) return false;
  s.damage_per_rev = std::move(v);
  s.channel_count = channels;
  return true;
}

bool store_cached_spectrum(const fs::path& path, std::uint64_t key, const mf::LoadSpectrum& s) {
  std::error_code ec;
  fs::create_directories(path.parent_path(), ec);
  const fs::path tmp = path.string() + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) return false;
    const std::uint64_t n = s.damage_per_rev.size();
    const std::uint64_t check = fnv1a(kFnvOffset, s.damage_per_rev.data(), n * sizeof(double));
    out.write(kSpectrumMagic, 8);
    out.write(reinterpret_cast<const char*>(&key), sizeof key);
    out.write(reinterpret_cast<const char*>(&n), sizeof n);
    out.write(reinterpret_cast<const char*>(s.damage_per_rev.data()),
              static_cast<std::streamsize>(n * sizeof(double)));
    out.write(reinterpret_cast<const char*>(&check), sizeof check);
    if (!out) return false;
  }
  fs::rename(tmp, path, ec);
  return !ec;
}

}  // namespace app::fatigue
