-- The joint model on the assembled halves (scripts/joint.lua) [scenarios.md 4], and the platens
-- that hold them.
--
--   require("joint.model").apply(run)   -- run.bottom, run.top: the groups the test moves
--
-- rigid: each half one rigid body, only the particles within reach of the other half searched.
-- elastic: unbreakable bonds. fracture: the calibrated bond strength, refused if the genesis left
-- more than 1 % of the bonds above it. The bonded models' platens are the layer of each outer face
-- and, with box=sides, the side faces' layers up to box_clearance from the joint (a shear box).
-- The platens' rule (the layers of the halves' faces, the box sides stopping short of the joint
-- surface) is the joint's own: lib/specimen.lua's platens are the top and bottom layers of one body.
local mat = require("materials")
local pack = require("pack")

local M = {}

-- The highest point of the lower half's surface (upper_side: the lowest of the upper half's) within
-- `within` of (x, y), from the profilometer surface `s` on the grid of spacing h, nx x ny.
local function local_extreme(g, s, x, y, within, upper_side)
  local h = g.h
  local best = upper_side and math.huge or -math.huge
  local i0, j0 = math.floor(x / h) + 1, math.floor(y / h) + 1
  local k = math.ceil(within / h)
  for j = math.max(1, j0 - k), math.min(g.ny, j0 + k) do
    for i = math.max(1, i0 - k), math.min(g.nx, i0 + k) do
      local z = s:at(i, j)
      if z == z then best = upper_side and math.min(best, z) or math.max(best, z) end
    end
  end
  return best
end

-- Rigid model: the halves are the bodies. Only particles within reach of the other half are
-- simulated: the rest of each half is inert [model.md 6]. A particle deeper than two diameters
-- below its half's surface (profilometer, over the neighbourhood it could slide under) can never
-- be touched.
local function rigid(run)
  local world, pos, rad, g = run.world, run.pos, run.rad, run.surface
  local lo_s, up_s = run.prof_lower.surface, run.prof_upper.surface
  world:remove_bonds()
  run.bottom = world:add_group(run.lower, {translation = "fixed"})
  run.top = world:add_group(run.upper, {translation = {"fixed", "fixed", "velocity"}, velocity = {0, 0, 0}})
  local reach = 4 * mat.packing.mean_radius * 1.6
  local inert = {}
  for _, id in ipairs(run.lower) do
    local p = pos[id]
    if p[3] + rad[id] < local_extreme(g, lo_s, p[1], p[2], reach, false) - reach then inert[#inert + 1] = id end
  end
  for _, id in ipairs(run.upper) do
    local p = pos[id]
    if p[3] - rad[id] > local_extreme(g, up_s, p[1], p[2], reach, true) + reach then inert[#inert + 1] = id end
  end
  if #inert > 0 then world:set_inert(inert) end
  run:log("rigid model: %d of the halves' %d particles inert", #inert, #run.lower + #run.upper)
end

-- Bonded models: the mass floor, the bond strength, then the platens.
local function bonded(run)
  local P, world, pos, rad, g = run.P, run.world, run.pos, run.rad, run.surface
  -- The critical time step [3-30] is set by the lightest particles (a sphere of the radii's lower
  -- cut, 0.2 mm, weighs 1/16 of a mean one). With a floor, those below it weigh as a sphere of
  -- floor x mean radius: a larger step for a small share of the mass (summary: mass_added).
  run.mass_added = 0
  if P.mass_floor > 0 then
    local floor = P.mass_floor * mat.packing.mean_radius
    local added_lower, total_lower = pack.floor_masses(world, run.lower, floor)
    local added_upper, total_upper = pack.floor_masses(world, run.upper, floor)
    run.mass_added = (added_lower + added_upper) / (total_lower + total_upper)
    run:log("mass floor: particles below %.3g mm weigh as one of that radius (+%.1f %% of the mass)",
            floor * 1e3, 100 * run.mass_added)
  end
  if P.model == "elastic" then
    world:set_bond_strength{breakable = false}
  else
    -- The bonds must hold what the preparation locked into them, or the "fracture" model is an
    -- unbonded pile that collapses at the first step. Say so instead of shearing it.
    local st = P.tensile_strength
    local over, worst, all = 0, 0, world:bonds{fields = {"sigma", "tau"}}
    for _, b in ipairs(all) do
      local need = mat.strength_to_hold(b.sigma, b.tau)
      if need > st then over = over + 1 end
      worst = math.max(worst, need)
    end
    if over > 0.01 * #all then
      error(("model=fracture: %d of %d bonds (%.0f %%) of the prepared specimen carry stresses that need " ..
             "a strength above the calibrated st = %.4g Pa (largest %.4g Pa): the packing locked more " ..
             "stress into the halves than the REV's genesis (scenarios.md 1). Run model=elastic or " ..
             "rigid, or lower genesis_stress."):format(over, #all, 100 * over / #all, st, worst), 0)
    end
    world:set_bond_strength{tensile_strength = st, contact_strength = (mat.contact_strength(P.contact_strength)),
                            contact_shear_strength = (mat.contact_shear_strength(P.contact_shear_strength)),
                            contact_bond_friction = P.contact_bond_friction}
    world:set_rotation_lock_bonds(P.rotation_lock_bonds)
    world:set_rotation_lock_beams(P.rotation_lock_beams)
  end
  -- Platens: the layer of each outer face. With the shear box, the side faces' layers too: a half
  -- whose sides are free carries the shear through its bulk as shear stress, and at a peak of
  -- 1.2-1.6 sigma_n (reference.md 2) the principal tension, sigma_n/2 - sqrt((sigma_n/2)^2 + tau^2),
  -- exceeds the material's tensile strength (at 14 MPa, from tau = 11.7 MPa on): the halves fail in
  -- their bulk, not at the joint. A box carries the shear into the halves as side pressure. Its
  -- sides stop short of the joint so that the halves touch only through bonded material.
  local lo_s, up_s = run.prof_lower.surface, run.prof_upper.surface
  local function on_side(p)
    return p[1] < P.platen or p[1] > g.Lx - P.platen or p[2] < P.platen or p[2] > g.Ly - P.platen
  end
  local c = P.box_clearance
  local bottom_ids, top_ids = {}, {}
  for _, id in ipairs(run.lower) do
    local p = pos[id]
    if p[3] < run.zlo + P.platen or (P.box == "sides" and on_side(p)
                                     and p[3] + rad[id] < local_extreme(g, lo_s, p[1], p[2], c, false) - c) then
      bottom_ids[#bottom_ids + 1] = id
    end
  end
  for _, id in ipairs(run.upper) do
    local p = pos[id]
    if p[3] > run.zhi - P.platen or (P.box == "sides" and on_side(p)
                                     and p[3] - rad[id] > local_extreme(g, up_s, p[1], p[2], c, true) + c) then
      top_ids[#top_ids + 1] = id
    end
  end
  run.platen_particles = {lower = #bottom_ids, upper = #top_ids}
  run:log("platens: %d particles below, %d above (%s)", #bottom_ids, #top_ids,
          P.box == "sides" and "bottom and top layers and the shear box's sides" or "bottom and top layers")
  run.bottom = world:add_group(bottom_ids, {translation = "fixed"})
  run.top = world:add_group(top_ids, {translation = {"fixed", "fixed", "velocity"}, velocity = {0, 0, 0}})
end

-- The model of run.P.model on the halves, the platens (run.bottom fixed, run.top to be moved),
-- and the watch for debris (fracture only: only broken material can escape).
function M.apply(run)
  -- Outer faces of the specimen: the lowest point of the lower half, the highest of the upper.
  local zlo, zhi = math.huge, -math.huge
  for _, id in ipairs(run.lower) do zlo = math.min(zlo, run.pos[id][3]) end
  for _, id in ipairs(run.upper) do zhi = math.max(zhi, run.pos[id][3]) end
  run.zlo, run.zhi = zlo, zhi
  if run.P.model == "rigid" then rigid(run) else bonded(run) end
  run.bonds_at_start = run.world:bond_count()
  run.escape_every = (run.P.model == "fracture") and 2000 or 0
  if run.escape_every > 0 then run:set_escape_box(0) end
end

return M
