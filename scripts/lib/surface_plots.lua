-- PNG plots of a height map and its roughness analysis (gnuplot through asperity.plot and
-- map:plot), used by scripts/surface.lua and reusable by any script holding a HeightMap.
--
--   local plots = require("surface_plots")
--   local r = map:analyze()
--   plots.all(map, r, "out/s5", "S5")   -- elevation, structure, psd, abbott .png in out/s5
--
-- Axes in mm (lags, heights) and cycles/m (frequencies): a 10 cm surface has lags of 0.3..50 mm
-- and heights of a few tenths of a mm, which read better than powers of ten of metres.
local M = {}

-- An Array of f(i) for i = 1..n.
local function column(n, f)
  local a = asperity.array(n)
  for i = 1, n do a[i] = f(i) end
  return a
end

-- The fitted power law y = exp(intercept) x^slope (SI), inside the fit window only (NaN
-- elsewhere: gnuplot leaves a gap), times `scale`.
local function fit_line(x, fit, scale)
  return column(#x, function(i)
    local v = x[i]
    if fit.points == 0 or v < fit.x_min * (1 - 1e-9) or v > fit.x_max * (1 + 1e-9) then return 0 / 0 end
    return math.exp(fit.intercept) * v ^ fit.slope * scale
  end)
end

function M.elevation(map, file, title)
  return map:plot(file, {title = title})
end

-- Radially averaged structure function and variogram, the 2H fit, the plateau 2 s2.
function M.structure(r, file, title)
  local s = r.structure_radial
  local n = #s.lag
  local s2 = r.amplitude.variance
  return asperity.plot{
    file = file, logx = true, logy = true,
    title = ("%s: structure function, H = %.3f (fit over %.2f..%.2f mm)")
      :format(title, r.hurst_structure.hurst, r.hurst_structure.x_min * 1e3, r.hurst_structure.x_max * 1e3),
    x = column(n, function(i) return s.lag[i] * 1e3 end), xlabel = "lag (mm)",
    ylabel = "mean squared height difference (mm^2)",
    y = {column(n, function(i) return s.value[i] * 1e6 end),
         column(n, function(i) return 0.5 * s.value[i] * 1e6 end),
         fit_line(s.lag, r.hurst_structure, 1e6),
         column(n, function() return 2 * s2 * 1e6 end)},
    labels = {"structure function S", "variogram S/2",
              ("fit S ~ lag^%.3f"):format(r.hurst_structure.slope), "plateau 2 s2"},
  }
end

-- Ring-averaged PSD and the fitted slope -(2 + 2H).
function M.psd(r, file, title)
  local p = r.psd_radial
  local n = #p.frequency
  return asperity.plot{
    file = file, logx = true, logy = true,
    title = ("%s: radially averaged PSD, H = %.3f, roll-off length %.2f mm")
      :format(title, r.hurst_psd.hurst, r.rolloff_length * 1e3),
    x = p.frequency, xlabel = "spatial frequency (cycles/m)", ylabel = "power spectral density (m^4)",
    y = {p.psd, fit_line(p.frequency, r.hurst_psd, 1)},
    labels = {"PSD", ("fit slope %.3f = -(2 + 2H)"):format(r.hurst_psd.slope)},
  }
end

-- Abbott-Firestone curve: height against the share of the surface at or above it.
function M.abbott(r, file, title)
  local a = r.abbott
  local n = #a.height
  return asperity.plot{
    file = file, title = title .. ": Abbott-Firestone curve",
    x = column(n, function(i) return a.bearing_fraction[i] * 100 end),
    xlabel = "bearing area: share of the surface at or above z (%)", ylabel = "height z (mm)",
    y = column(n, function(i) return a.height[i] * 1e3 end), labels = {"height z"},
  }
end

-- All four into `dir`.
function M.all(map, r, dir, title)
  M.elevation(map, dir .. "/elevation.png", title .. ": elevation")
  M.structure(r, dir .. "/structure.png", title)
  M.psd(r, dir .. "/psd.png", title)
  M.abbott(r, dir .. "/abbott.png", title)
end

-- Noise study rows (asperity.surface.noise_study) to dir/noise.{h5,csv} and, if plot, noise.png.
function M.noise(study, dir, plot)
  local s = asperity.series{"level [%]", "hurst_psd", "hurst_structure", "variance [m^2]",
                            "variance_ratio", "psd_fit_r2", "structure_fit_r2"}
  for _, row in ipairs(study) do
    s:record{level = row.level * 100, hurst_psd = row.hurst_psd, hurst_structure = row.hurst_structure,
             variance = row.variance, variance_ratio = row.variance / study[1].variance,
             psd_fit_r2 = row.psd_fit_r2, structure_fit_r2 = row.structure_fit_r2}
  end
  s:write(dir .. "/noise")
  if plot then
    asperity.plot{file = dir .. "/noise.png", x = s:column("level"),
                  y = {s:column("hurst_psd"), s:column("hurst_structure"), s:column("variance_ratio")},
                  labels = {"H from the PSD", "H from the structure function", "s2 / s2 without noise"},
                  xlabel = "white noise added (% of the rms height)", ylabel = "H (-); variance ratio (-)",
                  title = "measured H and variance with white noise added", points = true}
  end
end

return M
