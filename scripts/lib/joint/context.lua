-- The run context of a joint test (scripts/joint.lua): one table that every phase in
-- scripts/lib/joint/ takes and hands on, holding the parameters, the world and what each phase
-- leaves for the next, and the measures more than one phase takes on it.
--
--   local run = require("joint.context").new(P)    -- P: joint.lua's checked parameters
--   require("joint.genesis").specimen(run)         -- ... each phase reads and fills run
--   run:log("closed to %.3g MPa", run:mpa(run:normal_stress()))
--
-- What the phases leave in it:
--   new        P, t_start, stress_scale, target_stress (model Pa), applied_z, overlap_max,
--              overlap_at, overlap_turning_max, overlap_turning_at, escaped_count
--   checkpoint checkpoint (joint/checkpoint.lua: saves the state, resumes from it), resumes
--   genesis    surface (the height map and the mould), cache_file, world, genesis_record
--   assembly   N, lower, upper (ids of the halves), upper_mean_z_mould, pos, rad, prof_lower,
--              prof_upper, plane_lower, cls, area, ramp_steps, moved_steps
--   model      zlo, zhi, bottom, top (the platens' groups), platen_particles, bonds_at_start,
--              escape_every, escape_box
--   closure    z_contact, closure (series), normal_stiffness
--   shear      axis, c0, e0, shear (series), shear_impulse, dynamic_ratio, dynamic_at, peak_points,
--              shear_seconds, shear_steps, shear_rebuilds
--   report     summary
local mat = require("materials")
local specimen = require("specimen")

local M = {}

-- Tags of the particles; POROSITY is a flag bit (surface vs porosity particles, surfaces.md 3).
M.LOWER, M.UPPER, M.LOST, M.POROSITY = 1, 2, 3, 1
-- Units of the stress columns in the HDF5 and CSV files: the model's own Pa, or MPa scaled to the
-- rock by stress_scale [3-37] (an attribute of every file, with the run's parameters).
M.MODEL_PA, M.ROCK_MPA = "Pa (model)", "MPa (scaled to rock)"

local Run = {}
Run.__index = Run

function M.new(P)
  local run = setmetatable({P = P, t_start = asperity.wall_time()}, Run)
  -- The REV calibrated with the same bond installation as the halves (scripts/lib/materials.lua)
  -- sets the stress scale [3-37].
  run.stress_scale = mat.rock.young_modulus / mat.rev.young_modulus
  run.target_stress = P.stress * 1e6 / run.stress_scale                -- model units, Pa
  run.applied_z = 0          -- the dead load on the upper platen (normal_control=load)
  run.overlap_max, run.overlap_at = 0, "closure"
  run.overlap_turning_max, run.overlap_turning_at = 0, "closure"
  run.escaped_count = 0
  return run
end

function Run:log(fmt, ...) io.stderr:write(("[joint] " .. fmt .. "\n"):format(...)) end

-- A model stress in MPa scaled to rock [3-37].
function Run:mpa(sigma) return sigma * self.stress_scale / 1e6 end

-- The stress scale, the units of the stress columns and the run's parameters as attributes of a
-- series.
function Run:label_series(series)
  local P = self.P
  series:set_attribute("stress_scale", self.stress_scale)
  series:set_attribute("stress_units", "columns in '" .. M.MODEL_PA .. "' are model stresses; columns in '" ..
                       M.ROCK_MPA .. "' are model stresses x stress_scale / 1e6")
  local names = {}
  for name in pairs(P) do names[#names + 1] = name end
  table.sort(names)
  for _, name in ipairs(names) do
    local v = P[name]
    series:set_attribute("parameter_" .. name, type(v) == "boolean" and tostring(v) or v)
  end
end

-- Particle snapshots (HDF5 + XDMF) indexed by `label` (the shear or the closure displacement in
-- mm), with the keys of the integer fields; the particles left out of the specimen are not
-- written, so they are not drawn as debris between the halves. keep: the snapshots a resumed run
-- wrote before (joint/checkpoint.lua).
function Run:snapshots(name, label, keep)
  local groups = self.P.model == "rigid" and ("%d: lower half (rigid), %d: upper half (rigid), -1: none")
                 or ("%d: lower platen, %d: upper platen, -1: none (bonded particles)")
  return asperity.snapshots{dir = self.P.out, name = name, time = label, exclude_tag = M.LOST, keep = keep,
                            keys = {group = groups:format(self.bottom, self.top),
                                    tag = ("%d: lower half, %d: upper half"):format(M.LOWER, M.UPPER)}}
end

-- Mean height of the particles `ids`.
function Run:mean_height(ids)
  local ps, z = self.world:positions(), 0
  for _, id in ipairs(ids) do z = z + ps:get(id, 3) end
  return z / math.max(1, #ids)
end

-- Contacts between the halves (count, area, the force on porosity particles).
function Run:between() return self.world:contact_summary(M.LOWER, M.UPPER, M.POROSITY) end

-- The contact points between the halves, (x, y).
function Run:points_between()
  local world, pts = self.world, {}
  for _, ct in ipairs(world:contacts{fields = {"a", "b", "point"}}) do
    if world:tag(ct.a) ~= world:tag(ct.b) then pts[#pts + 1] = {ct.point[1], ct.point[2]} end
  end
  return pts
end

-- Force of the particles on the upper platen (the group force less any applied dead load).
function Run:platen_force()
  local f = self.world:group_force(self.top)
  return {f[1], f[2], f[3] - self.applied_z}
end

function Run:normal_stress() return self:platen_force()[3] / self.area end

-- The shear displacement (mm) of the upper platen along -axis since the shear began.
function Run:displacement() return (self.c0[self.axis] - self.world:group_position(self.top)[self.axis]) * 1e3 end

-- The deepest overlap over the smaller radius, read at every record: of any contact or bond, and of
-- the contacts with a particle free to turn. Only there do the contact point and its lever arm
-- [3-11] enter the motion: the bonded halves do not turn (the rotation rule) and the rigid ones
-- are groups of fixed rotation, so their deep contacts leave the linear law's forces as they are.
-- The study's loads press single contacts of the 5 cm halves 0.34-0.79 of a radius deep (elastic;
-- rigid 0.59-1.72, results/study); the engine's health check stops a run at one radius (1.9 rigid).
function Run:track_overlap(where)
  local r = self.world:max_overlap_ratio()
  if r > self.overlap_max then self.overlap_max, self.overlap_at = r, where end
  local t = self.world:max_overlap_ratio(true)
  if t > self.overlap_turning_max then self.overlap_turning_max, self.overlap_turning_at = t, where end
end

-- Debris that leaves the specimen: a particle freed by breaks can be thrown out through the open
-- band between the halves and then flies on (specimen.take_out_escaped); its travel alone would
-- trigger a neighbour rebuild every few tens of steps (a 2 cm fracture joint: 16 000 rebuilds in
-- the shear instead of 3 000). A centre more than 4 mean radii outside the box the halves can
-- occupy is taken out like the floaters: it carries nothing and touches nothing.
local ESCAPE_MARGIN = 4 * mat.packing.mean_radius

-- The box the halves can occupy, widened along -axis by the shear to come (m).
function Run:set_escape_box(shear_reach)
  local P = self.P
  local box = {min = {-ESCAPE_MARGIN, -ESCAPE_MARGIN, self.zlo - ESCAPE_MARGIN},
               max = {self.surface.Lx + ESCAPE_MARGIN, self.surface.Ly + ESCAPE_MARGIN,
                      self.zhi + P.gap + ESCAPE_MARGIN}}
  local axis_index = P.direction == "x" and 1 or 2
  box.min[axis_index] = box.min[axis_index] - shear_reach
  self.escape_box = box
end

-- A fracture run throws out debris a particle at a time, over a hundred at 5 cm: the log says so
-- when the count reaches 1, 2, 4, 8, ... (the report gives the total).
local function power_of_two_above(n)
  local p = 1
  while p <= n do p = 2 * p end
  return p
end

function Run:remove_escaped()
  local out = specimen.take_out_escaped(self.world, self.escape_box, M.LOST)
  if #out == 0 then return end
  local before = self.escaped_count
  self.escaped_count = before + #out
  if self.escaped_count >= power_of_two_above(before) then
    self:log("%d particle%s thrown out of the specimen so far, taken out (next said at %d)", self.escaped_count,
             self.escaped_count == 1 and "" or "s", power_of_two_above(self.escaped_count))
  end
end

-- Least-squares slope of ys against xs (NaN for fewer than two points).
function M.fit(xs, ys)
  local n_, sx, sy, sxx, sxy = #xs, 0, 0, 0, 0
  if n_ < 2 then return 0/0 end
  for k = 1, n_ do sx, sy, sxx, sxy = sx + xs[k], sy + ys[k], sxx + xs[k] ^ 2, sxy + xs[k] * ys[k] end
  return (n_ * sxy - sx * sy) / (n_ * sxx - sx * sx)
end

return M
