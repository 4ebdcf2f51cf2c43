-- Recording during a run.
--
--   local record = require("record")
--   local energy = record.energy_series()              -- time, kinetic, strain, ... [J]
--   w:run{steps = 1e5, every = 100, callback = record.every(energy, record.energy_row)}
--   energy:write(out .. "/energy")                     -- energy.h5 + energy.csv
--
-- record.every(series, row_fn) returns a callback for world:run that appends row_fn(world)
-- (a table name = value) to the series each time it is called.
local M = {}

M.energy_columns = {"step", "time [s]", "kinetic [J]", "strain [J]", "friction [J]",
                    "damping [J]", "boundary_work [J]", "gravity_work [J]",
                    "unbalanced_ratio", "contacts"}

function M.energy_series(attributes)
  local cols = {}
  for i, c in ipairs(M.energy_columns) do cols[i] = c end
  cols.attributes = attributes
  return asperity.series(cols)
end

function M.energy_row(w)
  local e = w:energies()
  return {step = w:step(), time = w:time(), kinetic = e.kinetic, strain = e.strain,
          friction = e.friction, damping = e.damping, boundary_work = e.boundary_work,
          gravity_work = e.gravity_work, unbalanced_ratio = w:unbalanced_force_ratio(),
          contacts = w:contact_count()}
end

function M.every(series, row_fn)
  return function(w) series:record(row_fn(w)) end
end

return M
