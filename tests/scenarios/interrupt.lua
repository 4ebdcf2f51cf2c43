-- A Ctrl-C (a real SIGINT, sent to this process by a background shell) reaches a pcall as an
-- interruption that asperity.is_interrupted recognises by its type; errors that merely say
-- "interrupted" are not taken for one.

-- Sends SIGINT to this process in a second, then runs f until it comes (30 s at most).
local function interrupt(f)
  assert(os.execute("(sleep 1; kill -INT $PPID) &"))  -- $PPID of the shell: this process
  local ok, err = pcall(f)
  assert(not ok, "no interruption within 30 s")
  return err
end

local w = asperity.world()
w:add_particle({0, 0, 0}, 0.1)

-- In the engine: world:cycle stops at the next step, the world intact. (The signal may land just
-- before the cycle starts, in Lua code: that is an interruption too, with the shorter message.)
local err = interrupt(function() w:cycle(1000000000000) end)
assert(asperity.is_interrupted(err), "not recognised: " .. tostring(err))
local text = tostring(err)
assert(text:find("interrupted at step %d+ %(the world is intact: continue with world:cycle or world:run%)$")
       or text:find(":%d+: interrupted$"), text)
assert("stopped: " .. err == "stopped: " .. text, "concatenation gives the message")
local step = w:step()
w:cycle(3)
assert(w:step() == step + 3, "the world goes on after the interruption")

-- In Lua code: the hook raises one at the next instruction.
err = interrupt(function()
  local t = asperity.wall_time()
  while asperity.wall_time() - t < 30 do end
end)
assert(asperity.is_interrupted(err), "not recognised: " .. tostring(err))
assert(tostring(err):find("interrupt.lua:%d+: interrupted$"), tostring(err))
-- Raised again, it stays one.
local ok, again = pcall(error, err)
assert(not ok and asperity.is_interrupted(again) and again == err)

-- Not interruptions, whatever they say.
for _, e in ipairs{"interrupted", "x.lua:3: interrupted at step 12 (the world is intact)",
                   setmetatable({message = "interrupted"}, {__tostring = function(e) return e.message end}),
                   {message = "interrupted"}, 42, false} do
  assert(not asperity.is_interrupted(e), "taken for an interruption: " .. tostring(e))
end
assert(not asperity.is_interrupted())
ok, err = pcall(error, "interrupted")
assert(not ok and not asperity.is_interrupted(err))
print("PASS")
