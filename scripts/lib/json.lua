-- JSON text to Lua values (the engine writes JSON with asperity.write_json; this reads it back):
-- objects become tables with string keys, arrays tables with integer keys from 1, null becomes
-- `json.null` (a unique value, so an object's null field is not confused with an absent one).
--
--   local json = require("json")
--   local summary = json.read("out/joint/summary.json")
--   local v = json.decode('{"a": [1, 2.5e3, null, true]}')
local M = {}

M.null = setmetatable({}, {__tostring = function() return "null" end})

local escapes = {['"'] = '"', ["\\"] = "\\", ["/"] = "/", b = "\b", f = "\f", n = "\n", r = "\r", t = "\t"}

function M.decode(text, source)
  source = source or "JSON text"
  local pos = 1
  local function fail(what)
    local line = select(2, text:sub(1, pos):gsub("\n", "")) + 1
    error(("%s, line %d: %s"):format(source, line, what), 0)
  end
  local function skip() pos = text:find("[^ \t\r\n]", pos) or #text + 1 end
  local value
  local function str()
    local parts = {}
    pos = pos + 1
    while true do
      local s, e = text:find('["\\]', pos)
      if not s then fail("unterminated string") end
      parts[#parts + 1] = text:sub(pos, s - 1)
      if text:sub(s, s) == '"' then pos = e + 1; break end
      local c = text:sub(s + 1, s + 1)
      if c == "u" then
        local hex = text:sub(s + 2, s + 5)
        if not hex:match("^%x%x%x%x$") then fail("bad \\u escape") end
        local code = tonumber(hex, 16)
        -- A UTF-16 surrogate pair encodes one code point above U+FFFF.
        if code >= 0xD800 and code <= 0xDBFF and text:sub(s + 6, s + 7) == "\\u" then
          local low = tonumber(text:sub(s + 8, s + 11), 16)
          if low and low >= 0xDC00 and low <= 0xDFFF then
            code = 0x10000 + (code - 0xD800) * 0x400 + (low - 0xDC00)
            s = s + 6
          end
        end
        parts[#parts + 1] = utf8.char(code)
        pos = s + 6
      else
        if not escapes[c] then fail("bad escape \\" .. c) end
        parts[#parts + 1] = escapes[c]
        pos = s + 2
      end
    end
    return table.concat(parts)
  end
  function value()
    skip()
    local c = text:sub(pos, pos)
    if c == "{" then
      local t = {}
      pos = pos + 1
      skip()
      if text:sub(pos, pos) == "}" then pos = pos + 1; return t end
      while true do
        skip()
        if text:sub(pos, pos) ~= '"' then fail("expected a string key") end
        local k = str()
        skip()
        if text:sub(pos, pos) ~= ":" then fail("expected ':'") end
        pos = pos + 1
        t[k] = value()
        skip()
        local d = text:sub(pos, pos)
        pos = pos + 1
        if d == "}" then return t end
        if d ~= "," then fail("expected ',' or '}'") end
      end
    elseif c == "[" then
      local t = {}
      pos = pos + 1
      skip()
      if text:sub(pos, pos) == "]" then pos = pos + 1; return t end
      while true do
        t[#t + 1] = value()
        skip()
        local d = text:sub(pos, pos)
        pos = pos + 1
        if d == "]" then return t end
        if d ~= "," then fail("expected ',' or ']'") end
      end
    elseif c == '"' then
      return str()
    elseif text:find("^true", pos) then pos = pos + 4; return true
    elseif text:find("^false", pos) then pos = pos + 5; return false
    elseif text:find("^null", pos) then pos = pos + 4; return M.null
    else
      local num = text:match("^-?%d+%.?%d*[eE]?[-+]?%d*", pos)
      if not num or num == "" or num == "-" then fail("unexpected '" .. c .. "'") end
      pos = pos + #num
      return tonumber(num) or fail("bad number '" .. num .. "'")
    end
  end
  local v = value()
  skip()
  if pos <= #text then fail("trailing text") end
  return v
end

function M.read(path)
  local f, err = io.open(path, "r")
  if not f then error(("cannot read %s: %s"):format(path, err), 2) end
  local text = f:read("a")
  f:close()
  return M.decode(text, path)
end

return M
