-- The assembly of a joint's halves (scripts/joint.lua) [thesis 4.2.1]: the cached specimen set up
-- for the test, its DEM surfaces measured, and the upper half brought down onto the lower one
-- until they touch.
--
--   local assembly = require("joint.assembly")
--   assembly.prepare(run)         -- numerical settings, the halves, DEM surfaces, upper half lowered
--   ...                           -- the model and its platens (joint.model)
--   assembly.first_contact(run)   -- moved down at the closure velocity, ramped, to one contact
local mat = require("materials")
local context = require("joint.context")

local LOWER, UPPER = context.LOWER, context.UPPER

local M = {}

-- Numerical settings of the test (perf/runtime_vs_error.lua chose them; 0 keeps the engine's).
local function settings(run)
  local P, world = run.P, run.world
  local dt_safety = P.dt_safety > 0 and P.dt_safety or (P.model == "rigid" and 0 or 1.0)
  if dt_safety > 0 then world:set_dt_safety(dt_safety) end
  -- The skin: a bonded specimen moves by elastic strains between rebuilds, so a thin skin (0.1 mean
  -- radius) rebuilds a few times more often than the packing's 0.4 and lists a quarter of the near
  -- misses (the elastic step: 0.86 of its cost). The rigid model's bodies travel a skin in a few
  -- hundred steps, and its step is mostly rebuilds: it keeps the packing's.
  local skin = P.skin > 0 and P.skin or (P.model == "rigid" and 0 or 0.1 * mat.packing.mean_radius)
  if skin > 0 then world:set_skin(skin) end
  -- The rigid model's halves are two bodies: an asperity contact cannot relieve itself by straining
  -- its half, and two surface spheres met head-on are pressed past each other (1.1 radii on the 3 cm
  -- S1 joint at 14 MPa) until the upper half rides over them. That is the rigid model with soft
  -- contacts (PFC has no stop), so its runs go on to just short of the centres meeting (2 radii);
  -- the WARNING above overlap_limit still says so.
  world:set_overlap_limit(P.overlap_stop > 0 and P.overlap_stop or (P.model == "rigid" and 1.9 or 1))
end

-- The DEM surfaces: profilometer, mean plane, surface vs porosity particles (surfaces.md 3); the
-- porosity particles flagged.
local function dem_surfaces(run)
  local P, world, map = run.P, run.world, run.surface.map
  run.pos, run.rad = world:positions(), world:radii()
  run.prof_lower = asperity.surface.profilometer{positions = run.pos, radii = run.rad, grid = map,
                                                 side = "lower", ids = run.lower}
  run.prof_upper = asperity.surface.profilometer{positions = run.pos, radii = run.rad, grid = map,
                                                 side = "upper", ids = run.upper,
                                                 origin = {0, 0}}
  run.plane_lower = asperity.surface.mean_plane(run.prof_lower, map)
  run.cls = asperity.surface.classify(run.prof_lower, map, P.band > 0 and {band = P.band} or nil)
  -- The upper half sits `gap` higher: its own mean plane (the shift) accounts for that.
  local cls_up_shifted = asperity.surface.classify(run.prof_upper, map, P.band > 0 and {band = P.band} or nil)
  local porosity_ids = {}
  for _, id in ipairs(run.cls.porosity) do porosity_ids[#porosity_ids + 1] = id end
  for _, id in ipairs(cls_up_shifted.porosity) do porosity_ids[#porosity_ids + 1] = id end
  world:set_flags(porosity_ids, context.POROSITY)
  run:log("DEM surface: mean plane dv = %.3g mm, %.0f %% of nodes coinciding; %.0f %% of the " ..
          "profilometer particles are on the expected surface", run.plane_lower.shift * 1e3,
          100 * run.plane_lower.coinciding_fraction, 100 * run.cls.retained_fraction)
end

-- Bring the upper half down as a whole (positions only, no dynamics) until the smallest vertical
-- gap between the two DEM surfaces is `approach_gap`; first_contact closes the rest slowly.
-- Driving a bonded half at speed into the other instead would send a stress wave through the
-- specimen larger than the target stress of the soft model.
local function lower_upper_half(run)
  local P, world, s = run.P, run.world, run.surface
  local lo_s, up_s = run.prof_lower.surface, run.prof_upper.surface
  local gap_min = math.huge
  for j = 1, s.ny do
    for i = 1, s.nx do
      local d = up_s:at(i, j) - lo_s:at(i, j)
      if d == d then gap_min = math.min(gap_min, d) end
    end
  end
  if gap_min < math.huge and gap_min > P.approach_gap then
    local dz = gap_min - P.approach_gap
    for _, id in ipairs(run.upper) do
      local p = run.pos[id]
      world:set_position(id, {p[1], p[2], p[3] - dz})
    end
    run.pos = world:positions()
    run.prof_upper = asperity.surface.profilometer{positions = run.pos, radii = run.rad, grid = s.map,
                                                   side = "upper", ids = run.upper, origin = {0, 0}}
    run:log("upper half lowered by %.3f mm (smallest gap %.3f mm)", dz * 1e3, P.approach_gap * 1e3)
  end
end

-- The specimen set up for the test: settings, the halves by tag, their DEM surfaces, the upper
-- half lowered to `approach_gap`.
function M.prepare(run)
  local world = run.world
  settings(run)
  run.N = world:particle_count()
  run.lower, run.upper = {}, {}
  for id = 1, run.N do
    local t = world:tag(id)
    if t == LOWER then run.lower[#run.lower + 1] = id elseif t == UPPER then run.upper[#run.upper + 1] = id end
  end
  -- The upper half's mean height in the frame of the mould (the cached specimen holds it `gap`
  -- higher): break depths are measured from the mean plane in that frame.
  run.upper_mean_z_mould = run:mean_height(run.upper) - run.P.gap
  dem_surfaces(run)
  lower_upper_half(run)
  run.area = run.surface.Lx * run.surface.Ly
end

-- The upper platen moved down at its velocity of the moment: rising from 0 to the closure velocity
-- over `ramp` of travel (time 2 ramp / v), `steps_done` steps on.
function M.approach_velocity(run, w, steps_done)
  run.moved_steps = run.moved_steps + steps_done
  local f = run.moved_steps >= run.ramp_steps and 1 or run.moved_steps / run.ramp_steps
  w:set_group_velocity(run.top, {0, 0, -run.P.closure_velocity * f})
end

-- Bring the halves together until exactly one contact exists [4.2.1]. The upper half does not stop
-- at the first contact, and its velocity rises from 0 over `ramp` of travel: a platen set moving at
-- the closure velocity in one step sends a wave through the soft bonded half whose force,
-- sqrt(k m) v, is of the order of a bond's strength.
function M.first_contact(run)
  local P, world = run.P, run.world
  run.ramp_steps = P.ramp > 0 and math.max(1, math.ceil(2 * P.ramp * 1e-3 / P.closure_velocity / world:dt())) or 0
  run.moved_steps = 0
  M.approach_velocity(run, world, run.ramp_steps > 0 and 1 or 0)
  local steps = world:run{steps = 10000000, every = 1, progress = P.progress,
                          callback = function(w)
                            if run.moved_steps < run.ramp_steps then M.approach_velocity(run, w, 1) end
                          end,
                          stop_when = function(w) return w:contact_summary(LOWER, UPPER).count >= 1 end}
  run:log("halves in contact after %d steps", steps)
end

return M
