#pragma once
// On-disk cache of history mode's load spectrum (model/fatigue/load_spectrum.hpp).
//
// A spectrum depends on the drivetrain, the rating options, the grid, the load source and
// the code that computed it. The cache key hashes all of them: every description field
// (app::config::to_toml), the options and the grid, a fingerprint of the rating code's
// behaviour (each source's stress at rated torque, cycles per revolution, S-N curve) and
// kSpectrumCodeVersion, which covers what the fingerprint cannot see (the dynamics model,
// the spectrum builder, the accumulator). A file whose key differs is never reused.
//
// File: magic "DTSPEC01", key (u64), value count (u64), values (f64), FNV-1a of the values
// (u64); written to a temporary file and renamed over the old one.
//
// Thread context: non-real-time command code (allocates, does file I/O).

#include <cstdint>
#include <filesystem>
#include <string>

#include "model/drivetrain/description.hpp"
#include "model/fatigue/drivetrain_channels.hpp"
#include "model/fatigue/load_spectrum.hpp"

namespace app::fatigue {

/// Version of the code that produces a spectrum (model/dynamics, model/fatigue,
/// app/fatigue/dynamics_spectrum). BUMP IT whenever a change there can move a spectrum value;
/// every cached spectrum then misses and is rebuilt.
///   5: K_Hβ/K_Fβ from ISO 6336-1 method C (load-dependent) instead of a constant 1.15.
///   6: dynamics spectrum ROM cut-off 2200 Hz (was 2500 Hz, which no longer fits kRomDofs).
///   7: bearing ratings C from the geometry (ISO 281:2007) when the description gives none;
///      K_Hβ eq. (53) of ISO 6336-1 Cor.1 selectable (--contact-pattern verified).
///   8: helix angle factor Z_β = 1/√cos β (ISO 6336-2:2006 §9) instead of √cos β.
///   9: bearing damage divided by ISO 281's a_ISO (lubrication and contamination inputs).
///  10: the carrier carries the planets round in the dynamics model (planet load sharing
///      varies over a carrier revolution and evens out).
inline constexpr std::uint32_t kSpectrumCodeVersion = 10;

/// The cache key of a spectrum (see the file comment). `code_version` is a parameter only so
/// that tests can show a changed version misses. `rom_rate_hz` / `rom_cutoff_hz`: the dynamics
/// spectrum's ROM when it is not DynamicsSpectrumSettings' default (0: the default, hashed
/// as before, so existing caches stay valid).
std::uint64_t spectrum_key(const model::Drivetrain& drivetrain,
                           const model::fatigue::ChannelSet& channels,
                           const model::fatigue::SpectrumGrid& grid,
                           model::fatigue::SpectrumSource source,
                           std::uint32_t code_version = kSpectrumCodeVersion,
                           double rom_rate_hz = 0.0, double rom_cutoff_hz = 0.0);

/// The cache file of `key` in `dir`: spectrum-<16 hex digits>.bin.
std::filesystem::path spectrum_cache_file(const std::filesystem::path& dir, std::uint64_t key);

/// $XDG_CACHE_HOME/drivetwin, else $HOME/.cache/drivetwin, else <tmp>/drivetwin-cache.
std::filesystem::path default_spectrum_cache_dir();

/// Loads `path` into `spectrum` (whose grid must be set) when it holds `key` and
/// `channels` values per grid point with a good checksum; false (spectrum untouched) else.
bool load_cached_spectrum(const std::filesystem::path& path, std::uint64_t key,
                          std::size_t channels, model::fatigue::LoadSpectrum& spectrum);

/// Writes the cache file; a cache that cannot be written is not an error (false, and the
/// next run rebuilds).
bool store_cached_spectrum(const std::filesystem::path& path, std::uint64_t key,
                           const model::fatigue::LoadSpectrum& spectrum);

}  // namespace app::fatigue
