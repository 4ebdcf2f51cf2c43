-- The figures of a joint test, drawn by gnuplot for a reader who knows rock mechanics: axis labels
-- in words with units, the peak and the residual marked, the reference study's values where it
-- has them, keys beside the plot (never over the data) and none for a single curve.
--
--   local jf = require("joint_figures")
--   jf.shear{file = "shear_stress.png", title = "...", u = u, tau = tau, dilatancy = dil,
--            peak = {at = 1.2, value = 17.9}, residual = {value = 12.1, from = 4.5, to = 5},
--            reference = {peak = 18.05, residual = 12.48, label = "thesis Table 4-1"}}
--   jf.cnl{...}  jf.closure{...}  jf.curves{...}  jf.contact_map{...}
local M = {}

local function quote(s) return '"' .. tostring(s):gsub('\\', '\\\\'):gsub('"', '\\"') .. '"' end

-- Columns of equal length into a temporary data file; returns its name.
local function data_file(columns)
  local name = os.tmpname()
  local f = assert(io.open(name, "w"))
  for i = 1, #columns[1] do
    local row = {}
    for c = 1, #columns do
      local v = columns[c][i]
      row[c] = (v == nil or v ~= v) and "NaN" or ("%.10g"):format(v)
    end
    f:write(table.concat(row, " "), "\n")
  end
  f:close()
  return name
end

local function gnuplot(script, temporaries)
  local name = os.tmpname()
  local f = assert(io.open(name, "w"))
  f:write(script)
  f:close()
  local ok = os.execute("gnuplot " .. name .. " 2>&1")
  os.remove(name)
  for _, t in ipairs(temporaries or {}) do os.remove(t) end
  if not ok then error("joint_figures: gnuplot failed", 3) end
end

local HEAD = "set terminal pngcairo noenhanced size %d,%d font \",11\"\nset output %s\nset grid\n"
-- Panels share the same left and right edges, so stacked x axes line up; the key sits right.
local function panel(top, bottom)
  return ("set lmargin at screen 0.08\nset rmargin at screen 0.64\nset tmargin at screen %.3f\n" ..
          "set bmargin at screen %.3f\nset key at screen 0.66, screen %.3f left top Left reverse\n"):format(
    top, bottom, top)
end
local BLUE, RED, ORANGE, GREEN, GREY = "#1f4e9c", "#c02020", "#e08000", "#208040", "#707070"

-- Shear stress and dilatancy against shear displacement, stacked, with the peak and the residual.
function M.shear(o)
  local d = data_file{o.u, o.tau, o.dilatancy}
  local lines = {HEAD:format(1250, 900, quote(o.file)), ("set multiplot title %s\n"):format(quote(o.title or ""))}
  local peak, res, ref = o.peak, o.residual, o.reference
  lines[#lines + 1] = ("set xrange [0:%.10g]\n"):format(o.u[#o.u])
  if peak then
    lines[#lines + 1] = ("set arrow 1 from %.10g, graph 0 to %.10g, graph 1 nohead dt 2 lw 1.5 lc rgb %s\n"):format(
      peak.at, peak.at, quote(RED))
  end
  -- upper panel: shear stress
  lines[#lines + 1] = panel(0.93, 0.52) .. "set format x \"\"\nunset xlabel\n" ..
                      "set ylabel \"shear stress (MPa, scaled to rock)\"\n"
  local items = {("%s using 1:2 with lines lw 2 lc rgb %s title \"shear stress\""):format(quote(d), quote(BLUE))}
  if peak then
    items[#items + 1] = ("'+' using (%.10g):(%.10g) every ::0::0 with points pt 7 ps 1.8 lc rgb %s title %s"):format(
      peak.at, peak.value, quote(RED), quote(("peak %.2f MPa at %.2f mm"):format(peak.value, peak.at)))
  end
  if res then
    items[#items + 1] = ("'+' using ($0 == 0 ? %.10g : %.10g):(%.10g) every ::0::1 with lines lw 4 lc rgb %s title %s"):format(
      res.from, res.to, res.value, quote(ORANGE),
      quote(("residual %.2f MPa (mean, last %.3g mm)"):format(res.value, res.to - res.from)))
  end
  if ref then
    items[#items + 1] = ("%.10g with lines dt 3 lw 2 lc rgb %s title %s"):format(ref.peak, quote(RED),
      quote(("%s: peak %.2f MPa"):format(ref.label, ref.peak)))
    items[#items + 1] = ("%.10g with lines dt 3 lw 2 lc rgb %s title %s"):format(ref.residual, quote(ORANGE),
      quote(("%s: residual %.2f MPa"):format(ref.label, ref.residual)))
  end
  lines[#lines + 1] = "set samples 2\nplot " .. table.concat(items, ", \\\n  ") .. "\n"
  -- lower panel: dilatancy
  lines[#lines + 1] = panel(0.49, 0.08) .. "set format x \"%g\"\nset xlabel \"shear displacement (mm)\"\n" ..
                      "set ylabel \"dilatancy (mm)\"\n"
  lines[#lines + 1] = ("plot %s using 1:3 with lines lw 2 lc rgb %s title \"dilatancy\"%s\n"):format(
    quote(d), quote(GREEN), peak and (", NaN with lines dt 2 lw 1.5 lc rgb " .. quote(RED) .. " title \"at the peak\"") or "")
  lines[#lines + 1] = "unset multiplot\nunset output\n"
  gnuplot(table.concat(lines), {d})
end

-- The constant-normal-load check: the normal stress held on the joint and the mobilised
-- friction tau / sigma_n, against shear displacement. target: the normal stress asked for, or
-- target_values (one per record, with target_label) when it follows the dilatancy.
function M.cnl(o)
  local ratio = {}
  for i = 1, #o.u do
    local sn = o.sn_mean[i]
    ratio[i] = (sn and sn > 0) and o.tau[i] / sn or 0 / 0
  end
  -- the stress the control asks for: constant, or (constant normal stiffness) one per record
  local target = o.target_values or {}
  if not o.target_values then for i = 1, #o.u do target[i] = o.target end end
  local d = data_file{o.u, o.sn, o.sn_mean, ratio, target}
  local lines = {HEAD:format(1250, 900, quote(o.file)), ("set multiplot title %s\n"):format(quote(o.title or "")),
                 ("set xrange [0:%.10g]\n"):format(o.u[#o.u])}
  lines[#lines + 1] = panel(0.93, 0.52) .. "set format x \"\"\nunset xlabel\n" ..
                      "set ylabel \"normal stress (MPa, scaled to rock)\"\n"
  lines[#lines + 1] = ("plot %s using 1:2 with lines lw 1 lc rgb %s title \"at the record\", \\\n" ..
                       "  %s using 1:3 with lines lw 2 lc rgb %s title \"mean over the record interval\", \\\n" ..
                       "  %s using 1:5 with lines dt 2 lw 2 lc rgb %s title %s\n"):format(
    quote(d), quote(GREY), quote(d), quote(BLUE), quote(d), quote(RED),
    quote(o.target_values and o.target_label or ("target %g MPa"):format(o.target)))
  lines[#lines + 1] = panel(0.49, 0.08) .. "set format x \"%g\"\nset xlabel \"shear displacement (mm)\"\n" ..
                      "set ylabel \"shear / normal stress, tau / sigma_n\"\n"
  local items = {("%s using 1:4 with lines lw 2 lc rgb %s title \"tau / sigma_n\""):format(quote(d), quote(BLUE))}
  if o.reference then
    local r = o.reference
    items[#items + 1] = ("%.10g with lines dt 3 lw 2 lc rgb %s title %s"):format(r.peak, quote(RED),
      quote(("%s: peak %.2f"):format(r.label, r.peak)))
    items[#items + 1] = ("%.10g with lines dt 3 lw 2 lc rgb %s title %s"):format(r.residual, quote(ORANGE),
      quote(("%s: at 5 mm %.2f"):format(r.label, r.residual)))
  end
  lines[#lines + 1] = "plot " .. table.concat(items, ", \\\n  ") .. "\n"
  lines[#lines + 1] = "unset multiplot\nunset output\n"
  gnuplot(table.concat(lines), {d})
end

-- Normal stress against closure, with the target stress and the fitted normal stiffness.
function M.closure(o)
  local d = data_file{o.closure, o.sn}
  local lines = {HEAD:format(1250, 620, quote(o.file)), ("set title %s\n"):format(quote(o.title or "")),
                 panel(0.90, 0.12), "set xlabel \"closure (mm)\"\nset ylabel \"normal stress (MPa, scaled to rock)\"\n"}
  local items = {("%s using 1:2 with lines lw 2 lc rgb %s title \"normal stress\""):format(quote(d), quote(BLUE)),
                 ("%.10g with lines dt 2 lw 2 lc rgb %s title %s"):format(o.target, quote(RED),
                   quote(("target %g MPa"):format(o.target)))}
  if o.stiffness and o.stiffness == o.stiffness then
    items[#items + 1] = ("NaN with lines lc rgb \"white\" title %s"):format(
      quote(("normal stiffness %.3g MPa/mm"):format(o.stiffness)))
  end
  lines[#lines + 1] = "plot " .. table.concat(items, ", \\\n  ") .. "\nunset output\n"
  gnuplot(table.concat(lines), {d})
end

-- One panel of curves against shear displacement: {x = {...}, curves = {{values, title}, ...}}.
-- A single curve has no key; from_zero: the y axis starts at 0.
function M.curves(o)
  local cols = {o.x}
  for _, c in ipairs(o.curves) do cols[#cols + 1] = c[1] end
  local d = data_file(cols)
  local single = #o.curves == 1
  local lines = {HEAD:format(1250, 620, quote(o.file)), ("set title %s\n"):format(quote(o.title or "")),
                 single and "set lmargin at screen 0.09\nset rmargin at screen 0.95\nunset key\n" or panel(0.90, 0.12),
                 ("set xrange [0:%.10g]\n"):format(o.x[#o.x]),
                 ("set xlabel %s\nset ylabel %s\n"):format(quote(o.xlabel or "shear displacement (mm)"), quote(o.ylabel))}
  if o.from_zero then   -- counts: from 0 (and a unit range when all are 0)
    local top = 0
    for _, c in ipairs(o.curves) do
      local values = c[1]   -- a table or an asperity Array (which has no end marker for ipairs)
      for i = 1, #values do
        local v = values[i]
        if v == v then top = math.max(top, v) end
      end
    end
    lines[#lines + 1] = top > 0 and "set yrange [0:*]\n" or "set yrange [0:1]\n"
  end
  if o.mark then
    lines[#lines + 1] = ("set arrow 1 from %.10g, graph 0 to %.10g, graph 1 nohead dt 2 lw 1.5 lc rgb %s\n"):format(
      o.mark.at, o.mark.at, quote(RED))
    lines[#lines + 1] = ("set label 1 %s at %.10g, graph 1.02 center tc rgb %s\n"):format(
      quote(o.mark.label), o.mark.at, quote(RED))
  end
  local colors = {BLUE, RED, GREEN, ORANGE, GREY, "#8040a0", "#00a0a0"}
  local items = {}
  for k, c in ipairs(o.curves) do
    items[#items + 1] = ("%s using 1:%d with lines lw 2 lc rgb %s title %s"):format(quote(d), k + 1,
      quote(colors[(k - 1) % #colors + 1]), quote(c[2] or ""))
  end
  lines[#lines + 1] = "plot " .. table.concat(items, ", \\\n  ") .. "\nunset output\n"
  gnuplot(table.concat(lines), {d})
end

-- Contact points between the halves (and optionally broken bonds) over the elevation map.
-- heights: row-major nx x ny, m; spacing h, m; points: {{x, y}, ...} m.
function M.contact_map(o)
  local name = os.tmpname()
  local f = assert(io.open(name, "w"))
  for j = 1, o.ny do
    for i = 1, o.nx do
      f:write(("%.6g %.6g %.6g\n"):format((i - 1) * o.h * 1e3, (j - 1) * o.h * 1e3, o.heights[(j - 1) * o.nx + i] * 1e3))
    end
    f:write("\n")
  end
  f:write("\n\n")
  for _, p in ipairs(o.points or {}) do f:write(("%.6g %.6g 0\n"):format(p[1] * 1e3, p[2] * 1e3)) end
  f:write("NaN NaN NaN\n\n\n")
  for _, p in ipairs(o.broken or {}) do f:write(("%.6g %.6g 0\n"):format(p[1] * 1e3, p[2] * 1e3)) end
  f:write("NaN NaN NaN\n")
  f:close()
  local extent_x, extent_y = (o.nx - 1) * o.h * 1e3, (o.ny - 1) * o.h * 1e3
  local script = (HEAD:format(1000, 820, quote(o.file))) ..
    ("set title %s\nset xlabel \"x (mm)\"\nset ylabel \"y (mm)\"\nset cblabel \"elevation of the surface (mm)\"\n" ..
     "set size ratio -1\nset view map\nset xrange [0:%.6g]\nset yrange [0:%.6g]\nunset grid\n" ..
     "set key outside below horizontal\nset palette defined (0 \"#f0f0f0\", 1 \"#909090\", 2 \"#303030\")\n" ..
     "plot %s index 0 using 1:2:3 with image notitle, \\\n" ..
     "  %s index 1 using 1:2 with points pt 7 ps 1.1 lc rgb %s title %s, \\\n" ..
     "  %s index 2 using 1:2 with points pt 6 ps 0.8 lc rgb %s title %s\nunset output\n"):format(
      quote(o.title or ""), extent_x, extent_y, quote(name), quote(name), quote(RED),
      quote(("contacts between the halves (%d)"):format(#(o.points or {}))), quote(name), quote(BLUE),
      quote(("bonds broken so far (%d)"):format(#(o.broken or {}))))
  gnuplot(script, {name})
end

return M
