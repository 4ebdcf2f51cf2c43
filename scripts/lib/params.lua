-- Script parameters with defaults: the key=value pairs of `asperity run SCRIPT key=value ...`
-- arrive in the global table `params`; this merges them over the script's defaults, checks that
-- each has the type of its default (a number stays a number), and rejects names the script
-- does not know, so a typo on the command line is an error, not a silently ignored setting.
--
--   local P = require("params").defaults{n = 400, out = "out/demo"}
--   print(P.n)
local M = {}

function M.defaults(defaults, given)
  given = given or params or {}
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
