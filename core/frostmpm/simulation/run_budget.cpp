#include "frostmpm/simulation/run_budget.hpp"

#include <unistd.h>

#include <cmath>

namespace frostmpm {

void check_count(const ParamSet& params, const std::string& key, double count, long limit, const std::string& what,
                 const std::string& because) {
  if (std::isfinite(count) && count <= double(limit)) return;
  throw params.error(key, because + " gives " + number_text(count, 3) + " " + what + ", over time.max_steps = " +
                              std::to_string(limit) + "; raise time.max_steps if the run is meant to be this long");
}

std::uintmax_t physical_memory_bytes() {
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
  return pages > 0 && page > 0 ? std::uintmax_t(pages) * std::uintmax_t(page) : 0;
}

std::string bytes_text(double bytes) {
  static const char* units[] = {"B", "kB", "MB", "GB", "TB", "PB"};
  int u = 0;
  while (bytes >= 1000 && u < 5) {
    bytes /= 1000;
    ++u;
  }
  return number_text(bytes, 3) + " " + units[u];
}

}  // namespace frostmpm
