-- The shear of a closed joint (scripts/joint.lua) under constant normal load or stiffness [thesis
-- 4.3.1]: the upper platen moves `shear` mm along -direction at `velocity`, ramped up over `ramp`.
--
--   require("joint.shear").run(run)   -- run.shear (series), run.e0, run.shear_impulse, ...
--
-- Writes shear.{h5,csv} (one row per `record` mm), the snapshots joint.xdmf at the `snapshots`
-- displacements (XDMF time: shear displacement, mm), events.{h5,csv} with events_every, and
-- breaks.{h5,csv} when bonds broke.
local mat = require("materials")
local params_lib = require("params")
local persist = require("persist")
local context = require("joint.context")

local MODEL_PA, ROCK_MPA = context.MODEL_PA, context.ROCK_MPA

local M = {}

-- Constant normal load. "load": the platen is free along z under a constant applied force, a dead
-- weight, undamped (local damping would bias the load it transmits by alpha times the mean force
-- noise): it follows any dilatancy at once and the load it transmits differs from the target only
-- by its inertia. "servo" (model.md 7): the platen's z velocity follows the force error, with
-- integral action (servo_integral_steps) so that a steady dilatancy rate leaves no lag.
-- "stiffness": the same servo, its target rising by normal_stiffness x the platen's rise (constant
-- normal stiffness, the engine's servo `stiffness`); it settles on sigma_0 like the CNL servo, and
-- the stiffness is switched on when the shear starts, so the dilatancy it acts on is the recorded one.
-- Returns the translation modes of the upper platen while shearing (all it does when resumed: the
-- saved world holds the platen's motion and load).
local function normal_control(run, resumed)
  local P, world, top, axis = run.P, run.world, run.top, run.axis
  local area, target_stress = run.area, run.target_stress
  local shear_velocity = {0, 0, 0}
  shear_velocity[axis] = -P.velocity
  local servo_control = P.normal_control == "servo" or P.normal_control == "stiffness"
  local modes = {"fixed", "fixed", servo_control and "servo" or "free"}
  modes[axis] = "velocity"
  if resumed then return modes end   -- the platen's motion and load are in the saved world
  if servo_control then
    world:set_group_motion(top, {translation = modes, velocity = shear_velocity,
                                 servo = {target_force = target_stress * area, max_velocity = P.servo_max_velocity * P.velocity,
                                          relaxation = P.servo_relaxation,
                                          integral_time = P.servo_integral_steps * world:dt()}})
  else  -- "load" (joint.lua's parameter table admits no other)
    world:set_group_motion(top, {translation = modes, velocity = shear_velocity, damping = P.platen_damping})
    run.applied_z = -target_stress * area
    world:set_group_force(top, {0, 0, run.applied_z})
  end
  -- Let the platen settle on the target load before shearing.
  local hold = {table.unpack(modes)}
  hold[axis] = "fixed"
  local v0 = {0, 0, 0}
  world:set_group_motion(top, {translation = hold, velocity = v0})
  local n = world:run{steps = 200000, every = 100, progress = P.progress,
            stop_when = function(w)
              return math.abs(run:normal_stress() / target_stress - 1) < 0.002 and w:unbalanced_force_ratio() < 1e-3
            end}
  run:log("settled on the normal load in %d steps", n)
  return modes
end

-- Every bond break while shearing (model.md 5), for the event statistics and maps.
local function write_breaks(run, events_before)
  local world = run.world
  if world:break_count("all") <= events_before then return end
  local breaks = asperity.series{"step [1]", "time [s]", "x [m]", "y [m]", "z [m]", "kind [1]", "mode [1]",
                                 "sigma [Pa]", "tau [Pa]", "released_energy [J]"}
  breaks:set_attribute("kind", "1 parallel bond (beam), 2 contact bond")
  breaks:set_attribute("mode", "1 tension, 2 compression, 3 shear")
  local mode_code = {tension = 1, compression = 2, shear = 3}
  for _, ev in ipairs(world:break_events(events_before + 1)) do
    breaks:record(ev.step, ev.time, ev.position[1], ev.position[2], ev.position[3], ev.kind == "beam" and 1 or 2,
                  mode_code[ev.mode] or 0, ev.sigma, ev.tau, ev.released_energy)
  end
  breaks:write(run.P.out .. "/breaks")
end

-- saved: the state of a run interrupted in its shear (joint/checkpoint.lua), to resume from.
function M.run(run, saved)
  local P, world, top, area = run.P, run.world, run.top, run.area
  run.axis = P.direction == "x" and 1 or 2
  local axis = run.axis
  -- MPa/mm scaled -> N/m of the platen: model Pa per m of rise, times the area.
  local cns_stiffness = P.normal_control == "stiffness" and P.normal_stiffness * 1e6 / run.stress_scale * 1e3 * area or 0
  local modes = normal_control(run, saved ~= nil)
  local shear = saved and run.shear or asperity.series{"displacement [mm]", "shear_stress [" .. MODEL_PA .. "]", "shear_stress_mpa [" .. ROCK_MPA .. "]",
    "normal_stress_mpa [" .. ROCK_MPA .. "]", "normal_stress_mean_mpa [" .. ROCK_MPA .. "]", "dilatancy [mm]", "contacts [1]", "contact_area [%]",
    "broken_bonds [1]", "porosity_shear_stress_mpa [" .. ROCK_MPA .. "]", "kinetic [J]", "strain [J]",
    "friction [J]", "damping [J]", "released [J]", "boundary_work [J]", "shear_work [J]",
    "dilatancy_work [J]", "time [s]"}
  run.shear = shear
  -- The shear's own state, one table, so that a checkpoint saves it whole and a resumed run
  -- continues with it (saved.locals).
  local st = saved and saved.locals or {}
  if not saved then
    run.c0 = world:group_position(top)
    run.e0 = world:energies()
    st.shear_work, st.dilatancy_work = 0, 0
    st.last_pos, st.last_force = run.c0, run:platen_force()
    st.next_snap = 1
    -- The contact points between the halves at the highest shear stress so far: at the end, those
    -- of the peak (for its contact map).
    st.peak_seen = -math.huge
    -- The normal stress averaged over each recording interval, as a load cell with a low-pass
    -- filter reads it (the instantaneous value also carries the platen's inertia at each slip event
    -- of the soft model): the change of the platen's impulse over the change of time, so nothing
    -- has to be sampled every step.
    st.last_impulse, st.last_time = world:group_impulse(top)[3], world:time()
    -- Quasi-static check: the specimen's kinetic energy against the work of the normal load over
    -- one mean radius. A rate-independent (quasi-static) test keeps it small; a start-up impact or a
    -- loading rate too high for the material shows up here long before the health checks.
    run.dynamic_ratio, run.dynamic_at = 0, 0
    run.shear_impulse = {}   -- platen impulse along the shear axis, one per record
  end
  local c0, e0 = run.c0, run.e0
  local snaps = run:snapshots("joint", "shear displacement (mm)", saved and saved.snaps.joint)
  local snap_at = {}
  for _, v in ipairs(params_lib.split(P.snapshots, true)) do snap_at[#snap_at + 1] = v end
  table.sort(snap_at)
  local energy_scale = run.target_stress * area * mat.packing.mean_radius
  local function record_shear()
    local p, f = world:group_position(top), run:platen_force()
    local impulse, now = world:group_impulse(top), world:time()
    local sn_mean = now > st.last_time and ((impulse[3] - st.last_impulse) / (now - st.last_time) - run.applied_z) / area
                    or f[3] / area
    st.last_impulse, st.last_time = impulse[3], now
    -- Work of the agent on the specimen: the force it applies is minus the particles' force.
    local last_pos, last_force = st.last_pos, st.last_force
    st.shear_work = st.shear_work - 0.5 * (f[axis] + last_force[axis]) * (p[axis] - last_pos[axis])
    st.dilatancy_work = st.dilatancy_work - 0.5 * (f[3] + last_force[3]) * (p[3] - last_pos[3])
    st.last_pos, st.last_force = p, f
    local c = run:between()
    local tau = f[axis] / area   -- the lower half resists the upper one moving along -axis
    local e = world:energies()
    if e.kinetic / energy_scale > run.dynamic_ratio then
      run.dynamic_ratio, run.dynamic_at = e.kinetic / energy_scale, run:displacement()
    end
    run:track_overlap(("%.3f mm of shear"):format(run:displacement()))
    run.shear_impulse[#run.shear_impulse + 1] = impulse[axis]
    shear:record(run:displacement(), tau, run:mpa(tau), run:mpa(f[3] / area), run:mpa(sn_mean), (p[3] - c0[3]) * 1e3,
                 c.count, 100 * c.area / area, world:break_count(), run:mpa(c.flagged_force[axis] / area),
                 e.kinetic, e.strain - e0.strain, e.friction - e0.friction, e.damping - e0.damping,
                 e.released - e0.released, e.boundary_work - e0.boundary_work, st.shear_work,
                 st.dilatancy_work, world:time())
    if run:mpa(tau) > st.peak_seen then
      st.peak_seen = run:mpa(tau)
      run.peak_points = {at = run:displacement(), step = world:step(), points = run:points_between()}
    end
    while st.next_snap <= #snap_at and run:displacement() >= snap_at[st.next_snap] - 1e-9 do
      snaps:write(world, {stage = "shear", shear_displacement_mm = run:displacement(), stress_scale = run.stress_scale},
                  run:displacement())
      st.next_snap = st.next_snap + 1
    end
  end
  if not saved then record_shear() end
  -- The time step at the shear's start sets the steps between records (the step changes as bonds
  -- break; a resumed run keeps the first one).
  if not saved then st.dt0 = world:dt() end
  local record_every = math.max(1, math.floor(P.record * 1e-3 / (P.velocity * st.dt0) + 0.5))
  -- Past the peak, the loading rate adapts to the state: the velocity doubles at each record, up to
  -- `speedup` times, while the kinetic energy stays below speedup_kinetic (the quasi-static
  -- check's scale), and halves whenever it does not. The records stay `record` mm apart: the
  -- checks run `speedup` times as often (record_every a multiple of it), and a record is due once
  -- the steps since the last one, times the velocity factor, reach record_every. speedup = 1 is the
  -- constant velocity, step for step.
  record_every = math.ceil(record_every / P.speedup) * P.speedup
  local tick = record_every // P.speedup
  if not saved then
    st.factor, st.since_record = 1, 0
    run.speedup_max, run.speedup_from = 1, nil
  end
  -- Event statistics (scenarios.md 8): the energies every `events_every` steps while shearing, on the
  -- run's sample cadence (the records, the velocity ramp and the trajectory are those of a run
  -- without samples); the breaks themselves come from world:break_events.
  if not saved then st.breaks_before, st.events_before = world:break_count(), world:break_count("all") end
  local events
  if P.events_every > 0 then
    events = saved and persist.series_from(saved.series.events)
             or asperity.series{"step [1]", "displacement [mm]", "broken_bonds [1]", "kinetic [J]", "strain [J]",
                                "damping [J]", "friction [J]", "released [J]"}
  end
  local function record_events()
    local en = world:energies()
    events:record(world:step(), run:displacement(), world:break_count() - st.breaks_before, en.kinetic, en.strain,
                  en.damping, en.friction, en.released)
  end
  if run.escape_every > 0 then run:set_escape_box(P.shear * 1e-3) end
  -- The shear's wall time and rebuilds count those before a resume too.
  if not saved then st.shear_s0, st.shear_rebuilds, st.shear_seconds = world:step(), 0, 0 end
  local shear_t0, shear_r0 = asperity.wall_time() - st.shear_seconds, world:stats().rebuilds - st.shear_rebuilds
  -- The shear velocity rises linearly over `ramp` mm (time 2 ramp / v), in one stage per record.
  local ramp_stages = P.ramp > 0 and math.max(1, math.ceil(2 * P.ramp * 1e-3 / P.velocity / st.dt0 / record_every)) or 1
  local servo_control = modes[3] == "servo"
  local function set_shear_velocity(stage)
    local v = {0, 0, 0}
    v[axis] = -st.factor * P.velocity * math.min(1, stage / ramp_stages)
    world:set_group_motion(top, {translation = modes, velocity = v})
  end
  -- The velocity factor after a record (the ramp done): up while past the peak and quasi-static,
  -- back when either ends. The servo's speed limit follows, as the dilatancy rate does.
  local upper_mass = 0  -- the upper half, carried at the shear velocity
  if P.speedup > 1 then for _, id in ipairs(run.upper) do upper_mass = upper_mass + world:mass(id) end end
  local function adapt_velocity(stage)
    if P.speedup == 1 or stage < ramp_stages then return end
    local tau = run:mpa(run:platen_force()[axis] / area)
    -- The specimen's own motion: its kinetic energy less the upper half's translation at the
    -- shear velocity, which grows with the square of the factor and says nothing of dynamics.
    local bulk = 0.5 * upper_mass * (st.factor * P.velocity) ^ 2
    local kinetic = math.max(0, world:energies().kinetic - bulk) / energy_scale
    local f = st.factor
    if kinetic >= P.speedup_kinetic or tau >= (1 - P.speedup_drop) * st.peak_seen then f = math.max(1, st.factor // 2)
    else f = math.min(P.speedup, 2 * st.factor) end
    if f == st.factor then return end
    st.factor = f
    if st.factor > run.speedup_max then run.speedup_max = st.factor end
    run.speedup_from = run.speedup_from or run:displacement()
    -- The servo's other fields are kept, and with them its CNS origin and integral.
    if servo_control then
      world:set_group_motion(top, {servo = {max_velocity = P.servo_max_velocity * st.factor * P.velocity}})
    end
    set_shear_velocity(stage)
  end
  -- A resumed run's platen already moves as saved (velocity, servo and its stiffness).
  if not saved then
    if cns_stiffness > 0 then world:set_group_motion(top, {servo = {stiffness = cns_stiffness}}) end
    set_shear_velocity(1)
    st.stage = 1
    if events then record_events() end
  end
  local steps_done = saved and saved.steps_done or 0
  local first_step = world:step() - steps_done
  local function state_now()
    st.shear_seconds, st.shear_rebuilds = asperity.wall_time() - shear_t0, world:stats().rebuilds - shear_r0
    return {phase = "shear", steps_done = world:step() - first_step, locals = st, snaps = {joint = snaps:count()},
            series = {events = events}}
  end
  run.checkpoint:catch_terminate()
  -- A state saved at the start of the shear spares a resumed run the closure.
  if not saved and run.checkpoint:enabled() then run.checkpoint:save(state_now()) end
  world:run{steps = 100000000, every = tick, progress = P.progress, steps_done = steps_done,
            sample_every = events and P.events_every or nil, sample = events and record_events or nil,
            callback = function()
              st.since_record = st.since_record + tick
              if st.since_record * st.factor < record_every then return end
              st.since_record = 0
              record_shear()
              if run.escape_every > 0 then run:remove_escaped() end
              if st.stage < ramp_stages then st.stage = st.stage + 1; set_shear_velocity(st.stage) end
              adapt_velocity(st.stage)
            end,
            -- stop less than one check before the end; the last stretch is stepped singly below, so
            -- every run ends at `shear` exactly and the residual's window is always the same. The
            -- last thing of a check: a state saved here resumes with the next step.
            stop_when = function(w)
              if run:displacement() >= P.shear - 1e3 * st.factor * P.velocity * w:dt() * (tick + 1) then return true end
              run.checkpoint:poll(state_now)
              return false
            end,
            fraction = function() return run:displacement() / P.shear end,
            show = function()
              return {disp_mm = run:displacement(), tau_mpa = run:mpa(run:platen_force()[axis] / area),
                      sigma_mpa = run:mpa(run:normal_stress())}
            end}
  run.checkpoint:release_terminate()
  world:run{steps = 100000000, every = 1, stop_when = function() return run:displacement() >= P.shear end}
  record_shear()
  if P.save ~= "" then
    world:save(P.save)
    run:log("saved the world at %.3f mm of shear to %s", run:displacement(), P.save)
  end
  run.shear_seconds, run.shear_steps = asperity.wall_time() - shear_t0, world:step() - st.shear_s0
  run.shear_rebuilds = world:stats().rebuilds - shear_r0
  run:label_series(shear)
  shear:write(P.out .. "/shear")
  if events then events:write(P.out .. "/events") end
  write_breaks(run, st.events_before)
  run:log("sheared %.2f mm", run:displacement())
end

return M
