// Stage `contacts`: run the selected pair kernel over fixed blocks of the pair list.
#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include "state.hpp"

namespace asperity::detail {

kernels::PairKernelArgs pair_kernel_args(State& s) {
  ParticleStore& p = s.p;
  PairStore& q = s.pairs;
  const ContactMaterial& m = s.settings.contact;
  return {p.x.data(), p.y.data(), p.z.data(), p.vx.data(), p.vy.data(), p.vz.data(),
          p.wx.data(), p.wy.data(), p.wz.data(), p.radius.data(), q.a.data(), q.b.data(),
          q.nx.data(), q.ny.data(), q.nz.data(), q.fsx.data(), q.fsy.data(), q.fsz.data(),
          q.out.data(), m.kn, m.ks, m.friction, s.dt, p.capacity,
          s.rest_overlaps ? q.rest.data() : nullptr};
}

StageLoop pair_stage(State& s) {
  auto args = pair_kernel_args(s);
  // Records past the caches are written with non-temporal stores: the gather reads them out of
  // order long after (and prefetches them, integrate.cpp), so the lines need not be read for
  // ownership first. AVX2 machine of perf/README.md, in one process: lattice n = 40 0.91-0.96 on
  // one thread, 0.86-0.91 on two; n = 46 0.90. In cache it would cost (n = 22: 1.16).
  args.stream = records_past_caches(s.pairs.out);
  const auto kernel = s.any_rotating ? s.kernels->pair : s.kernels->pair_norot;
  const std::size_t total = s.pairs.padded;
  s.pairs.outputs_in_records = true;  // the kernel writes fn and U to the records only
  StageLoop st;
  st.blocks = (total + kPairBlock - 1) / kPairBlock;
  s.pair_block_slip.assign(st.blocks, 0.0);
  double* slip = s.pair_block_slip.data();
  st.run = [=](std::size_t blk) {
    const std::size_t begin = blk * kPairBlock;
    slip[blk] = kernel(args, begin, std::min(total, begin + kPairBlock));
#if defined(__SSE2__)
    if (args.stream) _mm_sfence();  // the streamed records are visible to every thread after it
#endif
  };
  st.finish = [&s, slip, blocks = st.blocks] {
    if (s.settings.track_energy)
      for (std::size_t blk = 0; blk < blocks; ++blk) s.ledger.friction += slip[blk];
  };
  return st;
}

void compute_pair_forces(State& s) {
  StageLoop st = pair_stage(s);
  run_stages(s, {&st});
}

}  // namespace asperity::detail
