#pragma once
// Complex discrete Fourier transforms for the diagnosis toolkit, through kissfft
// (Debian libkissfft-dev, the header-only C++ template `kissfft.hh`, double precision).
//
// Sizes whose only prime factors are 2, 3 and 5 run on kissfft's radix-2/3/4/5
// butterflies (fast, no scratch memory); fft_size_at_least()/fft_size_at_most() pick
// such sizes. Any other size works but is slow for large prime factors.
//
// Thread context: construct off the real-time thread (the plan allocates its twiddle
// tables); forward()/inverse() are allocation-free for 2·3·5-smooth sizes. One owning
// thread per object.

#include <complex>
#include <cstddef>
#include <memory>

namespace model::diagnosis {

using Complex = std::complex<double>;

/// Smallest n' ≥ n whose prime factors are all 2, 3 or 5 (n' ≥ 1).
std::size_t fft_size_at_least(std::size_t n);
/// Largest n' ≤ n whose prime factors are all 2, 3 or 5 (0 for n = 0).
std::size_t fft_size_at_most(std::size_t n);

class Fft {
 public:
  explicit Fft(std::size_t n);
  ~Fft();
  Fft(const Fft&) = delete;
  Fft& operator=(const Fft&) = delete;

  std::size_t size() const { return n_; }
  /// X_k = Σ_n x_n·e^(−2πikn/N), k = 0..N−1 (in and out may not alias).
  void forward(const Complex* in, Complex* out) const;
  /// x_n = 1/N·Σ_k X_k·e^(+2πikn/N) (normalised: inverse(forward(x)) = x).
  void inverse(const Complex* in, Complex* out) const;

 private:
  struct Plans;
  std::size_t n_ = 0;
  std::unique_ptr<Plans> plans_;
};

}  // namespace model::diagnosis
