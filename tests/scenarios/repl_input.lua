1 + 1
w = asperity.world{gravity = {0, 0, -9.81}}
w:add_particle({0, 0, 0.5}, 0.01)
function double(x)
  return 2 * x
end
double(21)
t = {1,
  2, name = "x"}
t
w:position(1)
help(w.cycle)
error("oops")
"still alive after " .. "an error"
