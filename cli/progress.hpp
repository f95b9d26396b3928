// A progress bar on stderr for long runs: only when stderr is a terminal and the run has taken
// more than a second; redrawn at most ten times a second. Percent done, rate and ETA.
#pragma once
#include <chrono>
#include <string>

namespace femdyn::cli {

class Progress {
 public:
  // e.g. (t_end, "s"): "t = 0.1/0.5 s"; with a label, "<label> 0.1/0.5 s" instead.
  Progress(double total, std::string unit, std::string label = "t =");
  ~Progress() { finish(); }
  void update(double done);
  void update(double done, double total);  // the total revised (an estimate)
  void finish();                           // clears the bar

 private:
  using Clock = std::chrono::steady_clock;
  double total_;
  std::string unit_, label_;
  bool tty_;
  bool drawn_ = false;
  Clock::time_point start_, last_;
};

}  // namespace femdyn::cli
