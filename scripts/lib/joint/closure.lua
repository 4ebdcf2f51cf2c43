-- The closure of a joint (scripts/joint.lua) at constant velocity to the normal stress [thesis
-- 4.2.2], from the first contact on; the normal stiffness from its curve.
--
--   require("joint.closure").run(run)   -- run.closure (series), run.z_contact, run.normal_stiffness
--
-- Writes closure.{h5,csv} (closure from the first contact, mm; the closure less the halves' own
-- elastic shortening; normal stress; contacts between the halves; broken bonds) and the snapshots
-- joint_closure.xdmf at the first contact and at the normal stress (XDMF time: closure, mm). The
-- output folder is made here, once every refusal (parameters, the fracture model's strength check)
-- has had its say: a run that fails to start leaves no empty folder behind.
local mat = require("materials")
local context = require("joint.context")
local assembly = require("joint.assembly")

local M = {}

-- saved: the state of a run interrupted in its closure (joint/checkpoint.lua), to resume from.
function M.run(run, saved)
  local P, world = run.P, run.world
  local area, top, target_stress = run.area, run.top, run.target_stress
  if not saved then run.z_contact = world:group_position(top)[3] end
  local z_contact = run.z_contact
  asperity.mkdir(P.out)
  local function closure_mm() return 1e3 * (z_contact - world:group_position(top)[3]) end
  local closure_snaps = run:snapshots("joint_closure", "closure (mm)", saved and saved.snaps.joint_closure)
  if not saved then
    closure_snaps:write(world, {stage = "closure", closure_mm = 0, stress_scale = run.stress_scale}, 0)
    run.closure = asperity.series{"closure [mm]", "closure_corrected [mm]", "normal_stress [" .. context.MODEL_PA .. "]",
      "normal_stress_mpa [" .. context.ROCK_MPA .. "]", "contacts [1]", "contact_area [%]", "broken_bonds [1]", "time [s]"}
  end
  local closure = run.closure
  local height = run.zhi - run.zlo
  local function record_closure()
    run:track_overlap("closure")
    local s = run:normal_stress()
    local c = run:between()
    local d = z_contact - world:group_position(top)[3]
    closure:record(1e3 * d, 1e3 * (d - s * height / mat.rev.young_modulus), s, run:mpa(s), c.count,
                   100 * c.area / area, world:break_count(), world:time())
  end
  local closure_every = P.closure_every > 0 and P.closure_every or (P.model == "rigid" and 1 or 50)
  if not saved then record_closure() end
  local steps_done = saved and saved.steps_done or 0
  local first_step = world:step() - steps_done
  run.checkpoint:catch_terminate()
  world:run{steps = 10000000, every = 1, progress = P.progress, steps_done = steps_done,
            callback = function(w)
              if run.moved_steps < run.ramp_steps then assembly.approach_velocity(run, w, 1) end
              if w:step() % closure_every == 0 then record_closure() end
              if run.escape_every > 0 and w:step() % run.escape_every == 0 then run:remove_escaped() end
            end,
            -- The last thing of a check: a state saved here resumes with the next step.
            stop_when = function(w)
              if run:normal_stress() >= target_stress then return true end
              run.checkpoint:poll(function()
                return {phase = "closure", steps_done = w:step() - first_step,
                        snaps = {joint_closure = closure_snaps:count()}}
              end)
              return false
            end,
            fraction = function() return run:normal_stress() / target_stress end,
            show = function()
              return {closure_um = 1e6 * (z_contact - world:group_position(top)[3]),
                      sigma_mpa = run:mpa(run:normal_stress()), contacts = run:between().count}
            end}
  record_closure()
  run:log("closed to %.3g MPa in %.1f um", run:mpa(run:normal_stress()), 1e6 * (z_contact - world:group_position(top)[3]))
  closure_snaps:write(world, {stage = "closure", closure_mm = closure_mm(), stress_scale = run.stress_scale}, closure_mm())
  run:label_series(closure)
  closure:write(P.out .. "/closure")

  -- Normal stiffness: slope of stress against closure over the upper half of the loading.
  local cd, cs = closure:column("closure"), closure:column("normal_stress_mpa")
  local kx, ky = {}, {}
  for k = 1, closure:rows() do
    if cs[k] >= 0.5 * P.stress then kx[#kx + 1] = cd[k]; ky[#ky + 1] = cs[k] end
  end
  run.normal_stiffness = context.fit(kx, ky)   -- MPa/mm
end

return M
