// Fuzz the CMS CAN frame decoder and the frame→block path. Properties checked
// beyond "no crash, no UB": a frame that decodes re-encodes to the same bytes
// (the decoder accepts exactly the encoder's language), and the ingest counters
// account for every frame.
//
// Input layout: a stream of records [flags(1) id_lo(1) len(1) data(len)]:
//   flags bit0 fd, bit1 error, bit2 extended, bits 3..5 id bits 8..10, bit6 classic int24.
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "hal/cms_can_protocol.hpp"
#include "hal/cms_ingest.hpp"

namespace {
constexpr std::uint32_t kBase = 0x180;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  hal::CmsIngestConfig cfg;
  cfg.base_id = kBase;
  cfg.scale.fill(0.001f);
  hal::CmsIngest ingest(cfg);
  std::uint64_t frames = 0, delivered = 0;
  std::size_t pos = 0;
  std::int64_t t_ns = 0;
  while (pos + 3 <= size) {
    const std::uint8_t flags = data[pos];
    hal::CanFrame f;
    f.fd = flags & 1u;
    f.error = flags & 2u;
    f.extended = flags & 4u;
    f.id = ((flags >> 3) & 7u) << 8 | data[pos + 1];
    f.len = static_cast<std::uint8_t>(data[pos + 2] % 65);
    pos += 3;
    const std::size_t n = std::min<std::size_t>(f.len, size - pos);
    std::memcpy(f.data.data(), data + pos, n);
    pos += n;
    const auto classic =
        (flags & 64u) ? hal::CmsSampleFormat::kInt24 : hal::CmsSampleFormat::kInt16;

    hal::CmsFrame decoded;
    if (hal::decode_cms_frame(f, kBase, classic, decoded) == hal::CmsDecodeError::kNone) {
      hal::CanFrame again;
      const bool ok = f.fd ? hal::encode_cms_fd_frame(decoded, kBase, again)
                           : hal::encode_cms_classic_frame(decoded, kBase, again);
      if (!ok || again.len != f.len || std::memcmp(again.data.data(), f.data.data(), f.len) != 0)
        std::abort();
    }
    {
      frames += f.error ? 0 : 1;
      hal::CmsBlock b;
      t_ns += 1000;
      const hal::Status s = ingest.ingest(f, hal::Timestamp{t_ns}, b);
      if (s == hal::Status::kOk || s == hal::Status::kGap) {
        ++delivered;
        ingest.count_delivered();
        if (b.count == 0 || b.count > hal::kCmsMaxSamplesPerBlock ||
            b.channel >= hal::kCmsMaxChannels)
          std::abort();
      }
    }
  }
  const hal::CmsStreamStats st = ingest.stats();
  if (st.blocks != delivered || st.blocks + st.malformed + st.duplicates + st.reordered != frames)
    std::abort();
  return 0;
}
