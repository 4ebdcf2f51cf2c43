-- Files and child processes for the scripts that run other scripts (study.lua, size_study.lua)
-- and for their tests.
--
--   local sh = require("shell")
--   sh.quote("it's")                 -- 'it'\''s' (plain words stay as they are)
--   sh.capture("pwd")                -- a command's output, trailing white space removed
--   sh.absolute("out/study")         -- relative to the working directory at start
--   sh.program()                     -- the asperity executable running this script
--   sh.read("f") / sh.exists("f")    -- the whole file or nil / whether it opens
--   sh.write_atomic("f", text)       -- to f.tmp, then renamed: no reader sees half a file
--   sh.run(cmd, "log")               -- exit status (-1: killed by a signal), output (to log)
local M = {}

function M.quote(s)
  s = tostring(s)
  if s:match("^[%w%%%+,%-%./:=@_]+$") then return s end
  return "'" .. s:gsub("'", "'\\''") .. "'"
end

function M.capture(cmd)
  local p = assert(io.popen(cmd, "r"))
  local text = p:read("a")
  p:close()
  return (text:gsub("%s+$", ""))
end

-- Absolute paths: a command must mean the same from any directory (a Slurm task's too).
local cwd
function M.absolute(path)
  if path:sub(1, 1) == "/" then return path end
  cwd = cwd or M.capture("pwd")
  return cwd .. "/" .. path
end

-- The program running this script: $PPID of a shell it starts.
function M.program() return M.capture("readlink -f /proc/$PPID/exe") end

function M.read(path)
  local f = io.open(path, "r")
  if not f then return nil end
  local t = f:read("a")
  f:close()
  return t
end

function M.exists(path)
  local f = io.open(path, "r")
  if f then f:close() return true end
  return false
end

function M.write_atomic(path, text)
  local tmp = path .. ".tmp"
  local f = assert(io.open(tmp, "w"))
  f:write(text)
  f:close()
  assert(os.rename(tmp, path))
end

-- A command with its output and errors to `log`: its exit status (-1 if a signal ended it) and
-- the output.
function M.run(cmd, log)
  local _, how, status = os.execute(("%s > %s 2>&1"):format(cmd, M.quote(log)))
  return how == "exit" and status or -1, M.read(log) or ""
end

return M
