// The gnuplot runner behind every PNG of the engine: curves (io/plot.cpp, plot_png) and height
// maps (surface/plot_map.cpp). A plot writes its data into a private temporary directory and
// composes a script that draws into its PNG's temporary name (AtomicFile); run_gnuplot runs
// gnuplot on it as a child process (posix_spawn, no shell, so no quoting of file names through
// sh), quotes gnuplot's output in the error if it fails, and renames the PNG when it is complete.
#pragma once

#include <filesystem>
#include <string>

#include "asperity/io.hpp"

namespace asperity::io {

// s as a gnuplot single-quoted string: a quote is written as two quotes, nothing else is special.
std::string gnuplot_quoted(const std::string& s);

// A private temporary directory for a plot's data and script, removed with all it holds.
class PlotDir {
 public:
  PlotDir();
  ~PlotDir();
  PlotDir(const PlotDir&) = delete;
  PlotDir& operator=(const PlotDir&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

// Runs gnuplot on `script` (written into `dir`), which draws into png.temp_path(), and commits
// `png`. Throws Error naming png's target if gnuplot cannot be started, fails, or leaves an
// incomplete PNG (a full disk), with gnuplot's output.
void run_gnuplot(const PlotDir& dir, const std::string& script, AtomicFile& png);

}  // namespace asperity::io
