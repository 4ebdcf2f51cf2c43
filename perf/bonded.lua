-- The bonded benchmark scene (perf/peers.sh SCENE=bonded; its YADE twin is perf/bonded_yade.py):
--   n^3 spheres of the REV material (scripts/lib/materials.lua), radius 0.5 mm (the REV's mean
--   radius; one size, so every engine builds the same block), on a simple cubic lattice of
--   spacing 1 mm (= 2 R: neighbours touch without overlap, so no contact starts loaded), centres
--   at (i + 1/2) mm; every touching pair (the six face neighbours) bonded with the REV's breakable
--   bonds (contact + parallel bond, calibrated st, beam_kn = kn, beam_ks = 0.3 beam_kn, lambda = 1);
--   bonded particles do not rotate (model.md 2); local damping 0.7; no gravity, no walls.
--   Loading: the bottom layer is fixed, the top layer moves down at a constant velocity chosen so
--   that it has moved `strain` (5e-4) of the block's height at the end of the run (warm-up +
--   timed steps): a uniaxial compression at a fifth of the bonds' compressive failure strain
--   (10 st A / beam_kn over 1 mm: 2.5e-3), so no bond breaks and every engine keeps the same bonds.
--   dt = 5e-4 s fixed (0.6 of asperity's own estimate); skin 0.1 d. The top and bottom layers are
--   rigid groups: the bonds inside each layer are left out of the step (asperity's `frozen_bonds`;
--   the YADE twin leaves them out too, with the collider's avoidSelfInteractionMask).
--
--   build/asperity run perf/bonded.lua n=40 steps=1000 threads=2
--
-- Prints the particle and bond counts at the start and the end, then, as perf/lattice.lua, the
-- last line `particle-steps/s: <number>` (what perf/peers.sh reads), the one before it per
-- CPU-second.
local mat = require("materials")
local P = require("params").defaults{n = 40, steps = 1000, threads = 1, warmup = 200, simd = "auto",
                                     dt = 5e-4, strain = 5e-4}
local n = math.tointeger(P.n) or error("n must be an integer")
assert(n >= 3, "n must be at least 3")
local R = mat.packing.mean_radius
local a = 2 * R
local H = (n - 1) * a                       -- centre of the bottom layer to centre of the top one
local steps_total = P.warmup + P.steps
local v = P.strain * H / (steps_total * P.dt)

local w = asperity.world{material = mat.contact, density = mat.density, damping = mat.damping,
                         rotation_lock_bonds = mat.rev.rotation_lock_bonds, skin = 0.1 * a,
                         dt = P.dt, threads = P.threads, simd = P.simd}

-- x fastest, as perf/lattice.lua and the YADE twin.
local xyz, k = {}, 0
for kz = 0, n - 1 do
  for jy = 0, n - 1 do
    for ix = 0, n - 1 do
      xyz[k + 1], xyz[k + 2], xyz[k + 3] = (ix + 0.5) * a, (jy + 0.5) * a, (kz + 0.5) * a
      k = k + 3
    end
  end
end
w:add_particles(xyz, R, mat.density)
local bonds = w:install_bonds(mat.bond())
local per_layer = n * n
local bottom, top = {}, {}
for i = 1, per_layer do bottom[i], top[i] = i, n * n * (n - 1) + i end
w:add_group(bottom, {translation = "fixed"})
w:add_group(top, {translation = "velocity", velocity = {0, 0, -v}})
w:rebuild_neighbors()
local frozen = w:stats().frozen_bonds
local active0 = w:bond_count() - frozen

print(("bonded n=%d: %d particles, %d bonds (%d inside the two boundary layers, left out of the step), "
       .. "dt %.4g s (estimate %.4g s), top velocity %.4g m/s, st %.6g Pa")
      :format(n, w:particle_count(), bonds, frozen, w:dt(), 0.8 * w:critical_dt(), v,
              mat.rev.bond_tensile_strength))
print(("simd: %s, threads: %d"):format(w:simd(), P.threads))
if P.warmup > 0 then w:cycle(P.warmup) end
local st = w:stats()
print(("after %d warm-up steps: %d bonds, %d breaks, %d pairs")
      :format(P.warmup, w:bond_count(), w:break_count(), st.pairs))
local t0, c0 = asperity.wall_time(), os.clock()   -- os.clock: CPU time of the process
w:cycle(P.steps)
local el, cpu = asperity.wall_time() - t0, os.clock() - c0
print(("timed: %d steps in %.4f s (%.2f ns/particle-step), rebuilds during the run: %d")
      :format(P.steps, el, 1e9 * el / (w:particle_count() * P.steps), w:stats().rebuilds - st.rebuilds))
local z = w:position(n * n * (n - 1) + 1)[3]
local m = n // 2
local mid = w:position(m * n * n + m * n + m + 1)[3] - (m + 0.5) * a   -- the particle at the centre
print(("end: %d breaks, top layer moved %.4g m (strain %.3g), middle particle dz %.4g m")
      :format(w:break_count(), (n - 0.5) * a - z, ((n - 0.5) * a - z) / H, mid))
print(("bonds in the step: %d at the start, %d at the end"):format(active0, w:bond_count() - w:stats().frozen_bonds))
print(("cpu-particle-steps/s: %.6g"):format(w:particle_count() * P.steps / cpu))
print(("particle-steps/s: %.6g"):format(w:particle_count() * P.steps / el))
