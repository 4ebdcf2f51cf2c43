-- Cost of one shear step of the joint (scripts/joint.lua) for the rigid and the elastic model of
-- the same specimen, alternated over `rounds` so a busy machine slows both alike (issue 7 target:
-- the rigid model at least 20x cheaper per step). The rigid model also takes a far larger time
-- step (its bodies are heavy), so the cost per mm of shear is printed too.
--
--   build/asperity run perf/joint_step.lua                         -- the default 2 cm joint
--   build/asperity run perf/joint_step.lua size=0.04 rounds=1
--
-- Needs the joint's cached specimen (made by the first run of scripts/joint.lua with the same
-- size, thickness, surface and seed; made here if missing, which takes minutes).
local P = require("params").defaults{
  surface = "S1",
  size = 0.02,
  thickness = 0.006,
  elastic_shear = 0.5,  -- mm of shear timed for the elastic model (its steps are small)
  rigid_shear = 5,      -- mm for the rigid model
  rounds = 3,
  threads = 1,
  cache = "out/cache",
  out = "out/joint_step",
}
asperity.mkdir(P.out)

local function run(model, shear)
  params = {surface = P.surface, size = P.size, thickness = P.thickness, model = model,
            shear = shear, cache = P.cache, threads = P.threads, progress = false,
            snapshots = "", out = P.out .. "/" .. model}
  return dofile(asperity.scripts_dir .. "/joint.lua")
end

local per_step = {rigid = {}, elastic = {}}
local per_mm = {rigid = {}, elastic = {}}
for round = 1, P.rounds do
  for _, model in ipairs{"elastic", "rigid"} do
    local s = run(model, model == "rigid" and P.rigid_shear or P.elastic_shear)
    per_step[model][round] = s.shear_microseconds_per_step
    per_mm[model][round] = s.shear_seconds / (model == "rigid" and P.rigid_shear or P.elastic_shear)
    print(("round %d %-7s %8.1f us/step  %10.4g s/mm  (%d steps, dt %.3g s, %d particles, %d inert)"):format(
      round, model, s.shear_microseconds_per_step, per_mm[model][round], s.shear_steps, s.dt,
      s.n_particles, s.inert_particles))
  end
end
local function median(t)
  local c = {table.unpack(t)}
  table.sort(c)
  local m = #c // 2
  return #c % 2 == 1 and c[m + 1] or 0.5 * (c[m] + c[m + 1])
end
print(("median cost per shear step: elastic %.1f us, rigid %.1f us, ratio %.1fx"):format(
  median(per_step.elastic), median(per_step.rigid), median(per_step.elastic) / median(per_step.rigid)))
print(("median cost per mm of shear: elastic %.4g s, rigid %.4g s, ratio %.0fx"):format(
  median(per_mm.elastic), median(per_mm.rigid), median(per_mm.elastic) / median(per_mm.rigid)))
