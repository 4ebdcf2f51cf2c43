#include "lua/progress.hpp"

#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace asperity::lua {

namespace {
constexpr double kDelay = 2.0;     // s before the first draw
constexpr double kInterval = 0.25; // s between draws

std::string duration_text(double s) {
  char buf[32];
  long t = static_cast<long>(s + 0.5);
  if (t >= 3600) std::snprintf(buf, sizeof buf, "%ld:%02ld:%02ld", t / 3600, t / 60 % 60, t % 60);
  else std::snprintf(buf, sizeof buf, "%ld:%02ld", t / 60, t % 60);
  return buf;
}

std::string rate_text(double r) {
  char buf[32];
  if (r >= 1e6) std::snprintf(buf, sizeof buf, "%.1fM", r / 1e6);
  else if (r >= 1e3) std::snprintf(buf, sizeof buf, "%.1fk", r / 1e3);
  else std::snprintf(buf, sizeof buf, "%.0f", r);
  return buf;
}
}  // namespace

LogCadence LogCadence::from_environment() {
  LogCadence c;
  const char* text = std::getenv("ASPERITY_PROGRESS_EVERY");
  if (!text || !*text) return c;
  char* end = nullptr;
  const double s = std::strtod(text, &end);
  if (*end == '\0' && s > 0 && std::isfinite(s)) {
    c.first = c.every = s;
  } else {
    static bool said = false;
    if (!said) std::fprintf(stderr, "asperity: ASPERITY_PROGRESS_EVERY=%s ignored (seconds > 0 expected)\n", text);
    said = true;
  }
  return c;
}

Progress::Progress(bool wanted, std::uint64_t total_steps, LogCadence log)
    : terminal_(wanted && ::isatty(STDERR_FILENO)), logging_(wanted && !terminal_), log_(log),
      total_(total_steps), start_(Clock::now()), last_(start_) {}

Progress::~Progress() {
  if (drawn_ && terminal_) {
    std::fputs("\r\033[K", stderr);
    std::fflush(stderr);
  }
}

bool Progress::due() {
  if (!terminal_ && !logging_) return false;
  auto now = Clock::now();
  const double delay = terminal_ ? kDelay : log_.first, interval = terminal_ ? kInterval : log_.every;
  return std::chrono::duration<double>(now - start_).count() >= delay &&
         (!drawn_ || std::chrono::duration<double>(now - last_).count() >= interval);
}

void Progress::draw(std::uint64_t done, const std::string& extra, double fraction) {
  const auto now = Clock::now();
  const double since_last = std::chrono::duration<double>(now - last_).count();
  const double instant = since_last > 0 ? double(done - last_done_) / since_last : 0;
  rate_ = drawn_ ? 0.7 * rate_ + 0.3 * instant
                 : double(done) / std::chrono::duration<double>(now - start_).count();
  last_ = now;
  last_done_ = done;
  drawn_ = true;
  std::string line = text(done, extra, fraction, now);
  if (logging_) {
    std::fprintf(stderr, "%s\n", line.c_str());
    std::fflush(stderr);
    return;
  }
  winsize ws{};
  if (::ioctl(STDERR_FILENO, TIOCGWINSZ, &ws) == 0 && ws.ws_col > 1 && line.size() >= ws.ws_col)
    line.resize(ws.ws_col - 1);
  std::fprintf(stderr, "\r\033[K%s", line.c_str());
  std::fflush(stderr);
}

std::string Progress::text(std::uint64_t done, const std::string& extra, double fraction,
                           Clock::time_point now) const {
  std::string line;
  char buf[96];
  double elapsed = std::chrono::duration<double>(now - start_).count();
  const bool by_fraction = fraction >= 0;
  auto bar = [](double f) {
    const int width = 20, filled = static_cast<int>(f * width);
    return "[" + std::string(static_cast<std::size_t>(filled), '#') +
           std::string(static_cast<std::size_t>(width - filled), '-') + "]";
  };
  if (by_fraction) {
    const double f = std::min(fraction, 1.0);
    line = bar(f);
    std::snprintf(buf, sizeof buf, " %5.1f%%  step %llu", 100 * f, (unsigned long long)done);
    line += buf;
  } else if (total_) {
    double f = double(done) / double(total_);
    line = bar(f);
    std::snprintf(buf, sizeof buf, " %5.1f%%  %llu/%llu", 100 * f, (unsigned long long)done,
                  (unsigned long long)total_);
    line += buf;
  } else {
    std::snprintf(buf, sizeof buf, "step %llu", (unsigned long long)done);
    line = buf;
  }
  line += "  " + rate_text(rate_) + " steps/s";
  line += "  " + duration_text(elapsed);
  if (by_fraction && fraction > 0)
    line += "  ETA " + duration_text(elapsed * (1 - std::min(fraction, 1.0)) / fraction);
  else if (!by_fraction && total_ && rate_ > 0)
    line += "  ETA " + duration_text(double(total_ - done) / rate_);
  if (!extra.empty()) line += "  " + extra;
  return line;
}

void Progress::finish(std::uint64_t done, const std::string& reason) {
  if (drawn_) {
    double elapsed = std::chrono::duration<double>(Clock::now() - start_).count();
    std::fprintf(stderr, "%s%llu steps in %s (%s steps/s)%s%s\n", terminal_ ? "\r\033[K" : "",
                 (unsigned long long)done, duration_text(elapsed).c_str(),
                 rate_text(double(done) / elapsed).c_str(), reason.empty() ? "" : ", ", reason.c_str());
    std::fflush(stderr);
    drawn_ = false;
  }
  terminal_ = logging_ = false;
}

}  // namespace asperity::lua
