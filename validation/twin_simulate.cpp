// The twin's trajectories (twin.hpp, SimbodyTwin::simulate): Simbody's error-controlled
// integrators, which of them can run in this process, and the sampled run. Compiled like
// twin.cpp (C++17, without NDEBUG).
#include <Simbody.h>
#include <dlfcn.h>
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "core/model/names.hpp"
#include "validation/twin_impl.hpp"

namespace femdyn::validation {

namespace {

// The integrator `which` on `system`, in its default error-controlled (variable-step) mode.
std::unique_ptr<SimTK::Integrator> make_integrator(SimbodyIntegrator which,
                                                   const SimTK::System& system) {
  switch (which) {
    case SimbodyIntegrator::RungeKuttaMerson:
      return std::make_unique<SimTK::RungeKuttaMersonIntegrator>(system);
    case SimbodyIntegrator::RungeKutta3:
      return std::make_unique<SimTK::RungeKutta3Integrator>(system);
    case SimbodyIntegrator::RungeKuttaFeldberg:
      return std::make_unique<SimTK::RungeKuttaFeldbergIntegrator>(system);
    case SimbodyIntegrator::Verlet:  // the constructor without a step size: variable step
      return std::make_unique<SimTK::VerletIntegrator>(system);
    case SimbodyIntegrator::SemiExplicitEuler2:
      return std::make_unique<SimTK::SemiExplicitEuler2Integrator>(system);
    case SimbodyIntegrator::CPodes:  // the constructor's default: BDF with Newton iteration
      return std::make_unique<SimTK::CPodesIntegrator>(system);
  }
  throw std::invalid_argument("unknown SimbodyIntegrator");
}

// The file of the library the dynamic linker binds `symbol` to for the whole process, or "".
std::string defining_library(const char* symbol) {
  void* address = dlsym(RTLD_DEFAULT, symbol);
  Dl_info info;
  if (!address || !dladdr(address, &info) || !info.dli_fname) return {};
  return info.dli_fname;
}

// Why CPodes cannot run in this process, or "". Simbody's CPodes is its own copy of SUNDIALS
// CVODES, which exports the SUNDIALS names (N_VSpace, N_VClone, DenseGETRF, ...) unprefixed.
// A process that also exports the system's SUNDIALS (femdyn_core links it statically and keeps
// its symbols out of the dynamic table, see CMakeLists.txt, so femdyn's do not) binds each
// such name once, to whichever library comes first; if that is not Simbody's,
// CPodes calls SUNDIALS 6 on its own vectors and aborts in an assert (nvector_SimTK.h) — not
// an exception, so it must be refused before it starts. Checked once per process.
const std::string& cpodes_conflict() {
  static const std::string why = [] {
    const std::string simbody = defining_library("CPodeCreate");  // only in libSimTKmath
    for (const char* name :
         {"N_VSpace", "N_VClone", "N_VLinearSum", "N_VWrmsNorm", "DenseGETRF", "newDenseMat"}) {
      const std::string where = defining_library(name);
      if (!simbody.empty() && where == simbody) continue;
      return std::string("CPodes cannot run in this process: its SUNDIALS symbol ") + name +
             " binds to " + (where.empty() ? std::string("nothing") : where) +
             ", not to Simbody's " + (simbody.empty() ? std::string("libSimTKmath") : simbody) +
             " (the system SUNDIALS linked by femdyn shadows Simbody's bundled copy)";
    }
    return std::string();
  }();
  return why;
}

}  // namespace

bool SimbodyTwin::can_simulate(std::string* why_not) const {
  if (!impl_->couplers && why_not)
    *why_not =
        "a coordinate drives no joint directly, so the coupling is not a set of "
        "coordinate couplers";
  return impl_->couplers;
}

const char* simbody_integrator_name(SimbodyIntegrator which) {
  switch (which) {
    case SimbodyIntegrator::RungeKuttaMerson:
      return "RungeKuttaMerson";
    case SimbodyIntegrator::RungeKutta3:
      return "RungeKutta3";
    case SimbodyIntegrator::RungeKuttaFeldberg:
      return "RungeKuttaFeldberg";
    case SimbodyIntegrator::Verlet:
      return "Verlet";
    case SimbodyIntegrator::SemiExplicitEuler2:
      return "SemiExplicitEuler2";
    case SimbodyIntegrator::CPodes:
      return "CPodes";
  }
  return "unknown";
}

// Simbody 3.7 (Debian's libsimbody-dev) ships all six (simmath/*Integrator.h); CPodes only
// where its bundled SUNDIALS is not shadowed (cpodes_conflict).
std::vector<SimbodyIntegrator> simbody_integrators() {
  std::vector<SimbodyIntegrator> out{
      SimbodyIntegrator::RungeKuttaMerson, SimbodyIntegrator::RungeKutta3,
      SimbodyIntegrator::RungeKuttaFeldberg, SimbodyIntegrator::Verlet,
      SimbodyIntegrator::SemiExplicitEuler2};
  if (cpodes_conflict().empty()) out.push_back(SimbodyIntegrator::CPodes);
  return out;
}

// As before the integrator choice: empty without couplers, and a failed integration throws
// (callers such as validate() index every sample).
std::vector<TwinSample> SimbodyTwin::simulate(const VecX& q0, const VecX& qd0,
                                              const std::vector<double>& times, double accuracy) {
  TwinRun run = simulate(q0, qd0, times, accuracy, SimbodyIntegrator::RungeKuttaMerson);
  if (!run.stats.ok && can_simulate()) throw femdyn::Error(run.stats.failure);
  return std::move(run.samples);
}

namespace {

// Adds the wall time of its scope to `total`, also when the scope is left by an exception.
struct Stopwatch {
  using Clock = std::chrono::steady_clock;
  double& total;
  Clock::time_point start = Clock::now();
  ~Stopwatch() { total += std::chrono::duration<double>(Clock::now() - start).count(); }
};

// Why `which` must not be run at `accuracy` to `times`, or "": Simbody would abort in an
// assert (not throw) on these.
std::string why_not_run(SimbodyIntegrator which, double accuracy,
                        const std::vector<double>& times) {
  if (!(accuracy > 0 && accuracy < 1))
    return "accuracy must be in (0, 1), not " + std::to_string(accuracy);
  for (std::size_t i = 0; i < times.size(); ++i)
    if (!std::isfinite(times[i]) || !(times[i] >= (i ? times[i - 1] : 0.0)))
      return "sample times must be finite, >= 0 and non-decreasing";
  if (which == SimbodyIntegrator::CPodes) return cpodes_conflict();
  return {};
}

// One line for an integrator that returned from stepTo(t) short of t.
std::string stopped_early(SimbodyIntegrator which, const SimTK::Integrator& integ, double t) {
  const std::string reason =
      integ.isSimulationOver()
          ? SimTK::Integrator::getTerminationReasonString(integ.getTerminationReason())
          : std::string("no termination reason");
  return std::string(simbody_integrator_name(which)) +
         " stopped at t = " + std::to_string(integ.getTime()) + " short of " + std::to_string(t) +
         ": " + one_line(reason);
}

void count(const SimTK::Integrator& integ, TwinRunStats& stats) {
  stats.steps = integ.getNumStepsTaken();
  stats.attempts = integ.getNumStepsAttempted();
  stats.realizations = integ.getNumRealizations();
  stats.error_test_failures = integ.getNumErrorTestFailures();
  stats.convergence_failures = integ.getNumConvergenceTestFailures();
}

// The integrator with the run's settings (below); `final_times` non-empty when it interpolates.
// A time bound: the integrator hands control back every kChunk steps (ReachedStepLimit), and
// the stepper every significant state, so the clock can be read between steps.
std::unique_ptr<SimTK::Integrator> configured_integrator(SimbodyIntegrator which,
                                                         const SimTK::MultibodySystem& system,
                                                         double accuracy,
                                                         const std::vector<double>& final_times,
                                                         bool bounded) {
  constexpr int kChunk = 16;
  std::unique_ptr<SimTK::Integrator> integ = make_integrator(which, system);
  integ->setAccuracy(accuracy);
  integ->setConstraintTolerance(accuracy);
  integ->setReturnEveryInternalStep(false);
  integ->setAllowInterpolation(true);
  if (!final_times.empty() && final_times.back() > 0) integ->setFinalTime(final_times.back());
  if (bounded) integ->setInternalStepLimit(kChunk);
  return integ;
}

// CPODES, inside Simbody's CPodesIntegrator, prints its own warnings and errors on stderr
// ("[CPODES ERROR] … mxstep steps taken before reaching tout"), which Simbody gives no way to
// turn off; its failures reach the caller as stats.failure. While `quiet`, fd 2 is /dev/null.
class QuietStderr {
 public:
  explicit QuietStderr(bool quiet) {
    if (!quiet) return;
    std::fflush(stderr);
    saved_ = dup(STDERR_FILENO);
    const int null = open("/dev/null", O_WRONLY | O_CLOEXEC);
    if (saved_ >= 0 && null >= 0) dup2(null, STDERR_FILENO);
    if (null >= 0) close(null);
  }
  ~QuietStderr() {
    if (saved_ < 0) return;
    std::fflush(stderr);
    dup2(saved_, STDERR_FILENO);
    close(saved_);
  }
  QuietStderr(const QuietStderr&) = delete;
  QuietStderr& operator=(const QuietStderr&) = delete;

 private:
  int saved_ = -1;
};

std::string out_of_time_text(SimbodyIntegrator which, double t, double t_end, double bound) {
  char text[160];
  std::snprintf(text, sizeof text,
                " stopped at t = %.3g s of %.3g s: its time bound of %.3g s ran out", t, t_end,
                bound);
  return simbody_integrator_name(which) + std::string(text);
}

}  // namespace

// Settings: setAccuracy and setConstraintTolerance at `accuracy`; Simbody's defaults otherwise,
// set explicitly: setReturnEveryInternalStep(false) and setAllowInterpolation(true). StepToEach
// drives a TimeStepper, whose stepTo(t) makes t a scheduled event time too, so a step ends at
// every sample; Interpolate calls the integrator's own stepTo(t) (no scheduled event), with the
// final time at the last sample, and samples its interpolated states (twin.hpp). Only
// initialize() and stepTo() are timed.
TwinRun SimbodyTwin::simulate(const VecX& q0, const VecX& qd0, const std::vector<double>& times,
                              double accuracy, SimbodyIntegrator which, TwinSampling sampling,
                              const TwinRunLimits& limits) {
  Impl& s = *impl_;
  TwinRun run;
  TwinRunStats& stats = run.stats;
  // Not run: no coordinate couplers, or what Simbody would abort on.
  if (can_simulate(&stats.failure)) stats.failure = why_not_run(which, accuracy, times);
  if (!stats.failure.empty()) {
    stats.ok = false;
    return run;
  }
  std::unique_ptr<SimTK::Integrator> integ;
  const QuietStderr quiet(which == SimbodyIntegrator::CPodes);
  try {
    s.enable_loops(s.simulate_closed);  // the integrator starts from (a copy of) this state
    s.set_state(q0, qd0, SimTK::Stage::Velocity);
    s.state.setTime(0);
    const bool interpolate = sampling == TwinSampling::Interpolate;
    const bool bounded = limits.wall_time > 0;
    integ = configured_integrator(which, s.system, accuracy,
                                  interpolate ? times : std::vector<double>{}, bounded);
    SimTK::TimeStepper stepper(s.system, *integ);
    if (bounded) stepper.setReportAllSignificantStates(true);
    const auto start = std::chrono::steady_clock::now();
    const auto out_of_time = [&] {
      return bounded &&
             std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() >
                 limits.wall_time;
    };
    {
      Stopwatch timed{stats.wall_time};
      if (interpolate)
        integ->initialize(s.state);
      else
        stepper.initialize(s.state);
    }
    bool timed_out = false;
    for (double t : times) {
      if (t > 0) {
        Stopwatch timed{stats.wall_time};
        if (interpolate) {
          // Returns at t, or earlier at the start of the continuous interval or a step limit.
          while (integ->getTime() < t && !integ->isSimulationOver() && !(timed_out = out_of_time()))
            if (integ->stepTo(t) == SimTK::Integrator::EndOfSimulation) break;
        } else if (bounded) {  // returns at every significant state, and every kChunk steps
          while (integ->getTime() < t && !integ->isSimulationOver() && !(timed_out = out_of_time()))
            stepper.stepTo(t);
        } else {
          stepper.stepTo(t);
        }
      }
      if (timed_out) {
        stats.ok = false;
        stats.out_of_time = true;
        stats.failure = out_of_time_text(which, integ->getTime(), times.back(), limits.wall_time);
        break;
      }
      if (std::abs(integ->getTime() - t) > 1e-12 * std::max(1.0, t)) {
        stats.ok = false;
        stats.failure = stopped_early(which, *integ, t);
        break;
      }
      run.samples.push_back(s.sample(integ->getState()));
      if (limits.on_sample) limits.on_sample(t);
    }
  } catch (const std::exception& e) {
    stats.ok = false;
    stats.failure = std::string(simbody_integrator_name(which)) + " failed: " + one_line(e.what());
  }
  if (integ) count(*integ, stats);
  s.enable_loops(false);
  return run;
}

}  // namespace femdyn::validation
