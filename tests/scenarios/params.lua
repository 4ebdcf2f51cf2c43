-- Every parameter of every script is checked on entry (scripts/lib/params.lua): for each declared
-- parameter this feeds the script values its declaration forbids (wrong type, out of range, not
-- in the set, not finite, an unreadable file) and asserts that the script refuses each one by
-- name before it does any work. The functions that do work (worlds, files, surfaces) are
-- replaced by one that fails the test, so a value that slips through is caught at once instead of
-- running a simulation. Rules between parameters are tested by hand below.
local lib = require("params")
local scripts_dir = asperity.scripts_dir

local WORK = "the script started working"
local real = {}
local function guard(tbl, key, path)
  real[path] = tbl[key]
  tbl[key] = function() error(WORK .. " (" .. path .. ")", 0) end
end
guard(asperity, "world", "asperity.world")
guard(asperity, "load", "asperity.load")
guard(asperity, "mkdir", "asperity.mkdir")
guard(asperity, "snapshots", "asperity.snapshots")
guard(asperity, "series", "asperity.series")
guard(asperity.surface, "generate", "asperity.surface.generate")
guard(asperity.surface, "load", "asperity.surface.load")

-- The declaration of a script, captured from its call to parse.
local function spec_of(script)
  local captured
  local parse = lib.parse
  lib.parse = function(spec) captured = spec; error("captured", 0) end
  params = {}
  pcall(dofile, scripts_dir .. "/" .. script)
  lib.parse = parse
  assert(captured, script .. " declares its parameters with params.parse")
  return captured
end

local function run(script, given)
  params = given
  local ok, err = pcall(dofile, scripts_dir .. "/" .. script)
  return ok, err
end

local function show(v)
  if type(v) == "number" and v ~= v then return "nan" end
  return type(v) == "string" and ("'" .. v .. "'") or tostring(v)
end

-- Values the declaration forbids.
local function bad_values(e)
  local out = {}
  local k = e.type or (e.list and "string") or type(e[2])
  if e.list then
    if e.list == "number" then
      out[#out + 1] = "abc"
      out[#out + 1] = "1,,x"
      if e.min then out[#out + 1] = tostring(e.min - 1) end
      if e.above then out[#out + 1] = tostring(e.above) end
    elseif e.oneof then
      out[#out + 1] = "bogus"
    end
  elseif k == "number" or k == "integer" then
    out[#out + 1] = "abc"
    out[#out + 1] = true
    out[#out + 1] = 0 / 0
    out[#out + 1] = math.huge
    if e.min then out[#out + 1] = e.min - math.max(1, math.abs(e.min)) * 0.5 end
    if e.above then out[#out + 1] = e.above end
    if e.max then out[#out + 1] = e.max + math.max(1, math.abs(e.max)) * 0.5 end
    if e.below then out[#out + 1] = e.below end
    if k == "integer" then out[#out + 1] = (e.min or 0) + 1.5 end
  elseif k == "boolean" then
    out[#out + 1] = "maybe"
    out[#out + 1] = 1
  else
    if e.oneof then out[#out + 1] = "bogus" end
    if e.file then out[#out + 1] = "/no/such/file.h5" end
    if e.nonempty then out[#out + 1] = "" end
  end
  return out
end

local checked, skipped = 0, {}
local function expect_refusal(script, given, name, pattern)
  local ok, err = run(script, given)
  local text = tostring(err)
  local desc = ("%s %s=%s"):format(script, name, show(given[name]))
  assert(not ok, desc .. ": accepted")
  assert(not text:find(WORK, 1, true), desc .. ": not refused on entry (" .. text .. ")")
  assert(getmetatable(err) == lib.Refusal, desc .. ": an ordinary error, not a refusal: " .. text)
  assert(text:find(script .. ": parameter " .. name .. "=", 1, true),
         desc .. ": the message does not name the parameter: " .. text)
  if pattern then assert(text:find(pattern), desc .. ": message '" .. text .. "' lacks " .. pattern) end
  checked = checked + 1
end

for _, script in ipairs{"joint.lua", "rev.lua", "calibrate_rev.lua", "surface.lua", "demo.lua", "study.lua"} do
  local spec = spec_of(script)
  -- The defaults pass their own checks: the script gets to its first piece of work.
  local ok, err = run(script, {})
  assert(not ok and tostring(err):find(WORK, 1, true), script .. ": the defaults are refused: " .. tostring(err))
  -- help=true prints the table and stops before any work: every parameter with its default,
  -- its unit and what is allowed.
  local printed = {}
  local write = io.write
  io.write = function(...) for _, s in ipairs{...} do printed[#printed + 1] = tostring(s) end end
  ok, err = run(script, {help = true})
  io.write = write
  assert(ok, script .. ": help=true failed: " .. tostring(err))
  local text = table.concat(printed)
  for _, e in ipairs(spec) do
    local line = text:match("\n  (" .. e[1]:gsub("%p", "%%%0") .. "=[^\n]*)")
    assert(line, script .. ": the help does not list " .. e[1])
    if e.unit then assert(line:find(e.unit, 1, true), script .. ": the help gives no unit for " .. e[1]) end
    local a = lib.allowed(e)
    if a ~= "" then assert(line:find(a, 1, true), script .. ": the help does not say what " .. e[1] .. " allows") end
  end
  for _, e in ipairs(spec) do
    local values = bad_values(e)
    if #values == 0 then skipped[#skipped + 1] = script .. ":" .. e[1] end
    for _, v in ipairs(values) do expect_refusal(script, {[e[1]] = v}, e[1]) end
    -- every parameter is documented for the help
    assert(e.doc and e.doc ~= "", script .. ": parameter " .. e[1] .. " has no doc")
  end
  -- an unknown name is refused with the list of known ones
  ok, err = run(script, {no_such_parameter = 1})
  assert(not ok and tostring(err):find("unknown parameter 'no_such_parameter'", 1, true), script .. ": unknown name")
end

-- Rules between parameters and the cases a user met.
expect_refusal("joint.lua", {stress = -5}, "stress", "must be > 0")
expect_refusal("joint.lua", {contact_strength = "strong"}, "contact_strength", 'must be "beam"')
expect_refusal("joint.lua", {contact_strength = "0"}, "contact_strength", "a number > 0")
expect_refusal("rev.lua", {contact_shear_strength = "-1"}, "contact_shear_strength", 'must be "same"')
expect_refusal("calibrate_rev.lua", {contact_strength = "never"}, "contact_strength", '"inf"')
expect_refusal("joint.lua", {stress = 0}, "stress", "must be > 0")
expect_refusal("joint.lua", {shear = -1}, "shear")
expect_refusal("joint.lua", {shear = 0}, "shear")
expect_refusal("joint.lua", {shear = 0.3}, "shear", "residual window")
expect_refusal("joint.lua", {shear = 2, residual_window = 2}, "shear", "residual window")
expect_refusal("joint.lua", {snapshots = "abc"}, "snapshots", "not a number")
expect_refusal("joint.lua", {snapshots = "0,1,7"}, "snapshots", "beyond shear")
expect_refusal("joint.lua", {shear = 1, record = 1}, "record", "< shear")
expect_refusal("joint.lua", {shear = 1, ramp = 2}, "ramp", "< shear")
expect_refusal("joint.lua", {size = -0.02}, "size")
expect_refusal("joint.lua", {velocity = 0}, "velocity")
expect_refusal("joint.lua", {platen = 0.007}, "platen", "thickness")
expect_refusal("joint.lua", {spacing = 0.05}, "spacing", "grid cells")
expect_refusal("rev.lua", {platen = 0.006}, "platen", "size / 2")
expect_refusal("rev.lua", {radius_sd = 0.2e-3}, "radius_sd", "3 SD")
expect_refusal("rev.lua", {tests = ""}, "tests", "at least one")
expect_refusal("surface.lua", {n = 128}, "n", "odd")
-- The study's lists: items from their sets, none twice, not empty; seeds whole; `joint` holds
-- key=value items and none of those the study sets on every run itself.
expect_refusal("study.lua", {surfaces = "S1,S9"}, "surfaces", "item S9: must be one of S1, S2")
expect_refusal("study.lua", {surfaces = "S1,S5,S1"}, "surfaces", "'S1' is listed twice")
expect_refusal("study.lua", {surfaces = ""}, "surfaces", "at least one")
expect_refusal("study.lua", {models = " , "}, "models", "at least one")
expect_refusal("study.lua", {directions = "x,z"}, "directions", "item z: must be one of x, y")
expect_refusal("study.lua", {stresses = "14,-21"}, "stresses", "item %-21: must be > 0")
expect_refusal("study.lua", {stresses = "14, 14.0"}, "stresses", "listed twice")
expect_refusal("study.lua", {seeds = "1,2.5"}, "seeds", "'2.5' is not a whole number")
expect_refusal("study.lua", {seeds = 0}, "seeds", "item 0: must be >= 1")
expect_refusal("study.lua", {jobs = -1}, "jobs", "must be an integer, >= 0")
expect_refusal("study.lua", {threads = 1.5}, "threads", "must be an integer")
expect_refusal("study.lua", {poll = 0}, "poll", "must be > 0 %(s%)")
expect_refusal("study.lua", {joint = "thickness=0.003 shear"}, "joint", "'shear' is not of the form key=value")
expect_refusal("study.lua", {joint = "stress=3"}, "joint", "'stress' is set by the study itself %(use its own parameters, e.g. stresses=%)")
expect_refusal("study.lua", {joint = "cache=/tmp/c"}, "joint", "'cache' is set by the study itself")
expect_refusal("study.lua", {asperity = "/no/such/asperity"}, "asperity", "no such readable file")
-- The default snapshots follow a shorter shear (those within it and its end); given ones do not.
do
  local parse, seen = lib.parse, nil
  lib.parse = function(spec, given) seen = parse(spec, given); return seen end
  run("joint.lua", {shear = 1})
  assert(seen.snapshots == "0,1", "default snapshots for shear=1: " .. tostring(seen.snapshots))
  run("joint.lua", {shear = 2})
  assert(seen.snapshots == "0,1,2", "default snapshots for shear=2: " .. tostring(seen.snapshots))
  run("joint.lua", {})
  assert(seen.snapshots == "0,1,2.5,5", "default snapshots for the default shear: " .. tostring(seen.snapshots))
  lib.parse = parse
end
-- A list given as one number keeps every digit (the study names and runs that stress).
do
  local parse, seen = lib.parse, nil
  lib.parse = function(spec, given) seen = parse(spec, given); return seen end
  run("study.lua", {stresses = 14.123456789, seeds = 3})
  lib.parse = parse
  assert(seen.stresses == "14.123456789" and seen.seeds == "3",
         ("stresses=14.123456789 seeds=3 became %s, %s"):format(tostring(seen.stresses), tostring(seen.seeds)))
end
-- A value typed on the command line arrives as a string or a number; both forms of a list pass.
for _, v in ipairs{"0,1", 1, "0, 0.5 ,1"} do
  local ok, err = run("joint.lua", {snapshots = v, shear = 1})
  assert(not ok and tostring(err):find(WORK, 1, true), ("snapshots=%s refused: %s"):format(show(v), tostring(err)))
end

-- params.run: another script with its own parameters; the caller's come back, and a refusal
-- reaches the caller as the same object.
params = {mine = true}
local ok, err = pcall(lib.run, "demo.lua", {n = 0})
assert(not ok and getmetatable(err) == lib.Refusal and tostring(err):find("parameter n=0", 1, true),
       "params.run passes the refusal on: " .. tostring(err))
assert(params.mine == true, "params.run restores the caller's params")
ok, err = pcall(lib.run, "demo.lua", {help = true})
assert(ok and params.mine == true, "params.run with help: " .. tostring(err))

print(("%d bad values refused by name; parameters without a forbidden value (free paths): %s"):format(
  checked, table.concat(skipped, ", ")))
print("PASS")
