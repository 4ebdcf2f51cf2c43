// PNG plots through gnuplot: the runner every plot shares (io/plot.hpp says how it works) and
// plot_png's curves.
#include <spawn.h>
#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>

#include "asperity/io.hpp"
#include "io/plot.hpp"

extern char** environ;

namespace asperity::io {

namespace fs = std::filesystem;

std::string gnuplot_quoted(const std::string& s) {
  std::string q = "'";
  for (char c : s) {
    if (c == '\'') q += '\'';
    q += c;
  }
  return q + "'";
}

PlotDir::PlotDir() {
  std::string pattern = (fs::temp_directory_path() / "asperity-plot-XXXXXX").string();
  if (!::mkdtemp(pattern.data())) throw Error(std::string("plot: mkdtemp: ") + std::strerror(errno));
  path_ = pattern;
}

PlotDir::~PlotDir() {
  std::error_code ec;
  fs::remove_all(path_, ec);
}

namespace {

// Runs `program args...`, stdout and stderr into `log`. Returns the exit status, -1 if it could
// not be started.
int run_program(const std::vector<std::string>& argv, const fs::path& log) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = 0;
  int rc = posix_spawnp(&pid, args[0], &actions, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) return -1;
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) return -1;  // EINTR: a Ctrl-C reached us too; keep waiting for the child
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

std::string read_all(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

void run_gnuplot(const PlotDir& dir, const std::string& script, AtomicFile& png) {
  const fs::path script_file = dir.path() / "plot.gp";
  {
    std::ofstream out(script_file);
    out << script;
  }
  const fs::path log = dir.path() / "gnuplot.log";
  const int status = run_program({"gnuplot", script_file.string()}, log);
  const std::string target = png.target().string();
  if (status == -1)
    throw Error("plot '" + target + "': cannot run gnuplot (install gnuplot-nox)");
  if (status != 0 || !is_complete_png(png.temp_path()))
    throw Error("plot '" + target + "': gnuplot failed (status " + std::to_string(status) +
                "): " + read_all(log));
  png.commit();
}

bool gnuplot_available() {
  PlotDir dir;
  return run_program({"gnuplot", "--version"}, dir.path() / "log") == 0;
}

void plot_png(const fs::path& path, const Column& x, std::span<const Column> ys,
              const PlotOptions& options) {
  if (ys.empty()) throw Error("plot '" + path.string() + "': no y column given");
  for (const Column& y : ys)
    if (y.values.size() != x.values.size())
      throw Error("plot '" + path.string() + "': column '" + y.name + "' has " +
                  std::to_string(y.values.size()) + " values but x ('" + x.name + "') has " +
                  std::to_string(x.values.size()));
  PlotDir dir;
  fs::path data = dir.path() / "data.txt";
  {
    std::ofstream out(data);
    char buf[32];
    for (std::size_t i = 0; i < x.values.size(); ++i) {
      auto put = [&](double v) {
        if (std::isfinite(v)) {
          std::snprintf(buf, sizeof buf, "%.17g", v);
          out << buf;
        } else {
          out << "NaN";  // gnuplot leaves a gap
        }
      };
      put(x.values[i]);
      for (const Column& y : ys) {
        out << ' ';
        put(y.values[i]);
      }
      out << '\n';
    }
    out.close();  // a full disk may show only here
    if (!out) throw Error("plot: cannot write the data file in " + dir.path().string());
  }

  std::string ylabel = options.ylabel;
  if (ylabel.empty()) {
    // One column: its label. Several sharing a unit: the unit (the key names them).
    bool same_unit = true;
    for (const Column& y : ys) same_unit = same_unit && y.unit == ys[0].unit;
    if (ys.size() == 1) ylabel = ys[0].label();
    else if (same_unit && !ys[0].unit.empty()) ylabel = "[" + ys[0].unit + "]";
  }
  AtomicFile png(path);
  std::ostringstream gp;
  gp << "set terminal pngcairo noenhanced size " << options.width << "," << options.height
     << "\nset output " << gnuplot_quoted(png.temp_path().string())
     << "\nset xlabel " << gnuplot_quoted(options.xlabel.empty() ? x.label() : options.xlabel)
     << "\nset ylabel " << gnuplot_quoted(ylabel) << "\nset grid\n";
  // One curve needs no key (the axis label names it); several get theirs beside the plot, where
  // it never hides data.
  gp << (ys.size() == 1 ? "unset key\n" : "set key outside right top\n");
  if (!options.title.empty()) gp << "set title " << gnuplot_quoted(options.title) << "\n";
  if (options.logx) gp << "set logscale x\n";
  if (options.logy) gp << "set logscale y\nset format y \"%g\"\n";
  gp << "plot ";
  for (std::size_t j = 0; j < ys.size(); ++j) {
    if (j) gp << ", \\\n     ";
    gp << gnuplot_quoted(data.string()) << " using 1:" << j + 2 << " with "
       << (options.points ? "points" : "lines") << " linewidth 2 title "
       << gnuplot_quoted(ys[j].label());
  }
  gp << "\nunset output\n";
  run_gnuplot(dir, gp.str(), png);
}

}  // namespace asperity::io
