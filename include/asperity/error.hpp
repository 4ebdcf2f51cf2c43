// The errors the engine raises across its API.
//  - Error: bad input at the API boundary; the message says what was wrong and what to do.
//  - HealthError: the simulation itself went wrong (non-finite values, time step above the
//    critical estimate, runaway energy). The run stops cleanly at the step where it was detected;
//    the state of the world is that of the end of the previous completed step's bookkeeping.
#pragma once
#include <cstdint>
#include <stdexcept>
#include <string>

namespace asperity {

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class HealthError : public Error {
 public:
  HealthError(const std::string& what, std::uint64_t step, std::int64_t particle_id,
              std::string quantity, double value)
      : Error(what), step(step), particle_id(particle_id), quantity(std::move(quantity)),
        value(value) {}
  std::uint64_t step;        // step at which it was detected
  std::int64_t particle_id;  // stable id of the offending particle, -1 if none
  std::string quantity;      // e.g. "velocity", "dt", "kinetic energy"
  double value;
};

}  // namespace asperity
