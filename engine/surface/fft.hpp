// engine/surface/fft.hpp - the few FFTW transforms the surface code needs, behind plain types.
//
// Design notes
// - FFTW appears only in fft.cpp; callers see std::complex<double> (layout-compatible with
//   fftw_complex, as the FFTW manual guarantees) and std::vector.
// - Real transforms only: r2c forward, c2r inverse, with FFTW's half-spectrum layout
//   ny x (nx / 2 + 1), entry (j, k) holding frequency (u = k, v = j or j - ny). The c2r transform
//   assumes Hermitian symmetry and returns a real array, so the imaginary part of the inverse
//   transform is never formed [2-38, 2-39].
// - Transforms are unnormalised (FFTW convention): forward then inverse multiplies by nx * ny.
// - Plans use FFTW_ESTIMATE: no timing runs, the same algorithm every time, hence the same
//   roundings and reproducible surfaces. The planner is not thread-safe, so planning and plan
//   destruction take a mutex; execution does not.
#pragma once

#include <complex>
#include <span>
#include <vector>

namespace asperity::surface::detail {

using Complex = std::complex<double>;

// real: ny * nx row-major. Returns ny * (nx / 2 + 1).
std::vector<Complex> forward_real_2d(int ny, int nx, std::span<const double> real);
// half: ny * (nx / 2 + 1), Hermitian in the k = 0 column (and k = nx/2 for even nx).
std::vector<double> inverse_real_2d(int ny, int nx, std::span<const Complex> half);
// 1-D: n reals to n / 2 + 1 coefficients.
std::vector<Complex> forward_real_1d(std::span<const double> real);

// The smallest 2^a 3^b 5^c 7^d >= n: sizes FFTW transforms fastest.
int fft_friendly_size(int n);

}  // namespace asperity::surface::detail
