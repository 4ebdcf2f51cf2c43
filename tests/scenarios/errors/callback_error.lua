local w = asperity.world()
w:add_particle({0, 0, 0}, 0.01)
w:run{steps = 100, every = 10, callback = function(w)
  if w:step() == 50 then error("boom in callback") end
end}
