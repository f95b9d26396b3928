// The validator's front door (validation/validate.hpp): a Validator built for a model, its
// estimate and refusal, and its run; validate() in one call. Its parts: validation/validator.hpp.
#include "validation/validate.hpp"

#include "validation/validator.hpp"

namespace femdyn::validation {

bool ValidationReport::pass() const {
  if (!failure.empty()) return false;
  for (const QuantityError& q : quantities)
    if (!q.pass()) return false;
  return trajectory.pass();
}

Validator::Validator(const Model& model, ValidationOptions options)
    : impl_(std::make_unique<Impl>(model, std::move(options))) {}
Validator::~Validator() = default;

const WorkEstimate& Validator::estimate() const { return impl_->estimate; }

ValidationReport Validator::run() { return impl_->run(); }

void Validator::set_progress(std::function<void(double, double)> progress) {
  impl_->o.progress = std::move(progress);
}

ValidationReport validate(const Model& m, const ValidationOptions& o) {
  Validator v(m, o);
  if (std::string why = v.refusal(m.where.empty() ? m.name : m.where); !why.empty())
    throw OverBudget(why);
  return v.run();
}

}  // namespace femdyn::validation
