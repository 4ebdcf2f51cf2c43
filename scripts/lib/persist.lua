-- Plain Lua values and series written as text and read back exactly, for the state a resumed run
-- needs (scripts/lib/joint/checkpoint.lua).
--
--   local persist = require("persist")
--   local text = persist.encode{step = 12, c0 = {0.1, 0.2, 0.3}, label = "closure"}
--   local t = persist.decode(text, "state.lua")          -- the same table, bit for bit
--   local saved = persist.series_state(series)           -- a plain table of its names and rows
--   local again = persist.series_from(saved)             -- a new asperity.series with those rows
--
-- Numbers keep their subtype: integers as decimals, floats as hexadecimal floats ("%a", exact;
-- inf and NaN as 1/0 and 0/0); asperity.vec values stay vectors. Tables may nest but not refer to
-- themselves; keys are strings, numbers or booleans, written sorted so that the same state gives
-- the same text. A function, userdata or other object is refused with the path to it, so a state
-- that cannot come back is found when written, not when read.
local M = {}

-- asperity's vectors (world:group_position() ...) come back as vectors.
local VEC = getmetatable(asperity.vec(0, 0, 0))

local function number_text(v)
  if math.type(v) == "integer" then
    return v == math.mininteger and "math_mininteger" or ("%d"):format(v)
  end
  if v ~= v then return "0/0" end
  if v == math.huge then return "1/0" end
  if v == -math.huge then return "-1/0" end
  return ("%a"):format(v)
end

local function key_order(a, b)
  local ta, tb = type(a), type(b)
  if ta ~= tb then return ta < tb end
  if ta == "boolean" then return (not a) and b end
  return a < b
end

local function encode(v, path, out, open)
  local t = type(v)
  if t == "number" then out[#out + 1] = number_text(v)
  elseif t == "string" then out[#out + 1] = ("%q"):format(v)
  elseif t == "boolean" or t == "nil" then out[#out + 1] = tostring(v)
  elseif t == "table" then
    if open[v] then error(("persist: %s refers to a table that contains it"):format(path), 0) end
    local meta = getmetatable(v)
    if meta and meta ~= VEC then error(("persist: %s is a table with a metatable (an object)"):format(path), 0) end
    open[v] = true
    out[#out + 1] = meta and "vec{" or "{"
    local n = #v
    for i = 1, n do
      encode(v[i], ("%s[%d]"):format(path, i), out, open)
      out[#out + 1] = ","
    end
    local keys = {}
    for k in pairs(v) do
      local kt = type(k)
      if not (math.type(k) == "integer" and k >= 1 and k <= n) then
        if kt ~= "string" and kt ~= "number" and kt ~= "boolean" then
          error(("persist: %s has a key of type %s"):format(path, kt), 0)
        end
        keys[#keys + 1] = k
      end
    end
    table.sort(keys, key_order)
    for _, k in ipairs(keys) do
      local sub = type(k) == "string" and path .. "." .. k or ("%s[%s]"):format(path, tostring(k))
      out[#out + 1] = "["
      encode(k, sub, out, open)
      out[#out + 1] = "]="
      encode(v[k], sub, out, open)
      out[#out + 1] = ","
    end
    out[#out + 1] = meta and "}" or "}\n"
    open[v] = nil
  else
    error(("persist: %s is a %s, which cannot be written"):format(path, t), 0)
  end
end

-- The text of `value` (a Lua chunk that returns it).
function M.encode(value)
  local out = {"return "}
  encode(value, "state", out, {})
  return table.concat(out)
end

-- The value of a text written by encode; `name` is said in errors.
function M.decode(text, name)
  local chunk, err = load(text, "=" .. name, "t", {math_mininteger = math.mininteger, vec = asperity.vec})
  if not chunk then error(("%s: not a saved state (%s)"):format(name, err), 0) end
  local ok, value = pcall(chunk)
  if not ok then error(("%s: not a saved state (%s)"):format(name, tostring(value)), 0) end
  return value
end

-- A series as a plain table: its column headers ("name [unit]") and its columns.
function M.series_state(series)
  local names, units = series:names()
  local headers, columns = {}, {}
  for k, name in ipairs(names) do
    headers[k] = units[k] ~= "" and ("%s [%s]"):format(name, units[k]) or name
    local col, values = series:column(k), {}
    for i = 1, #col do values[i] = col[i] end
    columns[k] = values
  end
  return {headers = headers, columns = columns}
end

-- A new series with the columns and rows of a series_state.
function M.series_from(state)
  local series = asperity.series(state.headers)
  local columns = state.columns
  local rows = #columns > 0 and #columns[1] or 0
  local row = {}
  for i = 1, rows do
    for k = 1, #columns do row[k] = columns[k][i] end
    series:record(table.unpack(row, 1, #columns))
  end
  return series
end

return M
