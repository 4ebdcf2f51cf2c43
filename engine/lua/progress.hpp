// The progress of world:run on stderr.
//
// On a terminal: one line, redrawn at most four times a second once the run has lasted a couple
// of seconds; the rate is smoothed so the ETA does not jump. Into a file or a pipe (a log under
// nohup, a batch job, a study's run): a plain line now and then, the first after a minute and
// then every few minutes, and a closing summary if any was written, so a run of hours shows where
// it is and short runs, tests and scripts' outputs stay quiet.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>

namespace asperity::lua {

// When a run whose stderr is not a terminal writes its progress lines (seconds from its start).
struct LogCadence {
  double first = 60;
  double every = 300;
  // ASPERITY_PROGRESS_EVERY=S (seconds > 0): a line after S and then every S (a batch job that
  // wants more or fewer lines); otherwise, or if it is not such a number (said once), the defaults.
  static LogCadence from_environment();
};

class Progress {
 public:
  // total 0: unknown (no percent, no ETA).
  Progress(bool wanted, std::uint64_t total_steps, LogCadence log = {});
  ~Progress();  // erases the terminal line (an error is on its way)
  // Whether a line is due now (cheap: one clock read).
  bool due();
  // `fraction` in [0, 1] (the script's own measure of completion, e.g. sheared / target
  // displacement) replaces done / total when given (>= 0).
  void draw(std::uint64_t done, const std::string& extra, double fraction = -1);
  // Replaces the line by a one-line summary (if anything was drawn).
  void finish(std::uint64_t done, const std::string& reason);

 private:
  using Clock = std::chrono::steady_clock;
  // The line for `done` steps at `now` with the current rate (draw updates the rate first).
  std::string text(std::uint64_t done, const std::string& extra, double fraction, Clock::time_point now) const;
  bool terminal_;  // redraw one line in place
  bool logging_;   // write a line now and then
  LogCadence log_;
  bool drawn_ = false;
  std::uint64_t total_;
  Clock::time_point start_, last_;
  std::uint64_t last_done_ = 0;
  double rate_ = 0;  // steps/s, smoothed
};

}  // namespace asperity::lua
