// Smoke tests of the benchmarks in bench/: they run and print what they promise. No timing
// assertions — speed is measured by bench/throughput itself, never by a test.
#include <catch2/catch.hpp>

#include <cmath>
#include <set>

#include "test_support.hpp"

using namespace frostmpm::test;

namespace {

std::string roofline_exe() { return binary_dir() + "/bin/roofline"; }

/// The "checksum" value of the roofline's --json line, as printed (17 digits).
std::string roofline_checksum(int threads) {
  const auto r = run_command(roofline_exe() + " --particles 3000 --steps 3 --repeat 1 --json --threads " +
                             std::to_string(threads));
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  const auto at = r.output.find("\"checksum\": ");
  REQUIRE(at != std::string::npos);
  return r.output.substr(at + 12, r.output.find('}', at) - at - 12);
}

}  // namespace

TEST_CASE("bench smoke test: throughput --quick prints the table with finite positive rates", "[bench]") {
  TempDir dir;
  // Smallest size, three scene steps, a tiny roofline: a few seconds, exercising every column.
  const auto r = run_command("/usr/bin/python3 " + source_dir() +
                             "/bench/throughput --quick --sizes 30000 --threads 1,2"
                             " --repeat 1 --steps 3 --roofline-work 1e5 --frostmpm " + frostmpm_exe() +
                             " --roofline " + roofline_exe() + " --runs " + dir.file("runs") + " --out " +
                             dir.file("table.csv"));
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  CHECK(r.output.find("scene p-s/s") != std::string::npos);
  CHECK(r.output.find("roofline") != std::string::npos);

  const CsvTable table = read_csv(dir.file("table.csv"));
  REQUIRE(table.rows.size() == 2);
  std::set<double> threads;
  for (const auto& row : table.rows) {
    REQUIRE(row.size() == table.header.size());
    CHECK(row[table.column("particles")] == 30000);
    CHECK(row[table.column("cells_x")] == 150);
    CHECK(row[table.column("cells_y")] == 50);
    threads.insert(row[table.column("threads")]);
    for (const char* name : {"steps", "scene_ps_per_s", "scene_whole_run_ps_per_s", "scene_wall_s", "roofline_ps_per_s",
                             "ratio", "scene_speedup", "roofline_speedup", "roofline_cpu_share"}) {
      const double value = row[table.column(name)];
      INFO(name << " = " << value);
      CHECK(std::isfinite(value));
      CHECK(value > 0);
    }
  }
  CHECK(threads == std::set<double>{1, 2});
}

TEST_CASE("bench smoke test: the roofline's checksum is the same on 1 and 2 threads", "[bench]") {
  // Coloured-block P2G and reproducible sums: the same answer bit for bit on any thread count.
  CHECK(roofline_checksum(1) == roofline_checksum(2));
}

TEST_CASE("bench smoke test: throughput says to build first when frostmpm is missing", "[bench]") {
  TempDir dir;
  const auto r = run_command("/usr/bin/python3 " + source_dir() + "/bench/throughput --quick --frostmpm " +
                             dir.file("no-such-frostmpm"));
  CHECK(r.exit_code != 0);
  CHECK(r.output.find("build first") != std::string::npos);
}
