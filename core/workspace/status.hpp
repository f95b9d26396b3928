// Numerical outcome of an algorithm: failures are reported, never aborted on.
#pragma once
#include <cstdio>
#include <string>

namespace femdyn {

struct Status {
  bool ok = true;
  std::string message;
  int coordinate = -1;       // the coordinate a failure is attributed to, if any
  bool non_finite = false;   // the failure is a NaN or Inf (an overflow), not a singular matrix
  bool diverged = false;     // the numerical solution blew up (sim/divergence.hpp)
  bool interrupted = false;  // stopped at the caller's request (Ctrl-C): not a failure of the run
};

// The failure of a diagonal entry M^s(a, a) against the largest diagonal entry: no inertia at
// all, or too little to count in double precision.
inline Status negligible_inertia(const std::string& coordinate, int a, double Maa, double largest) {
  if (!(Maa > 0))
    return {false,
            "the mass matrix M^s is singular: coordinate '" + coordinate +
                "' moves no inertia (a massless chain end, or all its mass on the joint axis?)",
            a};
  char ratio[32];
  std::snprintf(ratio, sizeof ratio, "%.1e", Maa / largest);
  return {false,
          "the mass matrix M^s is singular to double precision: coordinate '" + coordinate +
              "' moves an inertia " + ratio +
              " times the largest on its diagonal (links of very different sizes, or a very long "
              "chain?)",
          a};
}

}  // namespace femdyn
