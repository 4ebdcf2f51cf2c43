-- The report of a sheared joint (scripts/joint.lua): summary.json, the warnings of the quasi-static
-- and overlap checks, the PNG plots and the one-line result.
--
--   local summary = require("joint.report").write(run)
--
-- From the shear series: the peak shear stress and where; the residual, the time mean of the
-- platen force over the last `residual_window` mm; the initial shear stiffness (slope over the
-- first 30 % of the peak); the dilatancy and its angle at the peak; the contact decay N = N0 d^q
-- after the largest count; how well the normal stress was held; the energy shares of the work the
-- platens did; with broken bonds, where they broke. Plots (lib/joint_figures.lua): shear_stress,
-- normal_stress, closure, contacts, broken_bonds, energies, contact_map_peak and contact_map.
local context = require("joint.context")

local fit = context.fit

local M = {}

-- Residual: the mean shear stress over the last residual_window mm, from the platen's impulse (the
-- exact time mean, so it does not depend on the record interval; at constant velocity time and
-- displacement means agree).
local function residual_stress(run, u, tau, rows)
  local time = run.shear:column("time")
  local first = rows
  while first > 1 and u[first - 1] >= u[rows] - run.P.residual_window do first = first - 1 end
  if first < rows and time[rows] > time[first] then
    return run:mpa((run.shear_impulse[rows] - run.shear_impulse[first]) / (time[rows] - time[first]) / run.area)
  end
  return tau[rows]
end

-- The fracture model's damage criteria [scenarios.md 4]: at 5 mm of shear at least this share of
-- the broken parallel bonds lies within NEAR_SURFACE_M of the mean plane, and at most this share of
-- the halves' bonds is broken.
M.NEAR_SURFACE_M = 3e-3
M.NEAR_SHARE_MIN = 0.8
M.BROKEN_FRACTION_MAX = 0.1

-- Where the bonds broke [scenarios.md 4: damage near the joint surfaces, not through the halves]:
-- depth below the mean plane (lower half) or above it (upper half, moved back by its mean
-- displacement since the genesis), 1 mm bins. Returns the bins, the broken fraction of the bonds
-- the halves held before closure and the share of the broken ones within M.NEAR_SURFACE_M of the
-- mean plane (NaN without breaks), or nil without breaks outside the fracture model.
local function broken_by_depth(run)
  local world = run.world
  if not (world:break_count() > 0 or run.P.model == "fracture") then return nil, nil, nil end
  local shift = run:mean_height(run.upper) - run.upper_mean_z_mould
  local lower_bins, upper_bins = {}, {}
  local bins = math.max(1, math.ceil(run.P.thickness * 1e3))
  for k = 1, bins do lower_bins[k], upper_bins[k] = 0, 0 end
  local beams, near = 0, 0
  for _, ev in ipairs(world:break_events()) do
    if ev.kind ~= "beam" then goto next end  -- the parallel bonds (the thesis's broken bonds)
    local z = ev.position[3]
    local upper_side = world:tag(ev.a) == context.UPPER
    local depth = upper_side and (z - shift) or -z
    beams = beams + 1
    if depth < M.NEAR_SURFACE_M then near = near + 1 end  -- an asperity's break (depth < 0) is near too
    local k = math.max(1, math.min(bins, math.floor(depth * 1e3) + 1))
    if upper_side then upper_bins[k] = upper_bins[k] + 1 else lower_bins[k] = lower_bins[k] + 1 end
    ::next::
  end
  local edges = {}
  for k = 1, bins do edges[k] = k end
  return {depth_mm_upper_edges = edges, lower = lower_bins, upper = upper_bins},
         world:break_count() / math.max(1, run.bonds_at_start), beams > 0 and near / beams or 0/0
end

-- The plots of the curves; a failure (no gnuplot) is logged, not raised.
local function plot_curves(run, r)
  local P, shear, closure = run.P, run.shear, run.closure
  local u, tau, dil, sn, rows = r.u, r.tau, r.dil, r.sn, r.rows
  local plotted, plot_error = pcall(function()
    local jf = require("joint_figures")
    local ref = require("reference")
    local surface_name = P.surface_file ~= "" and P.surface_file:match("[^/]*$") or P.surface
    local title = ("%s, %s model, %g MPa normal stress, shear along -%s (%d particles)"):format(
      surface_name, P.model, P.stress, P.direction, #run.lower + #run.upper)
    local res_from = u[rows] - P.residual_window
    jf.shear{file = P.out .. "/shear_stress.png", title = title, u = u, tau = tau, dilatancy = dil,
             peak = {at = u[r.at], value = r.peak}, residual = {value = r.residual, from = res_from, to = u[rows]},
             reference = P.surface_file == "" and ref.joint(P.surface, P.model, P.stress) or nil}
    local cns = P.normal_control == "stiffness"
    local asked
    if cns then
      asked = {}
      for k = 1, rows do asked[k] = P.stress + P.normal_stiffness * dil[k] end
    end
    jf.cnl{file = P.out .. "/normal_stress.png", title = title .. (cns and ": constant normal stiffness" or ": constant normal load"),
           u = u, tau = tau, sn = sn, sn_mean = r.sn_mean, target = P.stress, target_values = asked,
           target_label = cns and ("target %g MPa + %g MPa/mm x dilatancy"):format(P.stress, P.normal_stiffness) or nil,
           reference = not cns and ref.ratios(P.model, P.stress) or nil}
    jf.closure{file = P.out .. "/closure.png", title = title .. ": closure", closure = closure:column("closure"),
               sn = closure:column("normal_stress_mpa"), target = P.stress, stiffness = run.normal_stiffness}
    local peak_mark = {at = u[r.at], label = "peak"}
    jf.curves{file = P.out .. "/contacts.png", title = title, x = u, mark = peak_mark,
              ylabel = "contacts between the halves", curves = {{r.cnt}}, from_zero = true}
    jf.curves{file = P.out .. "/broken_bonds.png", title = title, x = u, mark = peak_mark,
              ylabel = "broken bonds", curves = {{shear:column("broken_bonds")}}, from_zero = true}
    local function col(name) return shear:column(name) end
    jf.curves{file = P.out .. "/energies.png", title = title .. ": energy since the shear began", x = u,
              ylabel = "energy (J, model units)",
              curves = {{col("boundary_work"), "work done by the platens"}, {col("friction"), "dissipated by friction"},
                        {col("damping"), "dissipated by damping"}, {col("strain"), "stored in contacts and bonds"},
                        {col("released"), "released by broken bonds"}, {col("kinetic"), "kinetic"}}}
  end)
  if not plotted then run:log("plots skipped: %s", tostring(plot_error)) end
end

-- Contact points and broken bonds over the elevation map, at the peak and at the end.
local function plot_maps(run)
  local P, world, s = run.P, run.world, run.surface
  pcall(function()
    local jf = require("joint_figures")
    local events = world:break_events()
    local function broken_until(step)
      local pts = {}
      for _, ev in ipairs(events) do
        if ev.kind == "beam" and (not step or ev.step <= step) then pts[#pts + 1] = {ev.position[1], ev.position[2]} end
      end
      return pts
    end
    local label = ("%s, %s model, %g MPa"):format(P.surface, P.model, P.stress)
    local peak_points = run.peak_points
    if peak_points then
      jf.contact_map{file = P.out .. "/contact_map_peak.png", nx = s.nx, ny = s.ny, h = s.h, heights = s.heights,
                     points = peak_points.points, broken = broken_until(peak_points.step),
                     title = ("%s: at the peak, %.2f mm of shear"):format(label, peak_points.at)}
    end
    jf.contact_map{file = P.out .. "/contact_map.png", nx = s.nx, ny = s.ny, h = s.h, heights = s.heights,
                   points = run:points_between(), broken = broken_until(nil),
                   title = ("%s: at the end, %.2f mm of shear"):format(label, run:displacement())}
  end)
end

-- Writes summary.json and the plots, prints the result line; returns the summary.
function M.write(run)
  local P, world, shear, s = run.P, run.world, run.shear, run.surface
  local u, tau = shear:column("displacement"), shear:column("shear_stress_mpa")
  local dil, sn = shear:column("dilatancy"), shear:column("normal_stress_mpa")
  local cnt = shear:column("contacts")
  local rows = shear:rows()
  local peak, at = -math.huge, 1
  for k = 1, rows do if tau[k] > peak then peak, at = tau[k], k end end
  local residual = residual_stress(run, u, tau, rows)
  local dynamic_ratio, dynamic_at = run.dynamic_ratio, run.dynamic_at
  if dynamic_ratio > P.quasi_static_limit then
    run:log("WARNING: not quasi-static: the kinetic energy reached %.3g x (normal load x mean radius) at %.3f mm "
            .. "(limit quasi_static_limit = %g); results depend on the loading rate: lower velocity (now %g m/s)",
            dynamic_ratio, dynamic_at, P.quasi_static_limit, P.velocity)
  end
  if run.escaped_count > 0 then
    run:log("%d particle%s thrown out of the specimen in all, taken out (escaped_particles)", run.escaped_count,
            run.escaped_count == 1 and "" or "s")
  end
  local overlap_max, turning_max = run.overlap_max, run.overlap_turning_max
  if turning_max > P.overlap_limit then
    run:log("WARNING: a contact of a particle free to turn overlapped %.3g of its smaller radius (%s; limit "
            .. "overlap_limit = %g): its contact point and lever arm are far from a shallow contact's, so the "
            .. "particle's moments are those of contacts too soft for the load (%g MPa)",
            turning_max, run.overlap_turning_at, P.overlap_limit, P.stress)
  elseif overlap_max > P.overlap_limit then
    run:log("deepest overlap %.3g of the smaller radius (%s), between particles that do not turn (bonded or "
            .. "rigid): the linear law's forces are unaffected; contact points drawn at it lie off (the "
            .. "particles free to turn: %.3g, limit overlap_limit = %g)", overlap_max, run.overlap_at, turning_max,
            P.overlap_limit)
  end
  -- Initial shear stiffness: slope over the first 30 % of the peak stress.
  local sx, sy = {}, {}
  for k = 1, at do if tau[k] <= 0.3 * peak then sx[#sx + 1] = u[k]; sy[#sy + 1] = tau[k] end end
  local ks = fit(sx, sy)
  local max_dil = -math.huge
  for k = 1, rows do max_dil = math.max(max_dil, dil[k]) end
  local function slope_at(k)
    local a, b = math.max(1, k - 5), math.min(rows, k + 5)
    return (dil[b] - dil[a]) / math.max(u[b] - u[a], 1e-12)
  end
  -- Contact decay N = N0 d^q after the maximum count.
  local cmax, cat = -1, 1
  for k = 1, rows do if cnt[k] > cmax then cmax, cat = cnt[k], k end end
  local lx, ly = {}, {}
  for k = cat, rows do
    if u[k] > 0 and cnt[k] > 0 then lx[#lx + 1] = math.log(u[k]); ly[#ly + 1] = math.log(cnt[k]) end
  end
  local q = fit(lx, ly)
  local sn_mean = shear:column("normal_stress_mean_mpa")
  local sn_dev, sn_dev_mean, devs = 0, 0, {}
  -- The stress the control asks for: sigma_0, or with constant normal stiffness sigma_0 + K dilatancy
  -- (for an interval mean, at the interval's mean dilatancy).
  local K_cns = P.normal_control == "stiffness" and P.normal_stiffness or 0
  for k = 1, rows do
    if u[k] > 0.05 then
      sn_dev = math.max(sn_dev, math.abs(sn[k] / (P.stress + K_cns * dil[k]) - 1))
      devs[#devs + 1] = math.abs(sn_mean[k] / (P.stress + K_cns * 0.5 * (dil[k] + dil[math.max(1, k - 1)])) - 1)
      sn_dev_mean = math.max(sn_dev_mean, devs[#devs])
    end
  end
  table.sort(devs)
  local within = 0
  for _, d in ipairs(devs) do if d <= 0.01 then within = within + 1 end end
  local sn_dev_p95 = #devs > 0 and devs[math.max(1, math.ceil(0.95 * #devs))] or 0/0
  local e, e0 = world:energies(), run.e0
  local input = e.boundary_work - e0.boundary_work
  local function share(v) return input ~= 0 and v / input or 0/0 end
  local broken_depths, broken_fraction, near_share = broken_by_depth(run)
  local closure_breaks = run.closure:column("broken_bonds")[run.closure:rows()]
  if P.model == "fracture" then
    local function met(ok) return ok and "met" or "not met" end
    run:log("damage after %.2f mm of shear (docs/scenarios.md 4, judged at 5 mm): %.1f %% of the bonds broken (at most %g %%: %s), "
            .. "%.1f %% of them within %g mm of the mean plane (at least %g %%: %s); %d broke in the closure",
            u[rows], 100 * broken_fraction, 100 * M.BROKEN_FRACTION_MAX, met(broken_fraction <= M.BROKEN_FRACTION_MAX),
            100 * near_share, 1e3 * M.NEAR_SURFACE_M, 100 * M.NEAR_SHARE_MIN, met(near_share >= M.NEAR_SHARE_MIN),
            closure_breaks)
  end
  local plane_lower, cls = run.plane_lower, run.cls
  local memory = asperity.memory()
  local summary = {
    parameters = P,
    surface = {nx = s.nx, ny = s.ny, spacing = s.h, side_x = s.Lx, side_y = s.Ly},
    n_particles = #run.lower + #run.upper,
    kernels = world:simd(),                    -- the kernel set of closure and shear
    left_out_particles = run.N - #run.lower - #run.upper,
    n_lower = #run.lower,
    n_upper = #run.upper,
    inert_particles = world:inert_count(),
    escaped_particles = run.escaped_count,     -- debris thrown out of the specimen and taken out
    platen_particles = run.platen_particles,
    mass_added = run.mass_added,                  -- the mass floor's share of the halves' mass (0: none)
    bonds = world:bond_count(),
    stress_scale = run.stress_scale,
    target_stress_pa = run.target_stress,
    stress_units = "*_mpa: MPa scaled to rock (model Pa x stress_scale / 1e6); *_pa: model Pa",
    -- The shear stress of the first record, before the platen moves: the lateral force the held
    -- platen carries once the closure is done (the normal load on inclined asperity contacts pushes
    -- the halves sideways). The shear curve starts from it.
    shear_stress_at_start_mpa = tau[1],
    closure_mm = run.closure:column("closure")[run.closure:rows()],
    peak_shear_stress_mpa = peak,
    peak_displacement_mm = u[at],
    residual_shear_stress_mpa = residual,
    -- the reference study's values for this surface, model and stress, where it has them
    reference = P.surface_file == "" and require("reference").joint(P.surface, P.model, P.stress) or nil,
    residual_window_mm = P.residual_window,    -- the residual: the mean over the last this much shear
    peak_friction = peak / P.stress,           -- tau / sigma_n at the peak
    residual_friction = residual / P.stress,
    kinetic_ratio_max = dynamic_ratio,         -- max Ek / (normal load x mean radius) while shearing
    kinetic_ratio_max_at_mm = dynamic_at,
    quasi_static = dynamic_ratio <= P.quasi_static_limit,
    speedup_max = run.speedup_max,             -- the highest velocity factor the shear reached (speedup)
    speedup_from_mm = run.speedup_from,        -- where it first rose above 1 (nil: never)
    overlap_ratio_max = overlap_max,           -- deepest overlap / smaller radius, over every record
    overlap_ratio_max_at = run.overlap_at,
    overlap_ratio_max_turning = turning_max,   -- the same over the contacts with a particle free to turn
    overlap_ratio_max_turning_at = run.overlap_turning_at,
    overlaps_small = turning_max <= P.overlap_limit,
    initial_shear_stiffness_mpa_per_mm = ks,
    max_dilatancy_mm = max_dil,
    dilatancy_angle_at_peak_deg = math.deg(math.atan(slope_at(at))),
    normal_stiffness_mpa_per_mm = run.normal_stiffness,
    normal_stress_max_deviation = sn_dev_mean,          -- of the interval means (after 0.05 mm)
    normal_stress_max_deviation_instant = sn_dev,       -- of the values at the recorded steps
    normal_stress_deviation_p95 = sn_dev_p95,           -- 95th percentile of the interval-mean deviation
    normal_stress_within_1pct = #devs > 0 and within / #devs or 0/0,  -- fraction of records within 1 %
    broken_bonds = world:break_count(),
    broken_bond_fraction = broken_fraction,          -- of the bonds the halves held before closure
    broken_bonds_by_depth_mm = broken_depths,        -- counts per 1 mm of depth from the mean plane
    broken_bonds_near_share = near_share,            -- of the broken ones, the share within 3 mm of the mean plane
    broken_bonds_in_closure = closure_breaks,
    contact_decay_exponent = q,
    max_contacts = cmax,
    dem_surface = {mean_plane_shift_m = plane_lower.shift,
                   coinciding_fraction = plane_lower.coinciding_fraction,
                   surface_particle_fraction = cls.retained_fraction,
                   band_m = cls.band},
    energy_shares = {friction = share(e.friction - e0.friction), damping = share(e.damping - e0.damping),
                     strain = share(e.strain - e0.strain), kinetic = share(e.kinetic - e0.kinetic),
                     released = share(e.released - e0.released)},
    input_work_j = input,
    energy_balance_error = share(world:energy_balance(e0)),
    steps = world:step(),
    shear_steps = run.shear_steps,
    shear_rebuilds = run.shear_rebuilds,  -- neighbour-list rebuilds while shearing
    shear_seconds = run.shear_seconds,
    shear_microseconds_per_step = 1e6 * run.shear_seconds / math.max(run.shear_steps, 1),  -- cost of one step
    dt = world:dt(),
    wall_seconds = asperity.wall_time() - run.t_start,   -- of every attempt, when resumed
    -- The process's peak resident memory (of this attempt, when resumed), whole and per particle.
    peak_memory_bytes = memory.peak,
    memory_bytes_per_particle = memory.peak / math.max(1, #run.lower + #run.upper),
    resumes = run.resumes or 0,              -- times the run was resumed from its saved state
    specimen_cache = run.cache_file,
    specimen_packed = run.specimen_packed,   -- packed by this run (its wall time includes the genesis)
    specimen_seconds = run.specimen_seconds, -- the genesis (packed, bonded, relaxed) or the cache's loading
    genesis = run.genesis_record,
  }
  asperity.write_json(P.out .. "/summary.json", summary)
  run.summary = summary

  plot_curves(run, {u = u, tau = tau, dil = dil, sn = sn, sn_mean = sn_mean, cnt = cnt, rows = rows,
                    peak = peak, at = at, residual = residual})
  plot_maps(run)

  run:log("peak memory %.0f MB (%.0f bytes per particle)", summary.peak_memory_bytes / 2^20,
          summary.memory_bytes_per_particle)
  print(("%s %s %g MPa -%s: %d particles, peak %.2f MPa at %.2f mm, residual %.2f MPa, " ..
         "max dilatancy %.3f mm, %d broken bonds, %.0f s"):format(P.surface, P.model, P.stress,
    P.direction, summary.n_particles, peak, u[at], residual, max_dil, world:break_count(),
    summary.wall_seconds))
  return summary
end

return M
