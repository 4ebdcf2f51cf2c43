-- Script parameters: the key=value pairs of `asperity run SCRIPT key=value ...` arrive in the
-- global table `params` (numbers and true/false already typed). A script declares what it takes,
-- once, and every value is checked on entry, before anything is built or written, so a bad value
-- is refused by name instead of running to the end with garbage.
--
--   local P = require("params").parse{
--     script = "joint.lua",
--     about = "A rock joint closed and sheared under constant normal load.",
--     {"stress", 14, unit = "MPa", above = 0, doc = "normal stress, scaled to rock"},
--     {"model", "elastic", oneof = {"rigid", "elastic", "fracture"}, doc = "..."},
--     {"snapshots", "0,1,5", list = "number", unit = "mm", min = 0, doc = "..."},
--     check = function(P, fail) if P.record >= P.shear then fail("record", "must be < shear") end end,
--   }
--   if not P then return end        -- help=true (or `asperity run SCRIPT --help`): printed, stop
--
-- A parameter entry: {name, default, ...} with
--   type     "number", "integer", "boolean" or "string" (default: that of the default value)
--   unit     printed in the help and in errors
--   min/max  inclusive bounds; above/below exclusive ones (numbers, and each item of a list)
--   oneof    the allowed values (strings or numbers); "" allowed only if listed
--   list     "number" or "string": a comma-separated list (a string; "" is the empty list),
--            each item checked against the bounds or `oneof`
--   file     true: a path that must be readable (when not "")
--   nonempty true: "" is refused (output folders)
--   doc      one line for the help
-- The spec's own fields: script (the name errors start with), path (for the usage line), about
-- (one line), notes (printed after the table), check (below). Defaults are not checked here:
-- tests/scenarios/params.lua runs every script with its defaults and with values each
-- declaration forbids.
-- Numbers must be finite. The spec's `check(P, fail, given)` runs after every single value
-- passed, for rules between parameters; fail(name, message) refuses one of them, and `given`
-- (the values as given) tells a default from a value the user chose, so a default may adapt to
-- the others where a given value would be refused.
--
-- Errors read "<script>: parameter NAME=VALUE: <what is allowed>" and carry no Lua position
-- (the position of the check inside this file would tell the user nothing).
local M = {}

local function show(v)
  if type(v) == "string" then return v == "" and '""' or v end
  if math.type(v) == "float" then
    if v ~= v then return "nan" end
    return ("%.6g"):format(v)
  end
  return tostring(v)
end

-- A number as text that reads back as the same number (a list or a name given as one number on the
-- command line, stresses=14.125 or seed-like names): show() rounds to 6 digits for messages.
local function exact(v)
  if math.type(v) == "integer" then return tostring(v) end
  for digits = 6, 17 do
    local t = ("%." .. digits .. "g"):format(v)
    if tonumber(t) == v then return t end
  end
  return ("%.17g"):format(v)
end

local function kind(e)
  if e.type then return e.type end
  if e.list then return "string" end
  return type(e[2])
end

-- The allowed values, in words: "> 0 MPa", "0 .. 1", "one of rigid, elastic, fracture".
local function allowed(e)
  local parts = {}
  if e.oneof then
    local names = {}
    for _, v in ipairs(e.oneof) do names[#names + 1] = show(v) end
    parts[#parts + 1] = "one of " .. table.concat(names, ", ")
  end
  local lo = e.min ~= nil and (">= " .. show(e.min)) or e.above ~= nil and ("> " .. show(e.above))
  local hi = e.max ~= nil and ("<= " .. show(e.max)) or e.below ~= nil and ("< " .. show(e.below))
  if lo and hi then
    parts[#parts + 1] = lo .. " and " .. hi
  elseif lo or hi then
    parts[#parts + 1] = lo or hi
  end
  local k = kind(e)
  if k == "integer" then table.insert(parts, 1, "an integer") end
  if k == "boolean" then parts[#parts + 1] = "true or false" end
  local text = table.concat(parts, ", ")
  if e.list then text = "a comma-separated list of " .. (e.list == "number" and "numbers" or "names") ..
                        (text ~= "" and (", each " .. text) or "") end
  if e.file then text = "a readable file, or \"\"" end
  return text
end
M.allowed = allowed
M.exact = exact   -- a number as the shortest text that reads back as the same number

-- The allowed values with the unit, for messages: "> 0 (MPa)".
local function allowed_with_unit(e)
  local text = allowed(e)
  if e.unit and e.unit ~= "" and text ~= "" and kind(e) ~= "boolean" and not e.oneof then
    text = text .. " (" .. e.unit .. ")"
  end
  return text
end

-- A refusal is raised as an error object whose text is the message: the program prints it
-- without a traceback (Lua's message handler leaves objects with __tostring alone), since the
-- user's command line, not the code, is at fault. tostring(err) gives the text to a pcall.
local Refusal = {__tostring = function(e) return e.message end}
M.Refusal = Refusal

local function raise(message) error(setmetatable({message = message}, Refusal), 0) end

local function refuse(script, name, value, what)
  raise(("%s: parameter %s=%s: %s"):format(script, name, show(value), what))
end

-- Bounds of one number; nil when it passes, else the reason.
local function out_of_range(e, v)
  if v ~= v or v == math.huge or v == -math.huge then return "must be a finite number" end
  if (e.min ~= nil and v < e.min) or (e.max ~= nil and v > e.max) or
     (e.above ~= nil and v <= e.above) or (e.below ~= nil and v >= e.below) then
    return "must be " .. allowed_with_unit(e)
  end
  if e.oneof then
    for _, o in ipairs(e.oneof) do if o == v then return nil end end
    return "must be " .. allowed(e)
  end
  return nil
end

-- The items of a comma-separated list ("0, 1,2.5" -> {0, 1, 2.5}); numbers when `as_numbers`.
-- Returns nil and the bad item when one is not a number.
function M.split(s, as_numbers)
  local items = {}
  for item in tostring(s):gmatch("[^,]+") do
    item = item:match("^%s*(.-)%s*$")
    if as_numbers then
      local x = tonumber(item)
      if x == nil then return nil, item end
      items[#items + 1] = x
    elseif item ~= "" then
      items[#items + 1] = item
    end
  end
  return items
end

-- One value, converted and checked; returns the value to use.
local function check_one(script, e, v)
  local name, k = e[1], kind(e)
  if e.list then
    if type(v) == "number" then v = exact(v) end
    if type(v) ~= "string" then refuse(script, name, v, "must be " .. allowed(e)) end
    local items, bad = M.split(v, e.list == "number")
    if not items then refuse(script, name, v, ("'%s' is not a number; must be %s"):format(bad, allowed(e))) end
    local item = {}   -- the bounds of one item, without the list's wording
    for key, value in pairs(e) do if key ~= "list" then item[key] = value end end
    for _, x in ipairs(items) do
      local why
      if e.list == "number" or e.oneof then why = out_of_range(item, x) end
      if why then refuse(script, name, v, ("item %s: %s"):format(show(x), why)) end
    end
    return v
  end
  if k == "number" or k == "integer" then
    if type(v) ~= "number" then
      local a = allowed_with_unit(e)
      refuse(script, name, v, k == "integer" and ("must be " .. a) or ("must be a number" .. (a ~= "" and (", " .. a) or "")))
    end
    if k == "integer" then
      local i = math.tointeger(v)
      if i == nil then refuse(script, name, v, "must be " .. allowed_with_unit(e)) end
      v = i
    end
    local why = out_of_range(e, v)
    if why then refuse(script, name, v, why) end
    return v
  end
  if k == "boolean" then
    if type(v) ~= "boolean" then refuse(script, name, v, "must be true or false") end
    return v
  end
  -- strings: a number given on the command line (seed-like names) is taken as its text
  if type(v) == "number" then v = exact(v) end
  if type(v) ~= "string" then refuse(script, name, v, "must be a string") end
  if e.oneof then
    local ok = false
    for _, o in ipairs(e.oneof) do if o == v then ok = true end end
    if not ok then refuse(script, name, v, "must be " .. allowed(e)) end
  end
  if e.file and v ~= "" then
    local f = io.open(v, "r")
    if not f then refuse(script, name, v, "no such readable file") end
    f:close()
  end
  if e.nonempty and v == "" then refuse(script, name, v, "must not be empty") end
  return v
end

-- The help text: one line per parameter with its default, unit and allowed values, then its doc.
function M.help(spec)
  local lines = {}
  local script = spec.script or "script"
  lines[#lines + 1] = script .. (spec.about and (": " .. spec.about) or "")
  lines[#lines + 1] = ("usage: asperity run %s [name=value ...]   (help=true or --help: this text)"):format(
    spec.path or script)
  lines[#lines + 1] = ""
  local width = 0
  for _, e in ipairs(spec) do width = math.max(width, #e[1] + #show(e[2]) + 1) end
  width = math.min(width, 34)
  for _, e in ipairs(spec) do
    local head = e[1] .. "=" .. show(e[2])
    local meta = {}
    if e.unit and e.unit ~= "" then meta[#meta + 1] = e.unit end
    local a = allowed(e)
    if a ~= "" then meta[#meta + 1] = a end
    lines[#lines + 1] = ("  %-" .. width .. "s  %s"):format(head, table.concat(meta, "; "))
    if e.doc then lines[#lines + 1] = (" "):rep(6) .. e.doc end
  end
  if spec.notes then
    lines[#lines + 1] = ""
    lines[#lines + 1] = spec.notes
  end
  return table.concat(lines, "\n") .. "\n"
end

-- Checks `given` (default: the global `params`) against the spec and returns the parameters, every
-- one present; nil after printing the help when help=true was given.
function M.parse(spec, given)
  given = given or params or {}
  local script = spec.script or "script"
  if given.help == true or given.help == "true" then
    io.write(M.help(spec))
    return nil
  end
  local by_name, names = {}, {}
  for _, e in ipairs(spec) do
    assert(type(e[1]) == "string", "params.parse: each entry starts with the parameter's name")
    by_name[e[1]] = e
    names[#names + 1] = e[1]
  end
  for k in pairs(given) do
    if k ~= "help" and by_name[k] == nil then
      local sorted = {table.unpack(names)}
      table.sort(sorted)
      raise(("%s: unknown parameter '%s' (this script takes: %s; help=true lists them)"):format(
        script, tostring(k), table.concat(sorted, ", ")))
    end
  end
  local P = {}
  for _, e in ipairs(spec) do
    local v = given[e[1]]
    if v == nil then P[e[1]] = e[2] else P[e[1]] = check_one(script, e, v) end
  end
  if spec.check then
    spec.check(P, function(name, message) refuse(script, name, P[name], message) end, given)
  end
  return P
end

-- Runs another script with these parameters, as a study runs joint.lua for each case, and returns
-- what the script returns (its summary). The caller's own `params` are put back afterwards, also
-- when the script fails (its error, a refusal included, goes on to the caller).
--   local s = require("params").run("joint.lua", {surface = "S5", stress = 21, out = "out/s5"})
function M.run(script, given)
  local path = script:find("/", 1, true) and script or (asperity.scripts_dir .. "/" .. script)
  local saved = params
  params = given or {}
  local result = table.pack(pcall(dofile, path))
  params = saved
  if not result[1] then error(result[2], 0) end
  return table.unpack(result, 2, result.n)
end

-- The older form: defaults only, each value must have the type of its default.
--   local P = require("params").defaults{n = 400, out = "out/demo"}
function M.defaults(defaults, given)
  given = given or params or {}
  if defaults.help == nil and (given.help == true or given.help == "true") then
    -- --help: the parameters and their defaults, then stop (the script has nothing to run).
    local names = {}
    for name in pairs(defaults) do names[#names + 1] = name end
    table.sort(names)
    local lines = {"parameters (key=value) and their defaults; the script's first lines say what they mean:"}
    for _, name in ipairs(names) do lines[#lines + 1] = ("  %s=%s"):format(name, tostring(defaults[name])) end
    io.write(table.concat(lines, "\n"), "\n")
    io.stdout:flush()
    os.exit(0)
  end
  local out = {}
  for k, v in pairs(defaults) do out[k] = v end
  for k, v in pairs(given) do
    local default = defaults[k]
    if default == nil then
      local names = {}
      for name in pairs(defaults) do names[#names + 1] = name end
      table.sort(names)
      error(("unknown parameter '%s' (this script takes: %s)"):format(k, table.concat(names, ", ")), 2)
    end
    if type(default) == "number" and type(v) ~= "number" then
      error(("parameter '%s' must be a number, got '%s'"):format(k, tostring(v)), 2)
    elseif type(default) == "boolean" and type(v) ~= "boolean" then
      error(("parameter '%s' must be true or false, got '%s'"):format(k, tostring(v)), 2)
    elseif type(default) == "string" then
      v = tostring(v)
    end
    out[k] = v
  end
  return out
end

return M
