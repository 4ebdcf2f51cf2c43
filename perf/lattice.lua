-- Whole-step throughput on the peers' lattice scene (../shared/peers/README.md), the same scene as
-- perf/lattice_bench (perf/lattice_scene.hpp):
--   n^3 spheres d = 1 mm, density 2500, simple cubic spacing 0.99 mm with centres at (i + 1/2) a,
--   six frictional planes at 0 and n a, kn = 0.1, ks = kn 2/7, mu = 0.5, no damping, dt = 5e-4 s
--   fixed, skin 0.1 d, a tiny random initial velocity; `warmup` steps, then `steps` timed steps.
--
--   build/asperity run perf/lattice.lua n=40 steps=1000 threads=2
--   build/asperity run perf/lattice.lua n=40 bonded=true      # the same block bonded (REV material)
--
-- bonded=true: every touching pair gets an unbreakable contact + parallel bond with the REV's bond
-- stiffnesses (scripts/lib/materials.lua: beam_kn = kn, beam_ks = ks), as the bonded specimens of
-- the joint scenarios; bonded particles do not rotate (model.md 5), as there.
--
-- The last line printed is `particle-steps/s: <number>` (what perf/peers.sh reads); the one before,
-- particle-steps per CPU-second (see perf/lattice_bench.cpp).
local P = require("params").defaults{n = 40, steps = 1000, threads = 1, warmup = 200, simd = "auto",
                                     bonded = false}
local n = math.tointeger(P.n) or error("n must be an integer")
local d, rho = 1e-3, 2500.0
local a = 0.99 * d
local L = n * a
local kn = 0.1
local material = {kn = kn, ks = kn * 2 / 7, friction = 0.5}

local w = asperity.world{material = material, density = rho, damping = 0, rotation = true,
                         skin = 0.1 * d, dt = 5e-4, allow_dt_above_estimate = true,
                         threads = P.threads, simd = P.simd}

-- x fastest, as LAMMPS's create_atoms on a lattice (and perf/lattice_scene.hpp).
local xyz, k = {}, 0
for kz = 0, n - 1 do
  for jy = 0, n - 1 do
    for ix = 0, n - 1 do
      xyz[k + 1], xyz[k + 2], xyz[k + 3] = (ix + 0.5) * a, (jy + 0.5) * a, (kz + 0.5) * a
      k = k + 3
    end
  end
end
w:add_particles(xyz, 0.5 * d, rho)

-- Tiny random velocity (~1e-6 m/s): no neighbour rebuild happens within the run.
math.randomseed(4928459)
local function gauss() return 1e-6 * math.sqrt(-2 * math.log(1 - math.random())) * math.cos(2 * math.pi * math.random()) end
local v = {}
for i = 1, 3 * n * n * n do v[i] = gauss() end
w:set_velocities(v)

for _, p in ipairs{
  {{0, 0, 0}, {1, 0, 0}}, {{L, 0, 0}, {-1, 0, 0}},
  {{0, 0, 0}, {0, 1, 0}}, {{0, L, 0}, {0, -1, 0}},
  {{0, 0, 0}, {0, 0, 1}}, {{0, 0, L}, {0, 0, -1}},
} do
  w:add_plane{point = p[1], normal = p[2], material = material}
end

if P.bonded then
  local count = w:install_bonds{breakable = false, beam_kn = kn, beam_ks = kn * 2 / 7}
  w:set_dt(0)  -- the peers' fixed 5e-4 s is above the bonded block's critical step: automatic
  print(("bonded: %d bonds, dt %.3g s"):format(count, w:critical_dt() * 0.8))
end
if P.warmup > 0 then w:cycle(P.warmup) end
local st = w:stats()
print(("lattice n=%d: %d particles, %d pairs, %d contacts, %d wall contacts; simd %s, threads %d")
      :format(n, w:particle_count(), st.pairs, st.contacts, st.wall_contacts, w:simd(), P.threads))
local t0, c0 = asperity.wall_time(), os.clock()   -- os.clock: CPU time of the process
w:cycle(P.steps)
local el, cpu = asperity.wall_time() - t0, os.clock() - c0
print(("timed: %d steps in %.4f s (%.2f ns/particle-step), rebuilds during the run: %d")
      :format(P.steps, el, 1e9 * el / (w:particle_count() * P.steps), w:stats().rebuilds - st.rebuilds))
print(("cpu-particle-steps/s: %.6g"):format(w:particle_count() * P.steps / cpu))
print(("particle-steps/s: %.6g"):format(w:particle_count() * P.steps / el))
