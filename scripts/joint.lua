-- A rock joint closed and sheared under constant normal load (scenarios.md 3-6, surfaces.md 3).
--
--   build/asperity run scripts/joint.lua                              -- the default small joint
--   build/asperity run scripts/joint.lua surface=S5 model=rigid stress=21 direction=y
--   build/asperity run scripts/joint.lua scale=thesis                 -- 10 cm x 10 cm
--
-- The parameters, then the phases in order, each a module of scripts/lib/joint/ that reads and
-- fills one run context (joint/context.lua):
--   genesis    generate (or load) the surface; mould it as a triangle mesh between two boxes of
--              plane walls; pack both halves at once by the REV's genesis (lib/genesis.lua), bond
--              each half, remove the walls, part the halves by `gap` and relax them; cache the
--              result on disk (keyed by everything that shaped it, so the three models and both
--              directions reuse it)
--   assembly   analyse the DEM surfaces (profilometer, mean plane, surface vs porosity particles),
--              lower the upper half as a whole to `approach_gap`
--   model      the chosen model and the platens (with box=sides a shear box)
--   assembly   bring the upper half down at the closure velocity until one contact exists [4.2.1]
--   closure    close the joint at 6e-5 m/s to the normal stress [4.2.2]
--   shear      shear it under constant normal load (or stiffness) [4.3.1]
--   report     summary.json, the plots, the result line
--
-- A run that is killed resumes (joint/checkpoint.lua): while closing and shearing it saves its
-- state in out/.resume every `checkpoint_every` minutes and on SIGTERM, and the same command with
-- the same `out=` continues from the last save to the files an uninterrupted run writes.
--
-- Models [scenarios.md 4]: rigid (each half one rigid body; only particles that can touch the
-- other half are searched), elastic (unbreakable bonds), fracture (elliptic criterion with the
-- calibrated bond strength; refused if the genesis left more than 1 % of the bonds above it).
-- The halves are made by the REV's genesis (lib/genesis.lua), so they are the calibrated
-- material. Stresses are reported in model units and scaled to rock [3-37].
--
-- Writes into `out` (created once every check has passed): summary.json; closure.{h5,csv},
-- shear.{h5,csv} (stresses in model Pa and in MPa scaled to rock, closure and displacements in
-- mm; the stress scale and the parameters as attributes); snapshots joint.xdmf (XDMF time = shear
-- displacement, mm) at the displacements in `snapshots` and joint_closure.xdmf (closure, mm);
-- PNG plots: shear stress and dilatancy, normal stress and tau / sigma_n, closure curve, contact
-- count, broken bonds, energies, and maps of contact points and broken bonds over the elevation
-- at the peak and at the end. `--help` lists the parameters.
local mat = require("materials")
local params_lib = require("params")
local R = mat.packing.mean_radius
local P = params_lib.parse{
  script = "joint.lua",
  path = "scripts/joint.lua",
  about = "a rock joint closed and sheared under constant normal load",
  {"surface", "S1", oneof = {"S1", "S2", "S3", "S4", "S5", "S6", "S7", "S8", "flat"},
   doc = "reference surface (surfaces.md table 4), or flat: a plane, the control case"},
  {"surface_file", "", file = true, doc = "an HDF5 height map instead (dataset `height`, attribute `spacing`)"},
  {"scale", "", oneof = {"", "thesis"}, doc = "thesis: size 0.1 m (about 91 000 particles) unless size is given"},
  {"size", 0.05, unit = "m", min = 4 * R, doc = "side of the square joint (scenarios.md 3: 5 cm; 2 cm is a fast check of the machinery)"},
  {"thickness", 0.006, unit = "m", min = 2 * R, doc = "each half beyond the mean plane"},
  {"spacing", 0.1 / 365, unit = "m", above = 0, doc = "surface grid spacing (the thesis grid)"},
  {"model", "elastic", oneof = {"rigid", "elastic", "fracture"},
   doc = "rigid bodies, unbreakable bonds, or the calibrated breakable bonds [scenarios.md 4]"},
  {"stress", 14, unit = "MPa", above = 0, doc = "normal stress, scaled to rock (model Pa x stress scale)"},
  {"direction", "x", oneof = {"x", "y"}, doc = "the upper half moves along -x or -y"},
  {"shear", 5, unit = "mm", above = 0, doc = "shear displacement"},
  {"residual_window", 0.5, unit = "mm", above = 0, doc = "the residual stress is the mean over the last this much of the shear"},
  {"velocity", 1.5e-5, unit = "m/s", above = 0, doc = "shear velocity (perf/runtime_vs_error.lua: within 1 % of a 4x slower run)"},
  {"speedup", 0, type = "integer", oneof = {0, 1, 2, 4},
   doc = "after the peak the shear velocity may double at each record, up to this many times "
      .. "`velocity`, while the specimen stays quasi-static (speedup_kinetic); 1: constant velocity; the elastic "
      .. "model only (0: by model, 4 elastic, 1 rigid and fracture)"},
  {"speedup_drop", 0.25, above = 0, max = 1,
   doc = "past the peak: the shear stress below (1 - this) x the highest so far (above it again, the velocity steps back)"},
  {"speedup_kinetic", 0.002, above = 0,
   doc = "quasi-static while the kinetic energy stays below this x normal load x mean radius; above it the velocity steps back"},
  {"ramp", 0.05, unit = "mm", min = 0,
   doc = "the shear velocity, and the upper half's approach, rise linearly from 0 over this displacement"},
  {"quasi_static_limit", 0.01, above = 0, doc = "warn when the kinetic energy exceeds this x normal load x mean radius"},
  {"overlap_limit", 0.5, above = 0, max = 1,
   doc = "warn when a contact of a particle free to turn overlaps this fraction of the smaller radius, its contact "
         .. "point and lever arm then far from a shallow contact's (the engine stops at overlap_stop)"},
  {"overlap_stop", 0, min = 0, max = 1.9,
   doc = "the engine stops the run at an overlap of this many smaller radii (0: 1, the rigid model 1.9)"},
  {"normal_control", "servo", oneof = {"servo", "load", "stiffness"},
   doc = "servo (model.md 7, with integral action), load: a constant force on a free platen, or stiffness: "
         .. "constant normal stiffness, sigma_0 + normal_stiffness x dilatancy"},
  {"normal_stiffness", 0, unit = "MPa/mm", min = 0, doc = "scaled to rock; of normal_control=stiffness (> 0 there, 0 otherwise)"},
  {"platen_damping", 0, below = 1, doc = "local damping of the dead-load platen (< 0: the world's)"},
  {"servo_relaxation", asperity.servo_defaults().relaxation, above = 0, max = 1, doc = "servo gain: fraction of the force error corrected per step"},
  {"servo_integral_steps", 2, min = 0, doc = "integral time of the servo, in time steps (0: proportional only)"},
  {"servo_max_velocity", 100, above = 0, doc = "the servo's speed limit, in shear velocities"},
  {"closure_velocity", 6e-5, unit = "m/s", above = 0, doc = "closure velocity [thesis 4.2.2]"},
  {"closure_every", 0, type = "integer", min = 0,
   doc = "steps between closure records (0: 50, or 1 for the rigid model, which closes in a few dozen steps)"},
  {"approach_gap", 0.2e-3, unit = "m", min = 0, doc = "smallest gap left between the halves after lowering the upper one"},
  {"gap", 1e-3, unit = "m", min = 0, doc = "between the halves while they relax"},
  {"platen", 1.5e-3, unit = "m", above = 0, doc = "layer of each outer face that forms a platen"},
  {"box", "sides", oneof = {"sides", "none"},
   doc = "sides: the layer of the four side faces joins its half's platen (a shear box) up to box_clearance "
         .. "from the joint; none: the platens are the top and bottom layers only, the sides are free"},
  {"box_clearance", 1e-3, unit = "m", min = 0,
   doc = "the shear box's sides stop this far below (lower half) or above (upper half) the highest (lowest) "
         .. "point of their half's surface within this distance"},
  {"porosity", mat.genesis.porosity, above = 0, below = 1, doc = "thesis definition [3-35]: the particle count of the genesis"},
  {"genesis_stress", mat.genesis.stress, unit = "Pa", above = 0, doc = "isotropic stress installed before bonding (scenarios.md 1; model units)"},
  {"genesis_shrink_gain", mat.genesis.shrink_gain, above = 0, max = 1, doc = "the stress servo's gain when it shrinks the radii, relative to when it grows them (< 1: it comes down to the target with the relaxation)"},
  {"genesis_damping", mat.genesis.damping, min = 0, below = 1, doc = "the local damping of the packing steps (compaction and stress installation, the stress then installed again at the material's)"},
  {"genesis_mass_floor", mat.genesis.mass_floor, min = 0, max = 2, doc = "while packing, particles smaller than this x mean radius weigh as one of it (a larger time step; 0: true masses)"},
  {"bond_gap", 0, unit = "m", min = 0, doc = "largest gap bonded (0: the engine's default, 1e-3 x mean radius)"},
  {"tensile_strength", mat.rev.bond_tensile_strength, unit = "Pa", above = 0,
   doc = "fracture model: bond strength st (model units; the REV's calibrated one by default)"},
  {"rotation_lock_bonds", mat.rev.rotation_lock_bonds, type = "integer", min = 1,
   doc = "fracture model: a damaged particle rotates once it holds fewer bonds (1: the thesis's rule; model.md 2)"},
  {"rotation_lock_beams", mat.rev.rotation_lock_beams,
   doc = "fracture model: only bonds whose parallel bond holds lock rotation (false: a contact bond alone too; model.md 5)"},
  {"contact_strength", mat.rev.contact_strength, type = "string",
   doc = "fracture model: the contact bonds break at c st A: c > 0, \"inf\" (never) or \"beam\" (with the parallel bond) (model.md 5)"},
  {"contact_shear_strength", mat.rev.contact_shear_strength, type = "string",
   doc = "fracture model: the contact bonds break in shear at cs st A: cs > 0, \"inf\" (never) or \"same\" (as contact_strength)"},
  {"contact_bond_friction", mat.rev.contact_bond_friction, min = 0,
   doc = "fracture model: the contact bonds' shear strength grows by this x their compressive force (Mohr-Coulomb; 0: model.md 5)"},
  {"wall_friction", 0, min = 0, doc = "of the box walls and the mould during the genesis (scenarios.md 1: frictionless)"},
  {"seed", 1, type = "integer", min = 0, doc = "of the surface and the packing"},
  {"pack_steps", 300000, type = "integer", min = 1, doc = "most steps spent cycling the packing towards the ratio 1e-4"},
  {"record", 0.01, unit = "mm", above = 0, doc = "shear displacement between records"},
  {"dt_safety", 0, min = 0, max = 2,
   doc = "time step / critical estimate for closure and shear (0: 1.0 elastic and fracture, 0.8 rigid; above 1 only to study instability)"},
  {"skin", 0, unit = "m", min = 0, doc = "Verlet skin (0: 0.1 mean radius, the rigid model 0.4)"},
  {"mass_floor", -1, min = -1, max = 2,
   doc = "elastic and fracture: particles smaller than this x mean radius weigh as one of it in the closure and shear "
      .. "(the lightest set the critical time step; 0: true masses; -1: by model, 0.75 elastic, 0 fracture until its "
      .. "loading rate is calibrated)"},
  {"snapshots", "0,1,2.5,5", list = "number", unit = "mm", min = 0,
   doc = "shear displacements of the particle snapshots, within 0 .. shear (\"\": none; by default those "
         .. "within a shorter shear and its end)"},
  {"band", 0, unit = "m", min = 0, doc = "surface vs porosity band (0: mean radius)"},
  {"out", "out/joint", nonempty = true, doc = "output folder (created when the run starts writing)"},
  {"cache", "", doc = "folder of cached specimens (\"\": $ASPERITY_CACHE, else ~/.cache/asperity, else out/cache)"},
  {"threads", 0, type = "integer", min = 0, doc = "0: automatic"},
  {"genesis_threads", 0, type = "integer", min = 0,
   doc = "threads of the genesis, when this run packs the specimen (0: threads); the shear then runs on threads"},
  {"simd", "auto", oneof = {"auto", "scalar", "sse4_2", "avx2", "avx512f"},
   doc = "kernels of closure and shear (auto: the widest this CPU runs)"},
  {"progress", true, doc = "progress: a line redrawn on a terminal; in a log file, a line every 5 minutes (the first after 1)"},
  {"events_every", 0, type = "integer", min = 0,
   doc = "steps between energy samples for the event statistics (events.{h5,csv}); 0: none"},
  {"save", "", doc = "a path: the world's checkpoint when the shear ends"},
  {"checkpoint_every", 5, unit = "min", min = 0,
   doc = "while closing and shearing, save the run's state (out/.resume) every this many minutes of wall time "
         .. "and on SIGTERM; the same command resumes from it (0: never)"},
  {"stop_after", "", oneof = {"", "packing"}, doc = "packing: stop once the halves are packed, before bonding"},
  check = function(P, fail, given)
    -- The defaults by model, chosen by perf/runtime_vs_error.lua (perf/README.md, "Heavier light
    -- particles" and "Loading rate after the peak").
    if P.mass_floor < 0 then P.mass_floor = P.model == "elastic" and 0.75 or 0 end
    if P.speedup == 0 then P.speedup = P.model == "elastic" and 4 or 1 end
    if P.residual_window >= P.shear then
      fail("shear", ("must exceed the residual window (residual_window = %g mm): the residual is the "
                     .. "mean over the last residual_window of the shear"):format(P.residual_window))
    end
    if P.record >= P.shear then fail("record", ("must be < shear (%g mm)"):format(P.shear)) end
    local _, why = mat.contact_strength(P.contact_strength)
    if why then fail("contact_strength", why) end
    local _, why_shear = mat.contact_shear_strength(P.contact_shear_strength)
    if why_shear then fail("contact_shear_strength", why_shear) end
    if P.ramp >= P.shear then fail("ramp", ("must be < shear (%g mm)"):format(P.shear)) end
    if P.speedup > 1 and P.model == "fracture" then
      fail("speedup", "is not for the fracture model: its results depend on the loading rate already at "
                      .. "`velocity` (perf/README.md, loading rate after the peak); give speedup=1")
    elseif P.speedup > 1 and P.model == "rigid" then
      fail("speedup", "is not for the rigid model: its residual moves with it (2 cm S4: +5.8 % at "
                      .. "speedup=4) and its shear takes seconds; give speedup=1")
    end
    if given.snapshots ~= nil then
      for _, s in ipairs(params_lib.split(P.snapshots, true)) do
        if s > P.shear then fail("snapshots", ("%g mm is beyond shear = %g mm"):format(s, P.shear)) end
      end
    else
      -- the default list follows a shorter shear: the displacements within it, and its end
      local kept = {}
      for _, s in ipairs(params_lib.split(P.snapshots, true)) do
        if s < P.shear then kept[#kept + 1] = ("%g"):format(s) end
      end
      kept[#kept + 1] = ("%g"):format(P.shear)
      P.snapshots = table.concat(kept, ",")
    end
    -- Constant normal stiffness: a stiffness is what makes it one (0 would be the servo's CNL).
    if P.normal_control == "stiffness" and not (P.normal_stiffness > 0) then
      fail("normal_stiffness", "must be > 0 with normal_control=stiffness")
    elseif P.normal_control ~= "stiffness" and P.normal_stiffness ~= 0 then
      fail("normal_stiffness", ("needs normal_control=stiffness (now %s)"):format(P.normal_control))
    end
    if P.platen >= P.thickness then fail("platen", ("must be < thickness (%g m)"):format(P.thickness)) end
    local size = (P.scale == "thesis" and params.size == nil) and 0.1 or P.size
    local cells = size / P.spacing
    if cells < 2 or cells > 32766 then
      fail("spacing", ("gives %.0f grid cells over size = %g m; must give 2 .. 32766"):format(cells, size))
    end
  end,
}
if not P then return end   -- help printed
if P.scale == "thesis" and params.size == nil then P.size = 0.1 end
if P.cache == "" then
  local home = os.getenv("HOME")
  P.cache = os.getenv("ASPERITY_CACHE") or (os.getenv("XDG_CACHE_HOME") and os.getenv("XDG_CACHE_HOME") .. "/asperity")
            or (home and home ~= "" and home .. "/.cache/asperity") or (P.out .. "/cache")
end
local run = require("joint.context").new(P)
asperity.mkdir(P.cache)

local checkpoint = require("joint.checkpoint")
local genesis = require("joint.genesis")
run.surface = genesis.surface(P)
local saved = checkpoint.find(run)   -- a state this out= holds from an interrupted run, or nil
if not genesis.specimen(run) then return run.genesis_record end   -- stop_after = "packing"
local assembly = require("joint.assembly")
assembly.prepare(run)
require("joint.model").apply(run)
if saved then checkpoint.restore(run, saved) else assembly.first_contact(run) end
if not saved or saved.phase == "closure" then require("joint.closure").run(run, saved) end
require("joint.shear").run(run, saved and saved.phase == "shear" and saved or nil)
local summary = require("joint.report").write(run)
checkpoint.clear(run)   -- the summary written: nothing left to resume
return summary          -- for scripts that run this one (tests, the study)
