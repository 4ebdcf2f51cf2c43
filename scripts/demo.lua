-- The demo: a few hundred spheres dropped into a box of plane walls settle under gravity.
--
--   build/asperity run scripts/demo.lua                 # writes out/demo/
--   build/asperity run scripts/demo.lua n=800 out=/tmp/d
--
-- Writes into `out`:
--   particles_000000.h5 ... + particles.xdmf   snapshots (open the .xdmf in ParaView; Glyph
--                                              filter, sphere, scale by radius)
--   particles_contacts.xdmf                    contacts as lines, coloured by normal_force
--   energy.h5, energy.csv                      energies and the equilibrium ratio over time
--   energy.png                                 kinetic energy and unbalanced-force ratio plots
--   summary.json                               parameters and final state
local P = require("params").parse{
  script = "demo.lua",
  path = "scripts/demo.lua",
  about = "a few hundred spheres dropped into a box settle under gravity",
  -- the box is 24 radii square and 240 tall; its lattice (pack.grid, pitch 3.6 radii) holds 6 x 6 x 66
  {"n", 400, type = "integer", min = 1, max = 2376, doc = "particles"},
  {"radius", 0.01, unit = "m", above = 0, doc = "mean radius"},
  {"ratio", 1e-3, above = 0, below = 1, doc = "unbalanced-force ratio that counts as settled"},
  {"max_steps", 100000, type = "integer", min = 1, doc = "most steps"},
  {"snapshots", 10, type = "integer", min = 0, doc = "snapshots during the fall"},
  {"out", "out/demo", nonempty = true, doc = "output folder"},
  {"seed", 1, type = "integer", min = 0, doc = "of the lattice jitter"},
  {"threads", 0, type = "integer", min = 0, doc = "0: automatic (a few hundred particles run on one thread)"},
}
if not P then return end   -- help printed
local walls = require("walls")
local pack = require("pack")
local record = require("record")

asperity.mkdir(P.out)
-- Stiff enough that gravity squeezes the contacts by ~0.1 % of a radius (m g / kn).
local world = asperity.world{
  gravity = {0, 0, -9.81},
  material = {kn = 1e4, ks = 1e3, friction = 0.5},
  damping = 0.7,
  threads = P.threads,
}

-- A box about 12 radii square, tall enough to hold the particles on a loose lattice.
local side = 12 * P.radius * 2
walls.box(world, {min = {0, 0, 0}, max = {side, side, 10 * side}, open_top = true})
pack.grid(world, {min = {0, 0, 0}, max = {side, side, 10 * side}, count = P.n,
                  radius = P.radius, spread = 0.2, gap = 0.5, seed = P.seed})

local energy = record.energy_series{n = P.n, radius = P.radius}
local snaps = asperity.snapshots{dir = P.out, name = "particles"}
snaps:write(world)

-- Record every 100 steps; snapshot a few times on the way down; stop when settled.
local steps_per_snapshot = 2000
local steps, reason = world:run{
  stop_when = "equilibrium", ratio = P.ratio, steps = P.max_steps, every = 100,
  callback = function(w)
    energy:record(record.energy_row(w))
    if w:step() % steps_per_snapshot == 0 and snaps:count() < P.snapshots then snaps:write(w) end
  end,
  show = function(w) return {contacts = w:contact_count()} end,
}
snaps:write(world)

energy:write(P.out .. "/energy")
local plotted = pcall(function()
  energy:plot{file = P.out .. "/energy.png", x = "time", y = {"kinetic"}, logy = true,
              title = ("%d spheres settling"):format(P.n), xlabel = "time (s)", ylabel = "kinetic energy (J)"}
  energy:plot{file = P.out .. "/ratio.png", x = "time", y = {"unbalanced_ratio"}, logy = true,
              title = ("%d spheres settling"):format(P.n), xlabel = "time (s)",
              ylabel = "mean unbalanced force / mean contact force"}
end)

local _, _, ztop = world:positions():max()
asperity.write_json(P.out .. "/summary.json", {
  parameters = P,
  steps = steps,
  stopped_by = reason,
  time = world:time(),
  dt = world:dt(),
  contacts = world:contact_count(),
  unbalanced_ratio = world:unbalanced_force_ratio(),
  energies = world:energies(),
  top_of_pile = ztop,
  simd = world:simd(),
})

print(("%d particles settled in %d steps (%s), %.3f s simulated; %d contacts; pile top at %.4f m")
      :format(P.n, steps, reason, world:time(), world:contact_count(), ztop))
print("wrote " .. P.out .. "/{particles.xdmf, energy.h5, energy.csv, summary.json" ..
      (plotted and ", energy.png, ratio.png}" or "} (no plot: gnuplot missing)"))
