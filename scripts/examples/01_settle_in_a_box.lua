-- Your first script: spheres fall into a box, settle, and the results go to files.
--   build/asperity run scripts/examples/01_settle_in_a_box.lua out=out/first
local out = params.out or "out/first"     -- key=value arguments arrive in `params`
asperity.mkdir(out)

local w = asperity.world{gravity = {0, 0, -9.81}, material = {kn = 1e4, ks = 1e3}, threads = 1}
require("walls").box(w, {min = {0, 0, 0}, max = {0.2, 0.2, 1}, open_top = true})
require("pack").grid(w, {min = {0, 0, 0}, max = {0.2, 0.2, 1}, count = 200, radius = 0.01,
                         spread = 0.2, gap = 0.5})

local energy = asperity.series{"time [s]", "kinetic [J]"}
w:run{stop_when = "equilibrium", ratio = 2e-2, steps = 100000, every = 100,   -- progress on a terminal
      callback = function(w) energy:record(w:time(), w:energies().kinetic) end}

asperity.snapshots{dir = out}:write(w)    -- particles_000000.h5 + particles.xdmf (ParaView)
energy:write(out .. "/energy")            -- energy.h5 + energy.csv
energy:plot{file = out .. "/energy.png", logy = true}
print(w, "->", out)
