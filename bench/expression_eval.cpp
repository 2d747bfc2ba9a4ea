// Expression evaluation speed: ns per evaluate() of a typical boundary-condition expression,
// one thread and all OpenMP threads (each thread evaluates its own share, as particle loops do).
//   ./build/bin/expression_eval [--expression TEXT] [--evaluations N]
#include <chrono>
#include <cstdio>
#include <string>

#include <CLI/CLI.hpp>
#include <omp.h>

#include "frostmpm/scene/expression.hpp"

int main(int argc, char** argv) {
  CLI::App app{"Expression evaluation speed"};
  std::string text = "5 + 2*sin(2*pi*t/86400)";
  long n = 20'000'000;
  app.add_option("--expression", text, "expression of t");
  app.add_option("--evaluations", n, "evaluations per measurement");
  CLI11_PARSE(app, argc, argv);

  const frostmpm::Expression e = frostmpm::Expression::compile(text, {"t"});
  for (int threads : {1, omp_get_max_threads()}) {
    double best = 1e300, sum = 0;
    for (int repeat = 0; repeat < 5; ++repeat) {
      const auto start = std::chrono::steady_clock::now();
      double local_sum = 0;
#pragma omp parallel for num_threads(threads) reduction(+ : local_sum)
      for (long i = 0; i < n; ++i) local_sum += e(static_cast<double>(i));
      const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      best = s < best ? s : best;
      sum += local_sum;
    }
    std::printf("%-28s threads %d  %.2f ns/evaluation (best of 5, %ld evaluations; checksum %.6g)\n",
                text.c_str(), threads, best * 1e9 / static_cast<double>(n) * threads, n, sum);
    if (threads == omp_get_max_threads()) break;
  }
  return 0;
}
