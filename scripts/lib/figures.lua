-- PNG figures drawn by gnuplot that the plain series plots do not cover: histograms and maps of
-- points (e.g. broken bonds).
--
--   local fig = require("figures")
--   fig.histogram{file = "h.png", values = {...}, bins = 40, xlabel = "bond normal stress (Pa)",
--                 ylabel = "bonds", csv = "h.csv", column = "sigma [Pa]"}   -- column: the CSV's header
--   fig.map{file = "m.png", points = {{x, y, z, group}, ...}, groups = {"tension", "shear"},
--           extent = {min = {..}, max = {..}}, title = "..."}
--   fig.curves{file = "c.png", xlabel = "u [mm]", ylabel = "tau [MPa]", logx = false, logy = false,
--              series = {{title = "S1", x = {...}, y = {...}, style = "lines", color = "#d02020",
--                         dash = 2, point = 7}, ...}}
local M = {}

local function gnuplot(script)
  local name = os.tmpname()
  local f = assert(io.open(name, "w"))
  f:write(script)
  f:close()
  local ok = os.execute("gnuplot " .. name .. " 2>&1")
  os.remove(name)
  if not ok then error("figures: gnuplot failed", 3) end
end

local function quote(s) return '"' .. tostring(s):gsub('"', '\\"') .. '"' end

-- Counts of `values` in `bins` equal bins between min and max (default: the data's range). Writes
-- the table as CSV if `csv` is given; returns centres and counts.
function M.histogram(o)
  local v = o.values
  local lo, hi = o.min, o.max
  if not lo or not hi then
    lo, hi = math.huge, -math.huge
    for i = 1, #v do lo, hi = math.min(lo, v[i]), math.max(hi, v[i]) end
    if hi <= lo then hi = lo + 1 end
  end
  local bins = o.bins or 40
  local width = (hi - lo) / bins
  local counts = {}
  for k = 1, bins do counts[k] = 0 end
  for i = 1, #v do
    local k = math.min(bins, math.max(1, math.floor((v[i] - lo) / width) + 1))
    counts[k] = counts[k] + 1
  end
  local centres = {}
  for k = 1, bins do centres[k] = lo + (k - 0.5) * width end
  local data = os.tmpname()
  local f = assert(io.open(data, "w"))
  for k = 1, bins do f:write(("%.10g %d\n"):format(centres[k], counts[k])) end
  f:close()
  if o.csv then
    local c = assert(io.open(o.csv, "w"))
    c:write(("%s,count\n"):format(o.column or o.xlabel or "value"))
    for k = 1, bins do c:write(("%.10g,%d\n"):format(centres[k], counts[k])) end
    c:close()
  end
  local marks = ""
  for i, m in ipairs(o.marks or {}) do
    marks = marks .. ("set arrow %d from %.10g, graph 0 to %.10g, graph 1 nohead lw 2 dt 2 lc rgb %s\n"):format(
      i, m.x, m.x, quote(m.color or "red"))
    if m.label then
      marks = marks .. ("set label %d %s at %.10g, graph 0.95 left offset 0.5,0 tc rgb %s\n"):format(
        i, quote(m.label), m.x, quote(m.color or "red"))
    end
  end
  -- The x range holds the marks too: a mark beyond the data (a strength far above every stress)
  -- would otherwise not be drawn.
  local xlo, xhi = lo, hi
  for _, m in ipairs(o.marks or {}) do xlo, xhi = math.min(xlo, m.x), math.max(xhi, m.x) end
  local pad = 0.05 * (xhi - xlo)
  marks = marks .. ("set xrange [%.10g:%.10g]\n"):format(xlo - pad, xhi + pad)
  gnuplot(("set terminal pngcairo noenhanced size 900,600\nset output %s\nset xlabel %s\nset ylabel %s\n" ..
           "set title %s\nset grid\nset style fill solid 0.6\nset boxwidth %.10g\n%s" ..
           "plot %s using 1:2 with boxes lc rgb \"#3060c0\" notitle\nunset output\n"):format(
    quote(o.file), quote(o.xlabel or ""), quote(o.ylabel or "count"), quote(o.title or ""), width * 0.9,
    marks, quote(data)))
  os.remove(data)
  return centres, counts
end

-- Points {x, y, z, group} projected on the x-z and y-z planes, side by side, one colour per group
-- (groups: the names, in order; group values index them).
function M.map(o)
  local colors = o.colors or {"#d02020", "#2050d0", "#20a040", "#a0a0a0"}
  local data = os.tmpname()
  local f = assert(io.open(data, "w"))
  for g = 1, #o.groups do
    local n = 0
    for _, p in ipairs(o.points) do
      if p[4] == g then
        f:write(("%.10g %.10g %.10g\n"):format(p[1] * 1e3, p[2] * 1e3, p[3] * 1e3))
        n = n + 1
      end
    end
    if n == 0 then f:write("NaN NaN NaN\n") end
    f:write("\n\n")
  end
  f:close()
  local e = o.extent
  local function range(k)
    return ("[%.6g:%.6g]"):format(e.min[k] * 1e3, e.max[k] * 1e3)
  end
  local lines = {("set terminal pngcairo noenhanced size 1200,620\nset output %s\n"):format(quote(o.file)),
                 ("set multiplot layout 1,2 title %s\n"):format(quote(o.title or "")),
                 "set size ratio -1\nset grid\nset key outside bottom center horizontal\n"}
  for _, view in ipairs({{1, "x [mm]"}, {2, "y [mm]"}}) do
    local col, label = view[1], view[2]
    lines[#lines + 1] = ("set xlabel %s\nset ylabel \"z [mm]\"\nset xrange %s\nset yrange %s\n"):format(
      quote(label), range(col), range(3))
    local plots = {}
    for g, name in ipairs(o.groups) do
      local count = 0
      for _, p in ipairs(o.points) do if p[4] == g then count = count + 1 end end
      plots[#plots + 1] = ("%s index %d using %d:3 with points pt 7 ps 0.6 lc rgb %s title %s"):format(
        quote(data), g - 1, col, quote(colors[(g - 1) % #colors + 1]), quote(("%s (%d)"):format(name, count)))
    end
    lines[#lines + 1] = "plot " .. table.concat(plots, ", ") .. "\n"
  end
  lines[#lines + 1] = "unset multiplot\nunset output\n"
  gnuplot(table.concat(lines))
  os.remove(data)
end

-- Several x-y series in one figure: lines, points or both (style "lines", "points",
-- "linespoints", "impulses"); a series with no finite point is left out (a figure with none is not drawn).
-- Returns true if the figure was drawn.
function M.curves(o)
  local palette = {"#d02020", "#2050d0", "#20a040", "#e08000", "#8040c0", "#00a0a0", "#a0a000", "#606060"}
  local data = os.tmpname()
  local f = assert(io.open(data, "w"))
  local plots, index = {}, 0
  local xmin, xmax = math.huge, -math.huge
  for k, s in ipairs(o.series) do
    local n = 0
    for i = 1, math.min(#s.x, #s.y) do
      local x, y = s.x[i], s.y[i]
      local ok = x == x and y == y and math.abs(x) < math.huge and math.abs(y) < math.huge and
                 (not o.logx or x > 0) and (not o.logy or y > 0)
      if ok then
        f:write(("%.10g %.10g\n"):format(x, y))
        n, xmin, xmax = n + 1, math.min(xmin, x), math.max(xmax, x)
      end
    end
    if n > 0 then
      f:write("\n\n")
      local style = s.style or "lines"
      local spec = ("%s index %d using 1:2 with %s lw %g lc rgb %s"):format(quote(data), index, style,
        s.width or 2, quote(s.color or palette[(k - 1) % #palette + 1]))
      if s.dash then spec = spec .. " dt " .. s.dash end
      if style == "points" or style == "linespoints" then spec = spec .. (" pt %d ps %g"):format(s.point or 7, s.size or 1) end
      plots[#plots + 1] = spec .. " title " .. quote(s.title or "")
      index = index + 1
    end
  end
  f:close()
  if #plots == 0 then os.remove(data) return false end
  -- Every point at one x: gnuplot would warn of an empty range; give it one around that x.
  local xrange = o.xrange
  if not xrange and xmax == xmin then
    local pad = xmin ~= 0 and 0.1 * math.abs(xmin) or 1
    xrange = o.logx and ("%.10g:%.10g"):format(xmin / 2, xmin * 2) or ("%.10g:%.10g"):format(xmin - pad, xmin + pad)
  end
  gnuplot(("set terminal pngcairo noenhanced size %d,%d\nset output %s\nset xlabel %s\nset ylabel %s\n" ..
           "set title %s\nset grid\nset key %s\n%s%s%s%splot %s\nunset output\n"):format(
    o.width or 900, o.height or 600, quote(o.file), quote(o.xlabel or ""), quote(o.ylabel or ""),
    quote(o.title or ""), o.key or "outside right top", o.logx and "set logscale x\n" or "",
    o.logy and "set logscale y\n" or "", xrange and ("set xrange [%s]\n"):format(xrange) or "",
    o.extra or "", table.concat(plots, ", ")))
  os.remove(data)
  return true
end

return M
