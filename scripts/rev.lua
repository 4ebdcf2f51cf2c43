-- The REV: a 1 cm cube of bonded particles, packed, bonded, freed and tested in uniaxial
-- compression, tension and direct shear [thesis 3.3.1, 3.3.2; scenarios.md 1-2].
--
--   build/asperity run scripts/rev.lua out=out/rev                    # defaults (a few minutes)
--   build/asperity run scripts/rev.lua tensile_strength=0.03 seed=2 out=out/rev2
--   build/asperity run scripts/rev.lua rate_check=true out=out/rev_rate   # also at half the rate
--
-- 1. Genesis (lib/genesis.lua, scenarios.md 1): N = (1 - n) V / (4/3 pi <R>^3) particles at the
--    genesis porosity n (materials.lua), radii Gaussian 0.5 +- 0.1 mm cut at 3 SD, compacted
--    without friction by radius expansion in frictionless walls; the isotropic stress
--    `genesis_stress` installed by one radius factor; particles with fewer than 3 contacts taken
--    out; friction restored. The packing is cached (cache=) for calibrations.
-- 2. Two copies of the packing get bonds (every contact; beam_kn = bond_normal_stiffness kn,
--    beam_ks = bond_shear_ratio beam_kn, Rb = bond_radius_factor min(Ra, Rb); contacts keep
--    their forces, beams start at zero, model.md 5): unbreakable (the elastic model: E, nu, G)
--    and breakable with the elliptic criterion of strength st (`tensile_strength`; strengths).
--    Walls removed, cycled to equilibrium. The bond stresses left are reported (histogram, CSV)
--    with the strength each bond needs to hold. Rotation is locked while a particle holds
--    `rotation_lock_bonds` intact bonds.
--    isotropy: the packing turned so that the z tests load it along x and along y.
-- 3. Platens: particles within `platen` of the bottom / top face, rigid groups, rotation fixed;
--    bottom fixed, top moved at `rate`. Stress = platen force / L^2 [3-43, 3-44]; strains from
--    particle layers at 1/4 and 3/4 height and the lateral faces (specimen.lua) [3-38..3-42].
--    Elastic compression and tension to `elastic_strain`, direct shear (top along +x) to the same
--    shear strain; fracture compression and tension until the stress falls to `stop_fraction` of
--    its peak.
--
-- Outputs in `out`: summary.json; series (HDF5 + CSV, with the parameters and the calibrated
-- stress scale as attributes) and stress-strain PNGs per test;
-- bond_stresses.csv / .png (after wall removal); broken-bond maps (PNG + CSV) of the fracture tests;
-- checkpoints packed.h5, elastic.h5, fracture.h5 (asperity.load continues from them).
--
-- Stresses are reported in model units (Pa) and scaled to the rock [3-37]:
-- sigma_rock = sigma * E_exp / E_REV, E_exp = 30 853 MPa (Table 3-1).
local mat = require("materials")
local radii = require("radii")
local pack = require("pack")
local walls = require("walls")
local eq = require("equilibrium")
local specimen = require("specimen")
local genesis = require("genesis")
local figures = require("figures")

-- The calibrated material of the chosen bond installation (scripts/lib/materials.lua) supplies
-- the defaults of st and the packing stress.
local rev = mat.rev
local params_lib = require("params")
local TESTS = {"elastic", "isotropy", "shear", "compression", "tension"}
local P = params_lib.parse{
  script = "rev.lua",
  path = "scripts/rev.lua",
  about = "the REV: a bonded cube packed, bonded, freed and tested in compression, tension and shear",
  {"size", 0.01, unit = "m", above = 0, doc = "side of the cube"},
  {"porosity", mat.genesis.porosity, above = 0, below = 1, doc = "nominal porosity [3-35]"},
  {"seed", 1, type = "integer", min = 0, doc = "of the radii and the packing"},
  {"mean_radius", mat.packing.mean_radius, unit = "m", above = 0, doc = "mean particle radius"},
  {"radius_sd", mat.packing.radius_sd, unit = "m", min = 0, doc = "standard deviation of the radii (cut at 3 SD)"},
  {"kn", mat.contact.kn, unit = "N/m", above = 0, doc = "contact normal stiffness"},
  {"ks", mat.contact.ks, unit = "N/m", min = 0, doc = "contact shear stiffness"},
  {"friction", mat.contact.friction, min = 0, doc = "contact friction coefficient"},
  {"damping", mat.damping, min = 0, below = 1, doc = "local damping"},
  {"density", mat.density, unit = "kg/m^3", above = 0, doc = "particle density"},
  {"genesis_stress", mat.genesis.stress, unit = "Pa", above = 0, doc = "isotropic stress the genesis installs before bonding (model units)"},
  {"genesis_shrink_gain", mat.genesis.shrink_gain, above = 0, max = 1, doc = "the stress servo's gain when it shrinks the radii, relative to when it grows them"},
  {"genesis_damping", mat.genesis.damping, min = 0, below = 1, doc = "the local damping of the packing steps (compaction and stress installation, the stress then installed again at `damping`)"},
  {"genesis_mass_floor", mat.genesis.mass_floor, min = 0, max = 2, doc = "while packing, particles smaller than this x mean radius weigh as one of it (0: true masses)"},
  {"floater_contacts", mat.genesis.floater_contacts, type = "integer", min = 0,
   doc = "particles with fewer contacts are floaters"},
  {"grow_floaters", mat.genesis.grow_floaters, doc = "floaters get the radius and place at which they touch four neighbours (else they are taken out)"},
  {"tensile_strength", rev.bond_tensile_strength, unit = "Pa", above = 0,
   doc = "bond strength st of the elliptic criterion (model units; the calibrated one by default)"},
  {"bond_shear_ratio", rev.bond_shear_ratio, min = 0, doc = "kbs / kbn of the parallel bonds"},
  {"bond_normal_stiffness", rev.bond_normal_stiffness, above = 0,
   doc = "kbn A / kn: the parallel bond's normal stiffness against the contact springs' (model.md 5: 1)"},
  {"bond_radius_factor", rev.bond_radius_factor, above = 0, max = 1, doc = "lambda: Rb = lambda min(Ra, Rb) [3-26]"},
  {"contact_strength", rev.contact_strength, type = "string",
   doc = "the contact bonds break at c st A: c > 0, \"inf\" (never) or \"beam\" (with the parallel bond) (model.md 5)"},
  {"contact_shear_strength", mat.rev.contact_shear_strength, type = "string",
   doc = "the contact bonds break in shear at cs st A: cs > 0, \"inf\" (never) or \"same\" (as contact_strength)"},
  {"contact_bond_friction", mat.rev.contact_bond_friction, min = 0,
   doc = "the contact bonds' shear strength grows by this x their compressive force (Mohr-Coulomb; 0: model.md 5)"},
  {"rate", 1e-6, unit = "m/s", above = 0, doc = "platen velocity (thesis: 1 um/s)"},
  {"elastic_strain", 2e-4, above = 0, below = 0.1, doc = "strain reached in the elastic tests"},
  {"stop_fraction", 0.7, above = 0, below = 1, doc = "fracture tests stop when |stress| < this x peak, after the peak"},
  {"max_strain", 0.02, above = 0, below = 1, doc = "... or at this strain"},
  {"platen", 1e-3, unit = "m", above = 0, doc = "platen thickness (particles within it of the face)"},
  {"ratio", 1e-4, above = 0, below = 1, doc = "equilibrium: mean unbalanced / mean contact force"},
  {"every", 100, type = "integer", min = 1, doc = "steps between recorded rows"},
  {"tests", "elastic,isotropy,shear,compression,tension", list = "string", oneof = TESTS, doc = "which tests to run"},
  {"rate_check", false, doc = "also run the elastic tests at half the rate"},
  {"lock_rotation", true, doc = "model.md 2: bonded particles do not rotate"},
  {"rotation_lock_bonds", rev.rotation_lock_bonds, type = "integer", min = 1,
   doc = "... while they hold at least this many intact bonds"},
  {"rotation_lock_beams", rev.rotation_lock_beams, doc = "only bonds whose parallel bond holds count for the lock (false: a contact bond alone too; model.md 5)"},
  {"bond_gap", 0, unit = "m", min = 0, doc = "largest gap bonded (0: the engine's default, 1e-3 x mean radius)"},
  {"dt_safety", 0, min = 0, max = 2, doc = "time step / critical estimate in the tests (0: the engine's 0.8; above 1 only to study instability)"},
  {"cache", "", doc = "a folder: the packing is cached there and reused (calibrate_rev.lua)"},
  {"threads", 1, type = "integer", min = 0, doc = "0: automatic"},
  {"simd", "auto", oneof = {"auto", "scalar", "sse4_2", "avx2", "avx512f"},
   doc = "kernels of bonding and tests (auto: the widest this CPU runs)"},
  {"out", "out/rev", nonempty = true, doc = "output folder"},
  check = function(P, fail)
    if P.platen >= P.size / 2 then fail("platen", ("must be < size / 2 (%g m)"):format(P.size / 2)) end
    if P.size < 4 * P.mean_radius then fail("size", ("must be >= 4 mean radii (%g m)"):format(4 * P.mean_radius)) end
    if P.radius_sd * 3 >= P.mean_radius then
      fail("radius_sd", ("must be < mean_radius / 3 (%g m): radii are cut at 3 SD and must stay positive"):format(P.mean_radius / 3))
    end
    if #params_lib.split(P.tests) == 0 then fail("tests", "must name at least one test") end
    local _, why = mat.contact_strength(P.contact_strength)
    if why then fail("contact_strength", why) end
    local _, why_shear = mat.contact_shear_strength(P.contact_shear_strength)
    if why_shear then fail("contact_shear_strength", why_shear) end
  end,
}
if not P then return end   -- help printed
local out = asperity.mkdir(P.out)
local want = {}
for _, name in ipairs(params_lib.split(P.tests)) do want[name] = true end
want.elastic = want.elastic or want.shear or want.isotropy  -- shear and isotropy compare with E and nu
local L = P.size
local area = L * L
local clock0 = asperity.wall_time()
local timings = {}
local function timed(name, fn, ...)
  local t = asperity.wall_time()
  local r = table.pack(fn(...))
  timings[name] = asperity.wall_time() - t
  return table.unpack(r, 1, r.n)
end
local function log(fmt, ...) io.write((fmt .. "\n"):format(...)); io.flush() end

local function new_world()
  return asperity.world{material = {kn = P.kn, ks = P.ks, friction = P.friction}, damping = P.damping,
                        density = P.density, threads = P.threads, lock_bonded_rotation = P.lock_rotation,
                        rotation_lock_bonds = P.rotation_lock_bonds, rotation_lock_beams = P.rotation_lock_beams}
end

-- 1. Genesis [scenarios.md 1] ---------------------------------------------------------------------
local function make_packing()
  local w = new_world()
  local lo, hi = {0, 0, 0}, {L, L, L}
  local box = walls.box(w, {min = lo, max = hi, material = {kn = P.kn, ks = P.ks, friction = 0}})
  local n = radii.count_for_porosity{volume = L ^ 3, porosity = P.porosity, mean_radius = P.mean_radius}
  local r = radii.truncated_gaussian{count = n, mean = P.mean_radius, sd = P.radius_sd, cut = mat.packing.cut,
                                     seed = P.seed, normalise_mean = true}
  local g = genesis.pack(w, {min = lo, max = hi, radii = r, seed = P.seed, box = box, stress = P.genesis_stress,
                             friction = P.friction, ratio = P.ratio, min_contacts = P.floater_contacts,
                             grow_floaters = P.grow_floaters, shrink_gain = P.genesis_shrink_gain,
                             mass_floor = P.genesis_mass_floor, damping = P.genesis_damping,
                             mean_radius = P.mean_radius, log = log})
  local info = {n_particles = #g.kept, n_generated = n, genesis = g, box = box, kept = g.kept,
                porosity_nominal = g.porosity_nominal, porosity_true = g.porosity_true,
                mean_radius = g.mean_radius, coordination = g.coordination, interior = g.interior,
                wall_stress_pa = g.wall_stress_pa}
  local rr = {}
  local all = w:radii()
  for i, id in ipairs(g.kept) do rr[i] = all:get(id) end
  info.radius_stats = radii.stats(rr)
  w:save(out .. "/packed.h5")
  return info
end
-- The packing is cached (cache=DIR): a calibration bonds the same packing with many bond parameters.
-- Keyed by everything that shapes it; the genesis record beside it as a Lua table.
local function cached_packing()
  if P.cache == "" then return make_packing() end
  asperity.mkdir(P.cache)
  local key = ("rev_v6_L%.6g_n%.6g_s%d_r%.6g_%.6g_k%.6g_%.6g_d%.6g_%.6g_g%.6g_f%d_q%.6g"):format(P.size, P.porosity,
    P.seed, P.mean_radius, P.radius_sd, P.kn, P.ks, P.damping, P.density, P.genesis_stress, P.floater_contacts, P.ratio)
    .. (P.lock_rotation and ("_l%d"):format(P.rotation_lock_bonds) or "_free") .. (P.rotation_lock_beams and "_lb" or "")
    .. (P.grow_floaters and "_grown" or "")
    .. (P.genesis_shrink_gain ~= 1 and ("_sg%.3g"):format(P.genesis_shrink_gain) or "")
    .. (P.genesis_mass_floor ~= 0 and ("_mf%.3g"):format(P.genesis_mass_floor) or "")
    .. (P.genesis_damping ~= P.damping and ("_gd%.3g"):format(P.genesis_damping) or "")
  local h5, rec = P.cache .. "/" .. key .. ".h5", P.cache .. "/" .. key .. ".lua"
  local f = io.open(rec, "r")
  if f then
    f:close()
    local info = dofile(rec)
    local w = asperity.load(h5, {threads = P.threads})
    w:save(out .. "/packed.h5")
    log("reusing the cached packing %s", h5)
    return info
  end
  local info = make_packing()
  os.rename(out .. "/packed.h5", h5 .. ".tmp")
  os.rename(h5 .. ".tmp", h5)
  asperity.load(h5):save(out .. "/packed.h5")
  local tmp = rec .. ".tmp"
  local g = assert(io.open(tmp, "w"))
  g:write("return " .. genesis.serialise(info) .. "\n")
  g:close()
  os.rename(tmp, rec)
  return info
end
local packing = timed("packing", cached_packing)

-- 2. Bonding, wall removal, relaxation --------------------------------------------------------------
-- axis "x" or "y": the packing's coordinates turned (x, y, z) -> (y, z, x) or (z, x, y) before bonding,
-- so the tests along z load the packing along x or y. Exact: the packing is a cube in a cube of
-- walls at rest, and its contacts, frictionless until bonded, carry no shear force that would have
-- to turn with it.
local function turn(w, axis)
  local pos = w:positions()
  local from = axis == "x" and {2, 3, 1} or {3, 1, 2}
  for _, id in ipairs(packing.kept) do   -- the floaters are out of the specimen (inert)
    w:set_position(id, {pos:get(id, from[1]), pos:get(id, from[2]), pos:get(id, from[3])})
    w:set_velocity(id, {0, 0, 0})
  end
end

local function bonded(material, csv, axis)
  local w = asperity.load(out .. "/packed.h5", {threads = P.threads, simd = P.simd})
  if axis and axis ~= "z" then turn(w, axis) end
  local walls_list = {}
  for _, id in pairs(packing.box) do walls_list[#walls_list + 1] = id end
  table.sort(walls_list, function(a, b) return a > b end)   -- removal renumbers the walls after it
  local b = genesis.bond(w, {sets = {packing.kept}, material = material, walls = walls_list, ratio = P.ratio,
                             tensile_strength = P.tensile_strength, csv = csv})
  return w, {bonds = b.bonds, relax_steps = b.relax_steps, relax_reached = b.relax_reached,
             relax_ratio = b.relax_ratio, broken_in_relaxation = b.broken_in_relaxation,
             bond_stress = b.bond_stress}
end

local beam_kn, beam_ks = mat.beam_stiffness(P.kn, P.bond_normal_stiffness, P.bond_shear_ratio)
local bond_material = {beam_kn = beam_kn, beam_ks = beam_ks, radius_factor = P.bond_radius_factor,
                       contact_strength = (mat.contact_strength(P.contact_strength)),
                       contact_shear_strength = (mat.contact_shear_strength(P.contact_shear_strength)),
                       contact_bond_friction = P.contact_bond_friction}
if P.bond_gap > 0 then bond_material.tolerance = P.bond_gap end   -- else the engine's 1e-3 <R>
local function with(t, extra)
  local c = {}
  for k, v in pairs(t) do c[k] = v end
  for k, v in pairs(extra) do c[k] = v end
  return c
end

local welastic, elastic_info = timed("bond_relax_elastic", bonded, with(bond_material, {breakable = false}),
                                    out .. "/bond_stresses.csv")
log("elastic model: %d bonds, relaxed in %d steps (ratio %.2g)", elastic_info.bonds, elastic_info.relax_steps,
    elastic_info.relax_ratio)

-- Bond stresses left after wall removal, and the strength each bond needs to hold [scenarios.md 1].
local function residual_stresses(w)
  local stats, sig, need = genesis.bond_stresses(w, P.tensile_strength)
  figures.histogram{file = out .. "/bond_stresses_sigma.png", values = sig, bins = 50,
                    xlabel = "bond normal stress (Pa, model; tension +)", ylabel = "bonds",
                    column = "sigma [Pa (model)]", csv = out .. "/bond_stresses_sigma_hist.csv",
                    title = "Bond normal stress after wall removal",
                    marks = {{x = P.tensile_strength, label = "st"}}}
  figures.histogram{file = out .. "/bond_stresses_strength.png", values = need, bins = 50, min = 0,
                    xlabel = "strength the bond needs to hold (Pa, model)", ylabel = "bonds",
                    column = "strength_to_hold [Pa (model)]", csv = out .. "/bond_stresses_strength_hist.csv",
                    title = "Bond strength each bond needs after wall removal (elliptic criterion)",
                    marks = {{x = P.tensile_strength, label = "st"}, {x = P.tensile_strength / 3, label = "st/3"}}}
  return stats
end
local residual = residual_stresses(welastic)
log("bond stresses after wall removal: sigma %.3g .. %.3g Pa, strength to hold: 99.9 %% below %.3g Pa = %.3f st, max %.3g Pa = %.3f st",
    residual.sigma_min_pa, residual.sigma_max_pa, residual.strength_to_hold_p999_pa, residual.p999_over_st,
    residual.strength_to_hold_max_pa, residual.max_over_st)

-- 3. Platens and gauges -------------------------------------------------------------------------------
local rigs = {}   -- checkpoint name -> {platens, gauges}
local function prepare(w, name)
  local ext = specimen.extent(w, packing.kept)
  local pl = specimen.platens(w, {thickness = P.platen, ids = packing.kept, extent = ext})
  local g = specimen.gauges(w, {platens = pl, extent = ext})
  w:save(out .. "/" .. name .. ".h5")
  rigs[name] = {platens = pl, gauges = g}
  return pl, g
end
local platens, gauges = prepare(welastic, "elastic")
welastic = nil
collectgarbage()
local function mean_z(w, set)
  local pos, s = w:positions(), 0
  for _, id in ipairs(set) do s = s + pos:get(id, 3) end
  return s / #set
end

-- One test from a checkpoint: the top platen moves at `velocity`; rows every P.every steps;
-- `stop(row, peak)` ends it. slab = true also records the mean stress tensor of the middle slab.
local columns = {"step", "time [s]", "displacement [m]", "axial_stress [Pa (model)]", "shear_stress [Pa (model)]",
                 "axial_strain", "lateral_strain", "strain_x", "strain_y", "shear_strain",
                 "shear_strain_layers", "broken_bonds", "slab_xx [Pa (model)]", "slab_yy [Pa (model)]", "slab_zz [Pa (model)]",
                 "slab_xz [Pa (model)]", "slab_zx [Pa (model)]"}
-- Attributes of every series file: the test, the run's parameters (one parameter_NAME each, as
-- joint.lua writes them) and the stress scale. The columns are model stresses; this REV's own
-- scale to the rock (E_rock / its measured E, summary.json's stress_scale) is known only after
-- both elastic tests, later than their files are written, so the files carry the scale of the
-- calibrated REV of materials.lua, the one joint.lua uses, under a name that says so.
local parameters = {}
for name, v in pairs(P) do parameters[name] = v end   -- as given: rate_check changes P.rate later
local function series_attributes(name)
  local a = {test = name, rate = P.rate, size = L,
             stress_scale_calibrated = mat.stress_scale(),
             young_modulus_rev_calibrated = rev.young_modulus,
             stress_units = "stress columns are model stresses, Pa (model); MPa scaled to rock = model Pa x " ..
                            "stress_scale_calibrated / 1e6 with the calibrated REV (materials.lua, E_REV = " ..
                            "young_modulus_rev_calibrated Pa); this REV's own scale from its measured E is " ..
                            "stress_scale in summary.json"}
  for k, v in pairs(parameters) do a["parameter_" .. k] = type(v) == "boolean" and tostring(v) or v end
  return a
end
local function run_test(checkpoint, name, velocity, o)
  local t0 = asperity.wall_time()
  local platens, gauges = rigs[checkpoint].platens, rigs[checkpoint].gauges
  local w = asperity.load(out .. "/" .. checkpoint .. ".h5", {threads = P.threads, simd = P.simd})
  if P.dt_safety > 0 then w:set_dt_safety(P.dt_safety) end
  local meter = specimen.strain_meter(w, gauges)
  local zlo, zhi = mean_z(w, gauges.lower), mean_z(w, gauges.upper)
  local s0 = o.slab and specimen.slab_stress(w, zlo, zhi, area)
  local start = w:group_position(platens.top)
  local dir = velocity[1] ~= 0 and 1 or 3
  local series = asperity.series(with(columns, {attributes = series_attributes(name)}))
  w:set_group_velocity(platens.top, velocity)
  local peak, peak_row = 0, nil
  local last
  local function row(w)
    local e, s = meter:read(w), specimen.stresses(w, platens, area)
    local p = w:group_position(platens.top)
    local r = {step = w:step(), time = w:time(), displacement = (dir == 1 and p.x - start.x or p.z - start.z),
               axial_stress = s.axial, shear_stress = s.shear_x, axial_strain = e.axial,
               lateral_strain = e.lateral, strain_x = e.x, strain_y = e.y, shear_strain = e.shear_xz,
               shear_strain_layers = e.shear_xz_layers, broken_bonds = w:break_count(),
               slab_xx = 0, slab_yy = 0, slab_zz = 0, slab_xz = 0, slab_zx = 0}
    if s0 then
      local t = specimen.slab_stress(w, zlo, zhi, area)
      r.slab_xx, r.slab_yy, r.slab_zz = t[1][1] - s0[1][1], t[2][2] - s0[2][2], t[3][3] - s0[3][3]
      r.slab_xz, r.slab_zx = t[1][3] - s0[1][3], t[3][1] - s0[3][1]
    end
    series:record(r)
    return r
  end
  row(w)
  local steps = w:run{steps = o.max_steps or 100000000, every = P.every,
    stop_when = function(w)
      last = row(w)
      local v = o.value(last)
      if math.abs(v) > peak then peak, peak_row = math.abs(v), last end
      return o.stop(last, peak)
    end,
    show = function() return last and {stress = o.value(last), peak = peak, broken = w:break_count()} end}
  local result = {series = series, peak = peak, peak_row = peak_row, steps = steps,
                  seconds = asperity.wall_time() - t0, world = w}
  series:write(out .. "/" .. name)
  return result
end

local function column(series, name) return series:column(name):flat() end
-- Axis labels of the stress-strain plots: words and units (tension positive, as the series).
local AXIAL_STRAIN, AXIAL_STRESS = "axial strain (-, tension +)", "axial stress (Pa, model; tension +)"

-- Linear fits over the part of the test beyond 20 % of its final strain (the start-up of the
-- platen is left out).
local function fit(series, xname, yname, strain_name)
  local x, y, e = column(series, xname), column(series, yname), column(series, strain_name or xname)
  local emax = math.abs(e[#e])
  return specimen.fit_line(x, y, function(i) return math.abs(e[i]) >= 0.2 * emax end)
end

local function elastic_axial(name, sign, checkpoint)
  local r = run_test(checkpoint or "elastic", name, {0, 0, sign * P.rate}, {slab = true,
    value = function(row) return row.axial_stress end,
    stop = function(row) return math.abs(row.axial_strain) >= P.elastic_strain end})
  local s = r.series
  local E, _, r2 = fit(s, "axial_strain", "axial_stress")
  local nu = -fit(s, "axial_strain", "lateral_strain")
  -- End restraint: the bonded platens hold the ends from spreading, so the middle slab is not in
  -- uniaxial stress; with the slab's mean stress tensor, isotropic elasticity gives E and nu:
  -- E ezz = szz - nu (sxx + syy), E elat = slat - nu (szz + slat).
  local sz = fit(s, "axial_strain", "slab_zz")
  local sl = (fit(s, "axial_strain", "slab_xx") + fit(s, "axial_strain", "slab_yy")) / 2
  local rl = fit(s, "axial_strain", "lateral_strain")
  local nu_c = (sl - sz * rl) / (sz + sl - 2 * sl * rl)
  local E_c = sz - 2 * nu_c * sl
  s:plot{file = out .. "/" .. name .. ".png", x = "axial_strain", y = {"axial_stress"},
         xlabel = AXIAL_STRAIN, ylabel = AXIAL_STRESS,
         title = ("%s: E = %.4g Pa (model), nu = %.3f"):format(name:gsub("_", " "), E, nu)}
  log("%-20s E = %.4g Pa (R2 %.5f), nu = %.4f; slab-corrected E = %.4g Pa, nu = %.4f  [%d steps, %.1f s]",
      name, E, r2, nu, E_c, nu_c, r.steps, r.seconds)
  return {young_modulus_pa = E, poisson_ratio = nu, young_modulus_slab_pa = E_c, poisson_ratio_slab = nu_c,
          fit_r2 = r2, steps = r.steps, seconds = r.seconds, lateral_confinement = sl / sz}
end

local elastic
local E, nu, E_slab, nu_slab = rev.young_modulus, nil, nil, nil
if want.elastic then
  elastic = {}
  timed("elastic_compression", function() elastic.compression = elastic_axial("elastic_compression", -1) end)
  timed("elastic_tension", function() elastic.tension = elastic_axial("elastic_tension", 1) end)
  E = (elastic.compression.young_modulus_pa + elastic.tension.young_modulus_pa) / 2
  nu = (elastic.compression.poisson_ratio + elastic.tension.poisson_ratio) / 2
  E_slab = (elastic.compression.young_modulus_slab_pa + elastic.tension.young_modulus_slab_pa) / 2
  nu_slab = (elastic.compression.poisson_ratio_slab + elastic.tension.poisson_ratio_slab) / 2
end

-- Isotropy [scenarios.md 2.4]: E and nu in compression along x, y and z.
local by_axis
if want.isotropy then
  by_axis = {young_modulus = {z = elastic.compression.young_modulus_pa}, poisson_ratio = {z = elastic.compression.poisson_ratio}}
  for _, axis in ipairs{"x", "y"} do
    timed("isotropy_" .. axis, function()
      local w = bonded(with(bond_material, {breakable = false}), nil, axis)
      prepare(w, "elastic_" .. axis)
      w = nil
      collectgarbage()
      local r = elastic_axial("elastic_compression_" .. axis, -1, "elastic_" .. axis)
      by_axis.young_modulus[axis], by_axis.poisson_ratio[axis] = r.young_modulus_pa, r.poisson_ratio
    end)
  end
  local function spread(t)
    local lo, hi, m = math.huge, -math.huge, 0
    for _, a in ipairs{"x", "y", "z"} do lo, hi, m = math.min(lo, t[a]), math.max(hi, t[a]), m + t[a] / 3 end
    return (hi - lo) / m
  end
  by_axis.young_modulus_spread = spread(by_axis.young_modulus)
  by_axis.poisson_ratio_spread = spread(by_axis.poisson_ratio)
  log("isotropy: E x/y/z = %.4g / %.4g / %.4g Pa (spread %.1f %%), nu = %.3f / %.3f / %.3f (spread %.1f %%)",
      by_axis.young_modulus.x, by_axis.young_modulus.y, by_axis.young_modulus.z, 100 * by_axis.young_modulus_spread,
      by_axis.poisson_ratio.x, by_axis.poisson_ratio.y, by_axis.poisson_ratio.z, 100 * by_axis.poisson_ratio_spread)
end

local shear
if want.shear then
  timed("shear", function()
    local r = run_test("elastic", "shear", {P.rate, 0, 0}, {slab = true,
      value = function(row) return row.shear_stress end,
      stop = function(row) return math.abs(row.shear_strain_layers) >= P.elastic_strain end})
    local s = r.series
    local G = fit(s, "shear_strain", "shear_stress", "shear_strain_layers")
    local G_layers = fit(s, "shear_strain_layers", "shear_stress")
    -- The symmetric part of the slab's mean stress: with rotations locked the stress tensor is not
    -- symmetric (the locks take the moment of the contact forces), and only its symmetric part
    -- belongs to the strain (tau = G gamma of an isotropic solid).
    local x, z, zx = column(s, "shear_strain"), column(s, "slab_xz"), column(s, "slab_zx")
    local sym = {}
    for i = 1, #z do sym[i] = (z[i] + zx[i]) / 2 end
    local e = column(s, "shear_strain_layers")
    local emax = math.abs(e[#e])
    local keep = function(i) return math.abs(e[i]) >= 0.2 * emax end
    local G_sym = specimen.fit_line(x, sym, keep)
    local G_slab_zx = specimen.fit_line(x, z, keep)
    s:plot{file = out .. "/shear.png", x = "shear_strain", y = {"shear_stress"},
           xlabel = "shear strain (-)", ylabel = "shear stress (Pa, model)",
           title = ("direct shear: G = %.4g Pa (model)"):format(G)}
    shear = {shear_modulus_pa = G, shear_modulus_layers_pa = G_layers, shear_modulus_symmetric_pa = G_sym,
             shear_modulus_slab_pa = G_slab_zx, steps = r.steps, seconds = r.seconds}
    log("%-20s G = %.4g Pa (layers only %.4g, symmetric stress %.4g); E/2(1+nu) = %.4g, slab %.4g  [%d steps, %.1f s]",
        "shear", G, G_layers, G_sym, E / (2 * (1 + nu)), E_slab / (2 * (1 + nu_slab)), r.steps, r.seconds)
  end)
end

-- Fracture -----------------------------------------------------------------------------------------
local fracture
local function break_map(w, name, title)
  local events = w:break_events()
  local f = assert(io.open(out .. "/" .. name .. "_breaks.csv", "w"))
  f:write("step,time [s],x [m],y [m],z [m],a,b,kind,mode,sigma [Pa (model)],tau [Pa (model)],released_energy [J]\n")
  local modes = {tension = 1, shear = 2, compression = 3}
  local pts = {}
  for _, e in ipairs(events) do
    local p = e.position
    f:write(("%d,%.10g,%.10g,%.10g,%.10g,%d,%d,%s,%s,%.10g,%.10g,%.10g\n"):format(
      e.step, e.time, p.x, p.y, p.z, e.a, e.b, e.kind, e.mode, e.sigma, e.tau, e.released_energy))
    if e.kind == "beam" then pts[#pts + 1] = {p.x, p.y, p.z, modes[e.mode]} end
  end
  f:close()
  local ext = specimen.extent(w)
  figures.map{file = out .. "/" .. name .. "_breaks.png", points = pts, groups = {"tension", "shear", "compression"},
              extent = ext, title = title}
  local counts = {tension = 0, shear = 0, compression = 0}
  for _, e in ipairs(events) do
    if e.kind == "beam" then counts[e.mode] = counts[e.mode] + 1 end
  end
  return counts
end

local function fracture_test(name, sign, rate)
  local r = run_test("fracture", name, {0, 0, sign * rate}, {
    value = function(row) return row.axial_stress end,
    stop = function(row, peak)
      return (math.abs(row.axial_stress) < P.stop_fraction * peak and peak > 0 and row.broken_bonds > 0)
             or math.abs(row.axial_strain) >= P.max_strain
    end})
  local s = r.series
  s:plot{file = out .. "/" .. name .. ".png", x = "axial_strain", y = {"axial_stress"},
         xlabel = AXIAL_STRAIN, ylabel = AXIAL_STRESS,
         title = ("%s: peak %.4g Pa (model) = %.3g MPa scaled by %s"):format(name:gsub("_", " "), r.peak,
           mat.to_rock_mpa(r.peak, E), want.elastic and "this REV's E" or "the calibrated REV's E")}
  local counts = break_map(r.world, name, ("%s: broken bonds at the end (%d)"):format(name, r.world:break_count()))
  log("%-20s strength %.4g Pa at strain %.3g; %d bonds broken (tension %d, shear %d, compression %d)  [%d steps, %.1f s]",
      name, r.peak, r.peak_row.axial_strain, r.world:break_count(), counts.tension, counts.shear,
      counts.compression, r.steps, r.seconds)
  return {strength_pa = r.peak, strain_at_peak = r.peak_row.axial_strain, broken_bonds = r.world:break_count(),
          breaks = counts, steps = r.steps, seconds = r.seconds}
end

if want.compression or want.tension then
  local wf, finfo = timed("bond_relax_fracture", bonded, with(bond_material, {tensile_strength = P.tensile_strength}))
  log("fracture model: st = %.4g Pa, %d bonds, %d broken during the relaxation", P.tensile_strength, finfo.bonds,
      finfo.broken_in_relaxation)
  prepare(wf, "fracture")
  wf = nil
  collectgarbage()
  fracture = {relaxation = finfo}
  if want.compression then
    timed("fracture_compression", function() fracture.compression = fracture_test("fracture_compression", -1, P.rate) end)
  end
  if want.tension then
    timed("fracture_tension", function() fracture.tension = fracture_test("fracture_tension", 1, P.rate) end)
  end
end

-- Quasi-static check: the same tests at half the rate.
local rate_check
if P.rate_check then
  local half = P.rate / 2
  local t = asperity.wall_time()
  local saved = P.rate
  P.rate = half
  local c = elastic_axial("elastic_compression_half_rate", -1)
  local sh
  if want.shear then
    local r = run_test("elastic", "shear_half_rate", {half, 0, 0}, {
      value = function(row) return row.shear_stress end,
      stop = function(row) return math.abs(row.shear_strain_layers) >= P.elastic_strain end})
    sh = fit(r.series, "shear_strain", "shear_stress", "shear_strain_layers")
  end
  local fc, ft
  if want.compression then fc = fracture_test("fracture_compression_half_rate", -1, half) end
  if want.tension then ft = fracture_test("fracture_tension_half_rate", 1, half) end
  P.rate = saved
  local function rel(a, b) return b and a and (a - b) / b or nil end
  rate_check = {rate = half,
                young_modulus_change = rel(c.young_modulus_pa, elastic.compression.young_modulus_pa),
                poisson_ratio_change = rel(c.poisson_ratio, elastic.compression.poisson_ratio),
                shear_modulus_change = shear and rel(sh, shear.shear_modulus_pa),
                compressive_strength_change = fc and rel(fc.strength_pa, fracture.compression.strength_pa),
                tensile_strength_change = ft and rel(ft.strength_pa, fracture.tension.strength_pa),
                seconds = asperity.wall_time() - t}
  log("half rate: relative changes E %.2g, nu %.2g, G %s, sc %s, st %s", rate_check.young_modulus_change,
      rate_check.poisson_ratio_change, tostring(rate_check.shear_modulus_change),
      tostring(rate_check.compressive_strength_change), tostring(rate_check.tensile_strength_change))
end

-- Summary ---------------------------------------------------------------------------------------------
local scale = mat.rock.young_modulus / E
local summary = {
  n_particles = packing.n_particles, porosity_nominal = packing.porosity_nominal,
  porosity_true = packing.porosity_true, mean_radius_m = packing.mean_radius,
  radius_dispersion = packing.radius_stats.dispersion, coordination_packed = packing.coordination,
  wall_stress_pa = packing.wall_stress_pa,
  genesis = {particles_generated = packing.n_generated, floaters_removed = packing.genesis.floaters_removed,
             floaters_grown = packing.genesis.floaters_grown, floater_share = packing.genesis.floater_share,
             stress_pa = packing.genesis.stress_pa, stress_target_pa = P.genesis_stress,
             stress_reached = packing.genesis.stress_reached, radius_factor = packing.genesis.radius_factor,
             coordination = packing.genesis.coordination, interior = packing.genesis.interior,
             steps = packing.genesis.steps,
             seconds = packing.genesis.seconds, porosity_nominal = packing.porosity_nominal,
             porosity_true = packing.porosity_true},
  bond_stress_max_over_st = residual.max_over_st, bond_stress_p999_over_st = residual.p999_over_st,
  bonds_above_third_of_st = residual.above_third_of_st,
  bonds = elastic_info.bonds, bonds_per_particle = 2 * elastic_info.bonds / packing.n_particles,
  residual_bond_stress = residual,
  young_modulus_pa = E, poisson_ratio = nu,
  young_modulus_slab_pa = E_slab, poisson_ratio_slab = nu_slab,
  shear_modulus_isotropic_pa = E and nu and E / (2 * (1 + nu)),  -- nil without the elastic test
  shear_modulus_isotropic_slab_pa = E_slab and nu_slab and E_slab / (2 * (1 + nu_slab)),
  elastic = elastic, shear = shear,
  young_modulus_by_axis_pa = by_axis and by_axis.young_modulus,
  poisson_ratio_by_axis = by_axis and by_axis.poisson_ratio,
  young_modulus_spread = by_axis and by_axis.young_modulus_spread,
  poisson_ratio_spread = by_axis and by_axis.poisson_ratio_spread,
  stress_scale = scale, young_modulus_rock_pa = mat.rock.young_modulus,
  bond_tensile_strength_pa = P.tensile_strength,
  rate_m_per_s = P.rate, dt_s = nil, rate_check = rate_check,
  parameters = P, timings_s = timings,
}
if shear then
  summary.shear_modulus_pa = shear.shear_modulus_pa
  summary.shear_modulus_layers_pa = shear.shear_modulus_layers_pa
  summary.shear_modulus_symmetric_pa = shear.shear_modulus_symmetric_pa
  summary.isotropy_error = shear.shear_modulus_pa / summary.shear_modulus_isotropic_pa - 1
  summary.isotropy_error_symmetric = shear.shear_modulus_symmetric_pa / summary.shear_modulus_isotropic_slab_pa - 1
end
if fracture then
  summary.fracture = fracture
  -- Either test may have been left out (tests=...).
  if fracture.compression then
    summary.compressive_strength_pa = fracture.compression.strength_pa
    summary.compressive_strength_mpa = fracture.compression.strength_pa * scale / 1e6
  end
  if fracture.tension then
    summary.tensile_strength_pa = fracture.tension.strength_pa
    summary.tensile_strength_mpa = fracture.tension.strength_pa * scale / 1e6
  end
  if fracture.compression and fracture.tension then
    summary.strength_ratio = fracture.compression.strength_pa / fracture.tension.strength_pa
  end
  summary.broken_in_relaxation = fracture.relaxation.broken_in_relaxation
  summary.bonds_broken_in_relaxation = fracture.relaxation.broken_in_relaxation
end
summary.seconds = asperity.wall_time() - clock0
asperity.write_json(out .. "/summary.json", summary)
local function v(x, fmt) return x and (fmt):format(x) or "-" end  -- "-": the test was not run
log("E = %s Pa, nu = %s, G = %s Pa (E/2(1+nu) = %s), scale %.4g", v(E, "%.4g"), v(nu, "%.3f"),
    v(shear and shear.shear_modulus_pa, "%.4g"), v(summary.shear_modulus_isotropic_pa, "%.4g"), scale)
if fracture then
  log("sc = %s Pa = %s MPa, st = %s Pa = %s MPa, ratio %s", v(summary.compressive_strength_pa, "%.4g"),
      v(summary.compressive_strength_mpa, "%.2f"), v(summary.tensile_strength_pa, "%.4g"),
      v(summary.tensile_strength_mpa, "%.2f"), v(summary.strength_ratio, "%.2f"))
end
log("wrote %s/summary.json (%.0f s)", out, summary.seconds)
return summary   -- for scripts that run this one with dofile (calibrate_rev.lua)
