// The neighbour search's linked cells (neighbor/build.cpp), kept in the caches between builds so
// that their columns' pages are mapped once, not at every build of a run that rebuilds every
// hundred steps.
#pragma once
#include <cmath>
#include <cstdint>
#include <vector>

namespace asperity::detail {

struct CellGrid {
  double ox = 0, oy = 0, oz = 0, cell = 1;
  int nx = 1, ny = 1, nz = 1;
  std::vector<std::int32_t> cell_of;   // per particle
  std::vector<std::int32_t> start;     // per cell + 1
  // Particle indices, by cell, ascending within a cell; then kMaxLanes entries of -1.
  std::vector<std::int32_t> members;
  // The binned particles' centres and radii in `members` order, then kMaxLanes zeros: the cells
  // of a row are one contiguous run for the search's kernel (kernels::NearArgs).
  std::vector<double> mx, my, mz, mr;
  // Per cell: the rigid group all its particles belong to; -1 where one is free or the cell is
  // empty, -2 where it holds members of two groups. A member's search skips the cells of its own
  // group, which hold no pair for it: in a rigid joint that is most of the cells it looks at.
  std::vector<std::int32_t> group_of_cell;
  std::int32_t longest_row = 0;  // members in three adjacent cells of a row, at most

  int clampi(double v, int n) const {
    const double c = std::floor(v / cell);
    // Compared as doubles first: a cast of a value outside int's range is undefined.
    if (!(c > 0)) return 0;
    if (c >= double(n - 1)) return n - 1;
    return static_cast<int>(c);
  }
  void coords(double x, double y, double z, int& i, int& j, int& k) const {
    i = clampi(x - ox, nx);
    j = clampi(y - oy, ny);
    k = clampi(z - oz, nz);
  }
};

}  // namespace asperity::detail
