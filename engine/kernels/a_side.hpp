// The a-side particles of a batch of pairs or bonds. Both lists are sorted by a, and a particle
// has a few pairs in a row, so the lanes' a usually lie within one lane-width window
// [a0, a0 + lanes): then one contiguous load and a lane permutation replace each a-side gather
// (ten of the twenty per batch with rotation; the gathers were most of the pair kernel's time on
// the AMD EPYC of perf/README.md). The values loaded are the same, so the results are bitwise
// those of the gathers.
#pragma once
#include <cstddef>
#include <cstdint>

namespace asperity::kernels {

template <class Lanes>
class ASide {
 public:
  using T = typename Lanes::Real;
  using I = typename Lanes::Index;
  // a: the batch's a column; ia: the same, loaded; columns: length of the particle columns (the
  // window must not read past them).
  ASide(const std::int64_t* a, const I& ia, std::size_t columns)
      : index_(ia), first_(a[0]), offset_(Lanes::offsets(ia, a[0])),
        window_(std::size_t(a[0]) + Lanes::size <= columns && Lanes::fits(offset_)) {}
  T gather(const double* col) const {
    return window_ ? Lanes::window(col + first_, offset_) : Lanes::gather(col, index_);
  }

 private:
  const I& index_;
  std::int64_t first_;
  I offset_;
  bool window_;
};

}  // namespace asperity::kernels
