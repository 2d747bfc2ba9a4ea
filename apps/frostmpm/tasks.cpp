#include "task.hpp"

namespace frostmpm::app {

const std::map<std::string, TaskFactory>& tasks() {
  static const std::map<std::string, TaskFactory> table = {
      {"freezing_curves", make_freezing_curves_task},
      {"simulation", make_simulation_task},
  };
  return table;
}

}  // namespace frostmpm::app
