// engine/surface/fft.cpp - FFTW wrappers (see fft.hpp for the design notes).
#include "surface/fft.hpp"

#include <fftw3.h>

#include <algorithm>
#include <memory>
#include <mutex>
#include <stdexcept>

namespace asperity::surface::detail {
namespace {

std::mutex& planner_mutex() {
  static std::mutex m;
  return m;
}

// fftw_malloc'd buffer: FFTW's SIMD codelets want their alignment.
template <class T>
struct FftwBuffer {
  explicit FftwBuffer(std::size_t count)
      : data(static_cast<T*>(fftw_malloc(sizeof(T) * std::max<std::size_t>(count, 1)))) {
    if (!data) throw std::bad_alloc();
  }
  ~FftwBuffer() { fftw_free(data); }
  FftwBuffer(const FftwBuffer&) = delete;
  FftwBuffer& operator=(const FftwBuffer&) = delete;
  T* data;
};

struct Plan {
  explicit Plan(fftw_plan p) : plan(p) {
    if (!plan) throw std::runtime_error("FFTW could not create a plan");
  }
  ~Plan() {
    std::lock_guard lock(planner_mutex());
    fftw_destroy_plan(plan);
  }
  Plan(const Plan&) = delete;
  Plan& operator=(const Plan&) = delete;
  fftw_plan plan;
};

}  // namespace

std::vector<Complex> forward_real_2d(int ny, int nx, std::span<const double> real) {
  const std::size_t n_real = static_cast<std::size_t>(ny) * nx;
  const std::size_t n_half = static_cast<std::size_t>(ny) * (nx / 2 + 1);
  if (real.size() != n_real) throw std::logic_error("forward_real_2d: size mismatch");
  FftwBuffer<double> in(n_real);
  FftwBuffer<fftw_complex> out(n_half);
  std::unique_ptr<Plan> plan;
  {
    std::lock_guard lock(planner_mutex());
    plan = std::make_unique<Plan>(fftw_plan_dft_r2c_2d(ny, nx, in.data, out.data, FFTW_ESTIMATE));
  }
  std::copy(real.begin(), real.end(), in.data);
  fftw_execute(plan->plan);
  const auto* first = reinterpret_cast<const Complex*>(out.data);
  return {first, first + n_half};
}

std::vector<double> inverse_real_2d(int ny, int nx, std::span<const Complex> half) {
  const std::size_t n_real = static_cast<std::size_t>(ny) * nx;
  const std::size_t n_half = static_cast<std::size_t>(ny) * (nx / 2 + 1);
  if (half.size() != n_half) throw std::logic_error("inverse_real_2d: size mismatch");
  FftwBuffer<fftw_complex> in(n_half);
  FftwBuffer<double> out(n_real);
  std::unique_ptr<Plan> plan;
  {
    std::lock_guard lock(planner_mutex());
    plan = std::make_unique<Plan>(fftw_plan_dft_c2r_2d(ny, nx, in.data, out.data, FFTW_ESTIMATE));
  }
  // c2r overwrites its input, so it works on this copy, never on the caller's data.
  std::copy(half.begin(), half.end(), reinterpret_cast<Complex*>(in.data));
  fftw_execute(plan->plan);
  return {out.data, out.data + n_real};
}

std::vector<Complex> forward_real_1d(std::span<const double> real) {
  const int n = static_cast<int>(real.size());
  const std::size_t n_half = static_cast<std::size_t>(n / 2 + 1);
  FftwBuffer<double> in(real.size());
  FftwBuffer<fftw_complex> out(n_half);
  std::unique_ptr<Plan> plan;
  {
    std::lock_guard lock(planner_mutex());
    plan = std::make_unique<Plan>(fftw_plan_dft_r2c_1d(n, in.data, out.data, FFTW_ESTIMATE));
  }
  std::copy(real.begin(), real.end(), in.data);
  fftw_execute(plan->plan);
  const auto* first = reinterpret_cast<const Complex*>(out.data);
  return {first, first + n_half};
}

int fft_friendly_size(int n) {
  for (int m = std::max(n, 1);; ++m) {
    int r = m;
    for (int p : {2, 3, 5, 7})
      while (r % p == 0) r /= p;
    if (r == 1) return m;
  }
}

}  // namespace asperity::surface::detail
