// world:run's progress (lua/progress.hpp) when stderr is not a terminal: a log gets a plain line
// now and then and a closing summary; a short run and a run that asked for none write nothing.
#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <thread>

#include "lua/progress.hpp"

using asperity::lua::LogCadence;
using asperity::lua::Progress;

namespace {
// A run of `seconds` drawing whenever a line is due, as world:run does after each chunk; returns
// what went to stderr (captured: not a terminal).
std::string logged(bool wanted, LogCadence cadence, double seconds) {
  testing::internal::CaptureStderr();
  {
    Progress p(wanted, 0, cadence);
    const auto t0 = std::chrono::steady_clock::now();
    std::uint64_t steps = 0;
    while (std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() < seconds) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
      steps += 10;
      if (p.due()) p.draw(steps, "disp_mm=0.5", std::min(1.0, steps / 1000.0));
    }
    p.finish(steps, "stop_when");
  }
  return testing::internal::GetCapturedStderr();
}

int count(const std::string& text, const std::string& what) {
  int n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}
}  // namespace

TEST(Progress, ALogGetsALineNowAndThenAndASummary) {
  const std::string out = logged(true, {0.05, 0.1}, 0.42);
  EXPECT_EQ(out.find('\r'), std::string::npos) << "no terminal control in a log:\n" << out;
  EXPECT_EQ(out.find('\033'), std::string::npos) << out;
  // Lines at about 0.05, 0.15, 0.25, 0.35 s (sleeps run long on a busy machine: at least 2).
  const int lines = count(out, "ETA ");
  EXPECT_GE(lines, 2) << out;
  EXPECT_LE(lines, 4) << out;
  EXPECT_EQ(count(out, "disp_mm=0.5\n"), lines) << "each line whole, with the script's values:\n" << out;
  EXPECT_EQ(count(out, "%"), lines) << out;
  EXPECT_NE(out.find("steps in "), std::string::npos) << "the closing summary:\n" << out;
  EXPECT_NE(out.find(", stop_when\n"), std::string::npos) << out;
}

TEST(Progress, ShortRunsAndRunsWithoutProgressStayQuiet) {
  EXPECT_EQ(logged(true, {}, 0.1), "");           // the default: the first line after a minute
  EXPECT_EQ(logged(false, {0.01, 0.01}, 0.1), "");  // progress = false
}
