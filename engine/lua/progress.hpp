// The progress line of world:run on stderr.
//
// Shown only when stderr is a terminal and the run has lasted more than a couple of seconds, so
// short runs, tests and logs redirected to files stay quiet. Redrawn at most four times a
// second; the rate is smoothed so the ETA does not jump.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>

namespace asperity::lua {

class Progress {
 public:
  Progress(bool wanted, std::uint64_t total_steps);  // total 0: unknown (no percent, no ETA)
  ~Progress();  // erases the line (an error is on its way)
  // Whether a redraw is due now (cheap: one clock read).
  bool due();
  // `fraction` in [0, 1] (the script's own measure of completion, e.g. sheared / target
  // displacement) replaces done / total when given (>= 0).
  void draw(std::uint64_t done, const std::string& extra, double fraction = -1);
  // Replaces the line by a one-line summary (if anything was drawn).
  void finish(std::uint64_t done, const std::string& reason);

 private:
  using Clock = std::chrono::steady_clock;
  bool enabled_;
  bool drawn_ = false;
  std::uint64_t total_;
  Clock::time_point start_, last_;
  std::uint64_t last_done_ = 0;
  double rate_ = 0;  // steps/s, smoothed
};

}  // namespace asperity::lua
