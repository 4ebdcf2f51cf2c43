// Stage `contacts`: run the selected pair kernel over fixed blocks of the pair list.
#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include <algorithm>
#include <cstdint>

#include "core/cache.hpp"
#include "stages/pairs.hpp"

namespace asperity::detail {

kernels::PairKernelArgs pair_kernel_args(const PairStageView& s) {
  const ParticleStore& p = s.p;
  PairStore& q = s.pairs;
  const ContactMaterial& m = s.contact;
  return {p.x.data(), p.y.data(), p.z.data(), p.vx.data(), p.vy.data(), p.vz.data(),
          p.wx.data(), p.wy.data(), p.wz.data(), p.radius.data(), q.a.data(), q.b.data(),
          q.nx.data(), q.ny.data(), q.nz.data(), q.fsx.data(), q.fsy.data(), q.fsz.data(),
          q.out.data(), m.kn, m.ks, m.friction, s.dt, p.capacity,
          s.rest_overlaps ? q.rest.data() : nullptr, false, q.touched.data(), q.live.data()};
}
static_assert(PairStore::kTouchStage == kernels::kPairStage);

namespace {

// Records past the caches are written with non-temporal stores: the gather reads them out of
// order long after (and prefetches them, integrate.cpp), so the lines need not be read for
// ownership first. Where they would still be in cache it costs: the gather then reads them from
// memory. The thresholds are per SIMD set, each the best of trials on a machine with it:
// - four lanes (AVX2): records past the caches (records_past_caches);
// - eight lanes (AVX-512): past a third of the last-level cache on one thread, past the whole of
//   it on two or more, where the cores' private caches hold more of the step.
bool stream_pair_records(const PairStageView& s) {
  if (s.ctx.kernels->lanes != 8) return records_past_caches(s.pairs.out);
  const std::size_t bytes = s.pairs.out.size() * sizeof(double);
  const std::size_t cache = last_level_cache_bytes();
  return s.threads > 1 ? bytes > cache : bytes > cache / 3;
}

// Whether some particle the pair list can reach has an angular velocity other than +0. Rotation
// being possible (any_rotating) does not mean anything turns: in the joint every particle of a
// pair is bonded (rotation locked, model.md 5) or a member of a platen that does not rotate, and
// only the inert ones left out after packing, which no pair reaches, keep a spin. Where nothing
// spins, the law without its spin terms gives the full law's values except for the sign of an
// exact zero (contact_law.hpp). Chunks of 256 particles, so the scan vectorises and still stops
// soon where things do turn (the lattice). Where the pairs are few against the particles (a rigid
// joint: ~160 pairs at the interface of two bodies of ~1400 particles), their two particles are
// checked instead, which is the same question asked of fewer particles. Both scans run only
// where the last step did not say (Caches::spin_known: the first step, and after the API changed
// something); its answer covers every particle that is not inert, so it may say yes where a scan
// of the pairs would say no, never the reverse.
bool pairs_can_spin(const PairStageView& s) {
  if (!s.any_rotating) return false;
  // What the last step left (Caches::spin_known): the particles a pair can reach, or more.
  if (s.spin_known) return s.spin_reachable != 0;
  const ParticleStore& p = s.p;
  const PairStore& q = s.pairs;
  if (4 * q.n < p.n) {
    std::uint64_t any = 0;
    for (std::size_t k = 0; k < q.n; ++k)
      any |= p.spin_bits(std::size_t(q.a[k])) | p.spin_bits(std::size_t(q.b[k]));
    return any != 0;
  }
  const std::uint8_t* inert = p.inert.data();
  constexpr std::size_t chunk = 256;
  for (std::size_t first = 0; first < p.n; first += chunk) {
    const std::size_t end = std::min(p.n, first + chunk);
    std::uint64_t any = 0;
    for (std::size_t i = first; i < end; ++i)
      any |= p.spin_bits(i) & (std::uint64_t(0) - std::uint64_t(inert[i] == 0));
    if (any) return true;
  }
  return false;
}

}  // namespace

StageLoop pair_stage(const PairStageView& s) {
  auto args = pair_kernel_args(s);
  args.stream = stream_pair_records(s);
  const auto kernel = pairs_can_spin(s) ? s.ctx.kernels->pair : s.ctx.kernels->pair_norot;
  // Live flags (PairKernelArgs::live) where most records are dead, so that the gather skips those
  // (GatherArgs::live): a bonded specimen's pairs are near misses whose particles are bonded
  // elsewhere (a joint in mid-shear: a few per cent live), each a record line read per
  // incidence. Where most touch (the lattice) the flags would cost their stores and save nothing,
  // so they are written only every 64th step there, to notice a change.
  // Neither choice changes a bit of the results.
  PairStore& q = s.pairs;
  if (q.live_current) {
    std::size_t live = 0;
    for (const std::uint8_t t : q.touched) live += t;
    s.records_sparse = 2 * live < q.n;
  }
  q.live_written = s.records_sparse || s.step % 64 == 0;
  if (!q.live_written) args.live = nullptr;
  // A batch of pairs dead in the last step and in this one keeps its records instead of writing
  // the same zeros again: only where the flags are the last step's.
  args.keep_dead_records = q.live_written && q.live_current;
  q.live_current = q.live_written;
  const std::size_t total = s.pairs.padded;
  s.pairs.outputs_in_records = true;  // the kernel writes fn and U to the records only
  StageLoop st;
  const std::size_t block = pair_block_size(total);
  st.blocks = (total + block - 1) / block;
  s.ctx.pair_block_slip.assign(st.blocks, 0.0);
  double* slip = s.ctx.pair_block_slip.data();
  st.run = [=](std::size_t blk) {
    const std::size_t begin = blk * block;
    slip[blk] = kernel(args, begin, std::min(total, begin + block));
#if defined(__SSE2__)
    if (args.stream) _mm_sfence();  // the streamed records are visible to every thread after it
#endif
  };
  if (s.ledger)
    st.finish = [ledger = s.ledger, slip, blocks = st.blocks] {
      for (std::size_t blk = 0; blk < blocks; ++blk) ledger->friction += slip[blk];
    };
  return st;
}

}  // namespace asperity::detail
