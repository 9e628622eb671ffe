#include "model/diagnosis/fft.hpp"

#include <kissfft/kissfft.hh>

namespace model::diagnosis {

namespace {
bool smooth_235(std::size_t n) {
  if (n == 0) return false;
  for (const std::size_t p : {2u, 3u, 5u}) {
    while (n % p == 0) n /= p;
  }
  return n == 1;
}
}  // namespace

std::size_t fft_size_at_least(std::size_t n) {
  if (n <= 1) return 1;
  while (!smooth_235(n)) ++n;
  return n;
}

std::size_t fft_size_at_most(std::size_t n) {
  while (n > 0 && !smooth_235(n)) --n;
  return n;
}

struct Fft::Plans {
  explicit Plans(std::size_t n) : forward(n, false), inverse(n, true) {}
  kissfft<double> forward;
  kissfft<double> inverse;
};

Fft::Fft(std::size_t n) : n_(n), plans_(n > 0 ? std::make_unique<Plans>(n) : nullptr) {}

Fft::~Fft() = default;

void Fft::forward(const Complex* in, Complex* out) const {
  if (n_ == 0) return;
  plans_->forward.transform(in, out);
}

void Fft::inverse(const Complex* in, Complex* out) const {
  if (n_ == 0) return;
  plans_->inverse.transform(in, out);
  const double scale = 1.0 / static_cast<double>(n_);
  for (std::size_t i = 0; i < n_; ++i) out[i] *= scale;
}

}  // namespace model::diagnosis
