// Numerical outcome of an algorithm: failures are reported, never aborted on.
#pragma once
#include <string>

namespace femdyn {

struct Status {
  bool ok = true;
  std::string message;
  int coordinate = -1;  // the coordinate a failure is attributed to, if any
  bool non_finite = false;  // the failure is a NaN or Inf (an overflow), not a singular matrix
};

}  // namespace femdyn
