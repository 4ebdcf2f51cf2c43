// engine/surface/plot_map.cpp - elevation map of a height map as a PNG heat map (gnuplot).
//
// Design notes
// - io::plot_png draws curves (x against one or more y columns); a map needs gnuplot's
//   `with image` on a matrix, which it does not offer, so this file writes its own data and
//   script and draws them with plot_png's runner (io/plot.hpp). If io::plot_png grows an image
//   mode, this file should become a call to it.
// - The heights go to gnuplot as raw doubles (`binary array=(nx,ny) format='%float64'`): a
//   365^2 map is 1 MB instead of a few MB of text, and no precision is lost. Row j of the data is
//   y = j h, as in HeightMap, so the image is drawn with y upwards. NaN nodes (a profilometer
//   node no particle covers) stay blank.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "asperity/error.hpp"
#include "asperity/io.hpp"
#include "asperity/surface.hpp"
#include "io/plot.hpp"

namespace asperity::surface {

namespace fs = std::filesystem;

void plot_height_map_png(const HeightMap& map, const std::string& path,
                         const MapPlotOptions& options) {
  if (map.nx < 1 || map.ny < 1 || map.height.size() != static_cast<std::size_t>(map.nx) * map.ny)
    throw Error("plot_height_map_png: the map needs nx, ny >= 1 and nx * ny heights");
  if (!(map.spacing > 0)) throw Error("plot_height_map_png: spacing must be > 0");
  io::PlotDir dir;
  const fs::path data = dir.path() / "heights.bin";
  {
    std::ofstream out(data, std::ios::binary);
    for (double z : map.height) {
      const double v = z * options.height_scale;
      out.write(reinterpret_cast<const char*>(&v), sizeof v);
    }
    out.close();  // a full disk may show only here
    if (!out) throw Error("plot_height_map_png: cannot write " + data.string());
  }
  const double h = map.spacing * options.length_scale;
  // Colour range symmetric about the mean height, so the palette's pale middle is the mean
  // level (zero for generated maps; a DEM map sits wherever the particles are).
  double sum = 0.0, count = 0.0, extent = 0.0;
  for (double z : map.height)
    if (std::isfinite(z)) {
      sum += z * options.height_scale;
      count += 1;
    }
  const double centre = count > 0 ? sum / count : 0.0;
  for (double z : map.height)
    if (std::isfinite(z)) extent = std::max(extent, std::abs(z * options.height_scale - centre));
  if (!(extent > 0)) extent = 1.0;
  // Pixels are centred on the nodes: the image spans half a step beyond the first/last node.
  const double xmax = (map.nx - 0.5) * h, ymax = (map.ny - 0.5) * h;
  io::AtomicFile png(path);
  std::ostringstream gp;
  gp.precision(17);
  gp << "set terminal pngcairo noenhanced size " << options.width << "," << options.height
     << "\nset output " << io::gnuplot_quoted(png.temp_path().string()) << "\nset xlabel "
     << io::gnuplot_quoted("x [" + options.length_unit + "]") << "\nset ylabel "
     << io::gnuplot_quoted("y [" + options.length_unit + "]") << "\nset cblabel "
     << io::gnuplot_quoted("height [" + options.height_unit + "]")
     << "\nset size ratio -1\nset tics out\n"
     << "set xrange [" << -0.5 * h << ":" << xmax << "]\n"
     << "set yrange [" << -0.5 * h << ":" << ymax
     << "]\n"
     // A diverging blue-white-brown palette: valleys blue, peaks brown, the mean plane pale.
     << "set palette defined (0 '#08306b', 0.25 '#4292c6', 0.5 '#f7f7f7', 0.75 '#d6a05c', "
        "1 '#67300b')\n"
     << "set cbrange [" << centre - extent << ":" << centre + extent << "]\n";
  if (!options.title.empty()) gp << "set title " << io::gnuplot_quoted(options.title) << "\n";
  gp << "plot " << io::gnuplot_quoted(data.string()) << " binary array=(" << map.nx << "," << map.ny
     << ") format='%float64' dx=" << h << " dy=" << h
     << " origin=(0,0) with image notitle\nunset output\n";
  io::run_gnuplot(dir, gp.str(), png);
}

}  // namespace asperity::surface
