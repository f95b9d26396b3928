#include "cli/progress.hpp"

#include <unistd.h>

#include <cstdio>

namespace femdyn::cli {

Progress::Progress(double total, std::string unit, std::string label)
    : total_(total),
      unit_(std::move(unit)),
      label_(std::move(label)),
      tty_(::isatty(STDERR_FILENO) == 1),
      start_(Clock::now()),
      last_(start_) {}

void Progress::update(double done, double total) {
  total_ = total;
  update(done);
}

void Progress::update(double done) {
  if (!tty_) return;
  const auto now = Clock::now();
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  if (elapsed < 1.0 || std::chrono::duration<double>(now - last_).count() < 0.1) return;
  last_ = now;
  const double f = total_ > 0 ? done / total_ : 1.0;
  const int width = 30, filled = static_cast<int>(f * width);
  std::string bar(static_cast<std::size_t>(filled), '#');
  bar.resize(width, ' ');
  const double rate = done / elapsed;  // simulated units per wall second
  const double eta = rate > 0 ? (total_ - done) / rate : 0;
  std::fprintf(stderr, "\r[%s] %5.1f%%  %s %.4g/%.4g %s  %.3g %s/s  ETA %.0f s ", bar.c_str(),
               100 * f, label_.c_str(), done, total_, unit_.c_str(), rate, unit_.c_str(), eta);
  std::fflush(stderr);
  drawn_ = true;
}

void Progress::finish() {
  if (!drawn_) return;
  std::fprintf(stderr, "\r%80s\r", "");
  std::fflush(stderr);
  drawn_ = false;
}

}  // namespace femdyn::cli
