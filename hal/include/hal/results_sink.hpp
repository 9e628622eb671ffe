#pragma once
// Results sink: where the twin's results go for the turbine controller / SCADA to
// read, as a REGISTER IMAGE — an array of 16-bit registers at 0-based protocol
// addresses. hal knows nothing of what the registers mean: which result lives at
// which address (the register map) is the application's (app/results/register_map.hpp);
// hal serves the image (ModbusResultsServer) or keeps it (MemoryResultsSink).
//
// Thread context: publish() from the RT thread: copies into a seqlock (LatestValue),
// wait-free; the server's own thread serves it to clients.

#include <array>
#include <cstddef>
#include <cstdint>

#include "hal/device.hpp"

namespace hal {

/// Registers an image can hold: the application's map must fit (it checks at start-up).
/// 2 × 1024 = 4 KiB, copied whole by publish().
inline constexpr std::size_t kMaxImageRegisters = 2048;

struct RegisterImage {
  std::array<std::uint16_t, kMaxImageRegisters> words{};  // [address] register values
  std::uint16_t count = 0;  // registers in use: addresses 0 .. count − 1
};

class ResultsSink : public Device {
 public:
  /// Makes `image` the registers served from now on. Wait-free.
  virtual Status publish(const RegisterImage& image) = 0;
};

}  // namespace hal
