// engine/surface/plot_map.cpp - elevation map of a height map as a PNG heat map (gnuplot).
//
// Design notes
// - io::plot_png draws curves (x against one or more y columns); a map needs gnuplot's
//   `with image` on a matrix, which it does not offer, so this file drives gnuplot itself the
//   same way: a private temporary directory holding the data and the script, gnuplot run with
//   posix_spawnp (no shell, so no quoting of paths through sh), its output captured and quoted in
//   the error, and the PNG drawn to a temporary name (io::AtomicFile) and renamed when complete.
//   If io::plot_png grows an image mode, this file should become a call to it.
// - The heights go to gnuplot as raw doubles (`binary array=(nx,ny) format='%float64'`): a
//   365^2 map is 1 MB instead of a few MB of text, and no precision is lost. Row j of the data is
//   y = j h, as in HeightMap, so the image is drawn with y upwards. NaN nodes (a profilometer
//   node no particle covers) stay blank.
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "asperity/error.hpp"
#include "asperity/io.hpp"
#include "asperity/surface.hpp"

extern char** environ;

namespace asperity::surface {

namespace fs = std::filesystem;

namespace {

// gnuplot single-quoted strings: a quote is written as two quotes, nothing else is special.
std::string quoted(const std::string& s) {
    std::string q = "'";
    for (char c : s) {
        if (c == '\'') q += '\'';
        q += c;
    }
    return q + "'";
}

class TempDir {
public:
    TempDir() {
        std::string pattern = (fs::temp_directory_path() / "asperity-map-XXXXXX").string();
        if (!::mkdtemp(pattern.data()))
            throw Error(std::string("plot_height_map_png: mkdtemp: ") + std::strerror(errno));
        path_ = pattern;
    }
    ~TempDir() {
        std::error_code ec;
        fs::remove_all(path_, ec);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
    const fs::path& path() const { return path_; }

private:
    fs::path path_;
};

// gnuplot SCRIPT with stdout and stderr into `log`; the exit status, -1 if it did not start.
int run_gnuplot(const fs::path& script, const fs::path& log) {
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, 1, 2);
    posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
    std::string program = "gnuplot", arg = script.string();
    char* argv[] = {program.data(), arg.data(), nullptr};
    pid_t pid = 0;
    const int rc = posix_spawnp(&pid, argv[0], &actions, nullptr, argv, environ);
    posix_spawn_file_actions_destroy(&actions);
    if (rc != 0) return -1;
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0)
        if (errno != EINTR) return -1;  // EINTR: Ctrl-C reached us too; wait for the child
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

}  // namespace

void plot_height_map_png(const HeightMap& map, const std::string& path,
                         const MapPlotOptions& options) {
    if (map.nx < 1 || map.ny < 1 || map.height.size() != static_cast<std::size_t>(map.nx) * map.ny)
        throw Error("plot_height_map_png: the map needs nx, ny >= 1 and nx * ny heights");
    if (!(map.spacing > 0)) throw Error("plot_height_map_png: spacing must be > 0");
    TempDir dir;
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
        if (std::isfinite(z)) { sum += z * options.height_scale; count += 1; }
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
       << "\nset output " << quoted(png.temp_path().string())
       << "\nset xlabel " << quoted("x [" + options.length_unit + "]")
       << "\nset ylabel " << quoted("y [" + options.length_unit + "]")
       << "\nset cblabel " << quoted("height [" + options.height_unit + "]")
       << "\nset size ratio -1\nset tics out\n"
       << "set xrange [" << -0.5 * h << ":" << xmax << "]\n"
       << "set yrange [" << -0.5 * h << ":" << ymax << "]\n"
       // A diverging blue-white-brown palette: valleys blue, peaks brown, the mean plane pale.
       << "set palette defined (0 '#08306b', 0.25 '#4292c6', 0.5 '#f7f7f7', 0.75 '#d6a05c', "
          "1 '#67300b')\n"
       << "set cbrange [" << centre - extent << ":" << centre + extent << "]\n";
    if (!options.title.empty()) gp << "set title " << quoted(options.title) << "\n";
    gp << "plot " << quoted(data.string()) << " binary array=(" << map.nx << "," << map.ny
       << ") format='%float64' dx=" << h << " dy=" << h
       << " origin=(0,0) with image notitle\nunset output\n";
    const fs::path script = dir.path() / "map.gp";
    {
        std::ofstream out(script);
        out << gp.str();
    }
    const fs::path log = dir.path() / "gnuplot.log";
    const int status = run_gnuplot(script, log);
    if (status == -1)
        throw Error("plot '" + path + "': cannot run gnuplot (install gnuplot-nox)");
    if (status != 0 || !io::is_complete_png(png.temp_path())) {
        std::ifstream in(log);
        std::stringstream text;
        text << in.rdbuf();
        throw Error("plot '" + path + "': gnuplot failed (status " + std::to_string(status) +
                    "): " + text.str());
    }
    png.commit();
}

}  // namespace asperity::surface
