-- A self-affine rough surface: generate it, measure it, write it and plot it (spec surfaces.md).
--
--   build/asperity run scripts/surface.lua name=S5 out=/tmp/s5          # a reference surface
--   build/asperity run scripts/surface.lua H=0.6 Lc=0.02 variance=4e-7 seed=3 out=/tmp/s
--   build/asperity run scripts/surface.lua Hx=0.8 Hy=0.5 Lc=0.016 variance=5e-7 out=/tmp/aniso
--   build/asperity run scripts/surface.lua name=S1 noise=true out=/tmp/s1    # + noise study
--
-- Parameters (SI units): H, Lc (m), variance (m^2), n (grid points per side, odd), L (side, m),
-- seed, name (S1..S8, spec table 4; H/Lc/variance given with it override it), anisotropic Hx, Hy,
-- Lcx, Lcy, variance_x, variance_y. Without a name, parameters not given are those of S1.
-- 0 means "not given" for the numeric ones.
--
-- Writes into `out`:
--   surface.h5        the height map (dataset `height`, ny x nx, m; attributes spacing, parameters)
--   summary.json      requested parameters and measured statistics: hurst_psd, hurst_structure,
--                     variance, rms, ra, skewness, kurtosis (after removing the least-squares
--                     mean plane, spec section 2), variance_raw (as generated), correlation_length,
--                     rolloff_length, the fits and per-direction (polar) values
--   elevation.png     the heights as a heat map
--   structure.png     structure function S and variogram S/2 (log-log), the fit 2H, the plateau
--   psd.png           radially averaged PSD with the fitted slope -(2 + 2H)
--   abbott.png        Abbott-Firestone (bearing area) curve
--   with noise=true: noise.csv and noise.png (H and s2 against added white noise)
local names = {""}
for k = 1, 8 do names[#names + 1] = "S" .. k end
local P = require("params").parse{
  script = "surface.lua",
  path = "scripts/surface.lua",
  about = "a self-affine rough surface: generated, measured, written and plotted",
  {"name", "", oneof = names, doc = "a reference surface (spec table 4); H, Lc, variance given with it override it"},
  {"H", 0, min = 0, below = 1, doc = "Hurst exponent (0: not given)"},
  {"Lc", 0, unit = "m", min = 0, doc = "roll-off (correlation) length (0: not given)"},
  {"variance", 0, unit = "m^2", min = 0, doc = "height variance s2 (0: not given)"},
  {"Hx", 0, min = 0, below = 1, doc = "anisotropic: Hurst exponent along x (0: not given)"},
  {"Hy", 0, min = 0, below = 1, doc = "anisotropic: along y"},
  {"Lcx", 0, unit = "m", min = 0, doc = "anisotropic: roll-off length along x"},
  {"Lcy", 0, unit = "m", min = 0, doc = "anisotropic: along y"},
  {"variance_x", 0, unit = "m^2", min = 0, doc = "anisotropic: variance along x"},
  {"variance_y", 0, unit = "m^2", min = 0, doc = "anisotropic: along y"},
  {"n", 365, type = "integer", min = 3, max = 32767, doc = "grid points per side, odd"},
  {"L", 0.10, unit = "m", above = 0, doc = "side of the surface"},
  {"seed", 1, type = "integer", min = 0, doc = "of the random phases"},
  {"noise", false, doc = "also the noise study (H and s2 against added white noise)"},
  {"out", "out/surface", nonempty = true, doc = "output folder"},
  check = function(P, fail)
    if P.n % 2 == 0 then fail("n", "must be odd (the spectral method keeps only (0, 0) self-conjugate)") end
  end,
}
if not P then return end   -- help printed
local S = asperity.surface
local plots = require("surface_plots")

-- Generation table for asperity.surface.generate.
local gen = {n = P.n, side = P.L, seed = P.seed}
if P.name ~= "" then
  gen.name = P.name
else
  local s1 = S.reference("S1")
  if P.H == 0 and P.Hx == 0 and P.Hy == 0 then gen.H = s1.H end
  if P.Lc == 0 and P.Lcx == 0 and P.Lcy == 0 then gen.Lc = s1.Lc end
  if P.variance == 0 then gen.variance = s1.variance end
  -- one anisotropic value alone: the other direction keeps the isotropic default
  if (P.Hx ~= 0) ~= (P.Hy ~= 0) then gen.H = s1.H end
  if (P.Lcx ~= 0) ~= (P.Lcy ~= 0) then gen.Lc = s1.Lc end
end
for _, k in ipairs{"H", "Lc", "variance", "Hx", "Hy", "Lcx", "Lcy", "variance_x", "variance_y"} do
  if P[k] ~= 0 then gen[k] = P[k] end
end

local t0 = asperity.wall_time()
local map = S.generate(gen)
local requested = map:params()
asperity.mkdir(P.out)
map:save(P.out .. "/surface.h5")
local r = map:analyze()
local a = r.amplitude

local summary = {
  requested = requested,
  spacing = map:spacing(),
  hurst_psd = r.hurst_psd.hurst,
  hurst_structure = r.hurst_structure.hurst,
  variance = a.variance,
  variance_raw = map:amplitude().variance,  -- before the mean-plane removal: s2 exactly
  rms = a.rms,
  ra = a.ra,
  skewness = a.skewness,
  kurtosis = a.kurtosis,
  min = a.min,
  max = a.max,
  correlation_length = r.correlation_length,
  rolloff_length = r.rolloff_length,
  hurst_psd_fit = r.hurst_psd,
  hurst_structure_fit = r.hurst_structure,
  mean_plane = r.mean_plane,
  polar = r.polar,
  rules = {
    correlation_length = "smallest lag where the radially averaged S reaches (1 - 1/e) 2 s2",
    rolloff_length = "1 / (2 f_c), f_c the corner of a broken power law fitted to the radial PSD",
    hurst_psd = "slope of the ring-averaged 2-D PSD (Hann window) = -(2 + 2H)",
    hurst_structure = "slope of log S vs log lag = 2H, lags from one step to xi / 4",
  },
}

local plotted, why = pcall(plots.all, map, r, P.out, requested.name ~= "" and requested.name or "surface")

if P.noise then
  local study = S.noise_study(map, {seed = P.seed})
  summary.noise_study = study
  plots.noise(study, P.out, plotted)
end
summary.wall_seconds = asperity.wall_time() - t0
asperity.write_json(P.out .. "/summary.json", summary)

local function mm(x) return x * 1e3 end
print(("%s: n = %d, L = %.4g m, seed = %d"):format(requested.name ~= "" and requested.name or "surface",
      requested.n, requested.side, requested.seed))
print(("  H        requested %.3f   measured %.3f (PSD), %.3f (structure function)")
      :format(requested.Hx, r.hurst_psd.hurst, r.hurst_structure.hurst))
print(("  s2       requested %.4g mm^2   generated %.4g mm^2, %.4g mm^2 after mean-plane removal")
      :format(requested.variance * 1e6, summary.variance_raw * 1e6, a.variance * 1e6))
print(("  Lc       requested %.2f mm   roll-off %.2f mm, correlation length (1-1/e rule) %.2f mm")
      :format(mm(requested.Lcx), mm(r.rolloff_length), mm(r.correlation_length)))
print(("  rms %.4f mm, skewness %.3f, kurtosis %.3f"):format(mm(a.rms), a.skewness, a.kurtosis))
print("wrote " .. P.out .. "/{surface.h5, summary.json" ..
      (plotted and ", elevation.png, structure.png, psd.png, abbott.png" or "") ..
      (P.noise and ", noise.csv" .. (plotted and ", noise.png" or "") or "") .. "}")
if not plotted then print("no plots: " .. tostring(why)) end
