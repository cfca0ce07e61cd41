#include "livo/vio/vio_messages.hpp"

#include <cmath>

#include <Eigen/Cholesky>

#include "livo/filter_state_message.hpp"
#include "livo/messages.hpp"

namespace livo::vio {

bool priorFromMessage(const filter_state_t& m, FilterState* x, StateCovariance* P, std::string* why) {
  if (!fromFilterState(m, x, P)) {
    *why = "prior has non-finite numbers or a degenerate quaternion";
    return false;
  }
  *P = (0.5 * (*P + P->transpose())).eval();  // .eval(): the right side reads what the left writes
  if (!isUsableCovariance(*P)) {
    *why = "prior covariance is not positive definite";
    return false;
  }
  return true;
}

StatePrior decodePrior(const filter_state_t& m) {
  StatePrior prior;
  prior.utime = m.utime;
  prior.request_id = m.request_id;
  prior.epoch = m.epoch;
  prior.correction_id = m.correction_id;
  priorFromMessage(m, &prior.x, &prior.P, &prior.problem);  // false: `problem` says why
  prior.body_rate = vec3From(m.angular_velocity);
  prior.message = m;
  return prior;
}

filter_state_t toPosterior(const filter_state_t& prior, const std::string& source, const FilterState& x,
                           const StateCovariance& P, bool valid, int iterations, int num_measurements) {
  filter_state_t m = toFilterState(prior.utime, x, P, prior.request_id, source);
  m.epoch = prior.epoch;
  m.correction_id = prior.correction_id;
  m.valid = valid ? 1 : 0;
  m.iterations = iterations;
  m.num_measurements = num_measurements;
  return m;
}

filter_state_t keptPrior(const filter_state_t& prior, const std::string& source) {
  filter_state_t m = prior;
  m.source = source;
  m.valid = 0;
  m.iterations = 0;
  m.num_measurements = 0;
  return m;
}

}  // namespace livo::vio
