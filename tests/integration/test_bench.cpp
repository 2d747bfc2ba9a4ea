// Smoke tests of the benchmarks in bench/: they run and print what they promise. No timing
// assertions — speed is measured by bench/throughput itself, never by a test.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <set>
#include <string>
#include <vector>

#include "test_support.hpp"

using namespace frostmpm::test;

namespace {

std::string roofline_exe() { return binary_dir() + "/bin/roofline"; }

/// The "checksum" value of a reference kernel's --json line (roofline, elastic_kernel), as printed (17 digits).
std::string kernel_checksum(const std::string& exe, int steps, int threads) {
  const auto r = run_command(exe + " --particles 3000 --steps " + std::to_string(steps) +
                             " --repeat 1 --json --threads " + std::to_string(threads));
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  const auto at = r.output.find("\"checksum\": ");
  REQUIRE(at != std::string::npos);
  return r.output.substr(at + 12, r.output.find('}', at) - at - 12);
}

/// A benchmark's CSV table of 30 000 particles on 1 and 2 threads: one row each, at least
/// `min_steps` scene steps, and every column of `rates` finite and positive.
void check_rate_table(const std::string& path, double min_steps, const std::vector<std::string>& rates) {
  const CsvTable table = read_csv(path);
  REQUIRE(table.rows.size() == 2);
  std::set<double> threads;
  for (const auto& row : table.rows) {
    REQUIRE(row.size() == table.header.size());
    CHECK(row[table.column("particles")] == 30000);
    CHECK(row[table.column("cells_x")] == 150);
    CHECK(row[table.column("cells_y")] == 50);
    CHECK(row[table.column("steps")] >= min_steps);
    threads.insert(row[table.column("threads")]);
    for (const auto& name : rates) {
      const double value = row[table.column(name)];
      INFO(name << " = " << value);
      CHECK(std::isfinite(value));
      CHECK(value > 0);
    }
  }
  CHECK(threads == std::set<double>{1, 2});
}

}  // namespace

TEST_CASE("bench smoke test: throughput --quick prints the table with finite positive rates", "[bench]") {
  TempDir dir;
  // Smallest size, three scene steps, a tiny roofline: a few seconds, exercising every column.
  const auto r = run_command("/usr/bin/python3 " + source_dir() +
                             "/bench/throughput --quick --sizes 30000 --threads 1,2"
                             " --repeat 1 --steps 3 --roofline-work 1e5 --frostmpm " + frostmpm_exe() +
                             " --roofline " + roofline_exe() + " --runs " + dir.file("runs") + " --out " +
                             dir.file("table.csv") + " --baseline " + frostmpm_exe());
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  CHECK(r.output.find("scene p-s/s") != std::string::npos);
  CHECK(r.output.find("vs base") != std::string::npos);
  CHECK(r.output.find("roofline") != std::string::npos);

  // "steps" is positive: the scene ran.
  check_rate_table(dir.file("table.csv"), 1,
                   {"steps", "scene_ps_per_s", "scene_whole_run_ps_per_s", "scene_wall_s", "roofline_ps_per_s", "ratio",
                    "scene_speedup", "roofline_speedup", "roofline_cpu_share", "baseline_ps_per_s", "vs_baseline"});
}

TEST_CASE("bench smoke test: the roofline's checksum is the same on 1 and 2 threads", "[bench]") {
  // Coloured-block P2G and reproducible sums: the same answer bit for bit on any thread count.
  CHECK(kernel_checksum(roofline_exe(), 3, 1) == kernel_checksum(roofline_exe(), 3, 2));
}

TEST_CASE("bench smoke test: the elastic kernel's checksum is the same on 1 and 2 threads", "[bench]") {
  // Enough steps for particles to change blocks (the scatter order is rebuilt), still tiny.
  const std::string exe = binary_dir() + "/bin/elastic_kernel";
  CHECK(kernel_checksum(exe, 40, 1) == kernel_checksum(exe, 40, 2));
}

TEST_CASE("bench smoke test: mechanical_throughput prints the table with finite positive rates", "[bench]") {
  TempDir dir;
  // Smallest size, five scene steps, a tiny kernel run: a few seconds, exercising every column.
  const auto r = run_command("/usr/bin/python3 " + source_dir() +
                             "/bench/mechanical_throughput --sizes 30000 --threads 1,2 --repeat 1 --steps 5"
                             " --kernel-work 1e5 --frostmpm " + frostmpm_exe() + " --kernel " + binary_dir() +
                             "/bin/elastic_kernel --runs " + dir.file("runs") + " --out " + dir.file("table.csv") +
                             " --baseline " + frostmpm_exe());
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  CHECK(r.output.find("scene p-s/s") != std::string::npos);
  CHECK(r.output.find("mechanical.predict") != std::string::npos);
  CHECK(r.output.find("vs base") != std::string::npos);
  check_rate_table(dir.file("table.csv"), 5,
                   {"scene_ps_per_s", "scene_wall_s", "kernel_ps_per_s", "ratio", "scene_speedup", "kernel_speedup",
                    "kernel_cpu_share", "baseline_ps_per_s", "vs_baseline"});
}

TEST_CASE("bench smoke test: throughput says to build first when frostmpm is missing", "[bench]") {
  TempDir dir;
  const auto r = run_command("/usr/bin/python3 " + source_dir() + "/bench/throughput --quick --frostmpm " +
                             dir.file("no-such-frostmpm"));
  CHECK(r.exit_code != 0);
  CHECK(r.output.find("build first") != std::string::npos);
}

namespace {

std::vector<std::string> split(const std::string& text, char separator) {
  std::vector<std::string> parts;
  std::string::size_type start = 0, end;
  while ((end = text.find(separator, start)) != std::string::npos) {
    parts.push_back(text.substr(start, end - start));
    start = end + 1;
  }
  parts.push_back(text.substr(start));
  return parts;
}

}  // namespace

TEST_CASE("bench smoke test: stability --quick --only cell_size=0.01 prints its table and counts", "[bench]") {
  TempDir dir;
  // Two rows (thaw, base cell, explicit and implicit): a few seconds. The format is checked,
  // not the physics: the sweep itself is the place to read results.
  const auto r = run_command("/usr/bin/python3 " + source_dir() +
                             "/bench/stability --quick --only cell_size=0.01 --only case=thaw --frostmpm " +
                             frostmpm_exe() + " --runs " + dir.file("runs") + " --out " + dir.file("table.csv"));
  INFO(r.output);
  REQUIRE((r.exit_code == 0 || r.exit_code == 1));  // 1 = a defect row, still a table
  CHECK(r.output.find("case   parameter") != std::string::npos);
  CHECK(r.output.find("thaw   cell_size          0.01 explicit") != std::string::npos);
  CHECK(r.output.find("thaw   cell_size          0.01 implicit") != std::string::npos);
  // The counts line: three categories adding up to the two runs.
  const auto at = r.output.find(" accurate, ");
  REQUIRE(at != std::string::npos);
  const auto line_start = r.output.rfind('\n', at) + 1;
  int accurate = -1, stopped = -1, defect = -1, runs = -1;
  REQUIRE(std::sscanf(r.output.c_str() + line_start, "%d accurate, %d clean stop, %d defect (%d runs", &accurate,
                      &stopped, &defect, &runs) == 4);
  CHECK(accurate + stopped + defect == 2);
  CHECK(runs == 2);
  CHECK((r.exit_code == 1) == (defect > 0));

  const auto lines = split(read_file(dir.file("table.csv")), '\n');
  REQUIRE(lines.size() >= 3);
  const auto header = split(lines[0], ',');
  CHECK(header == std::vector<std::string>{"case", "parameter", "value", "scheme", "cell_m", "t_end_s", "dt_max_s",
                                           "steps", "result", "front_error", "front_tol", "rmse_of_range",
                                           "rmse_tol", "energy_error_rel", "fields_energy_rel", "wall_s", "notes"});
  std::set<std::string> schemes;
  for (int row = 1; row <= 2; ++row) {
    const auto cells = split(lines[row], ',');
    REQUIRE(cells.size() >= header.size());
    CHECK(cells[0] == "thaw");
    CHECK(cells[1] == "cell_size");
    CHECK(std::stod(cells[2]) == 0.01);
    schemes.insert(cells[3]);
    CHECK(std::set<std::string>{"accurate", "clean stop", "defect"}.count(cells[8]) == 1);
    if (cells[8] == "accurate")  // every measure of an accurate row is a finite number
      for (int c : {4, 5, 6, 7, 9, 10, 11, 12, 13, 14, 15}) {
        INFO(header[c] << " = " << cells[c]);
        CHECK(std::isfinite(std::stod(cells[c])));
      }
  }
  CHECK(schemes == std::set<std::string>{"explicit", "implicit"});
}

TEST_CASE("bench smoke test: stability names the valid keys of a bad --only", "[bench]") {
  const auto r = run_command("/usr/bin/python3 " + source_dir() + "/bench/stability --only cell=0.01 --frostmpm " +
                             frostmpm_exe());
  CHECK(r.exit_code != 0);
  CHECK(r.output.find("cell_size") != std::string::npos);
}

TEST_CASE("bench smoke test: frozen_inclusion prints its row with a thaw time and the INTERFROST range", "[bench]") {
  TempDir dir;
  // Case 3 on a 0.1 m grid (30 × 10 cells): about a second; the format is checked, not the physics.
  const auto r = run_command("/usr/bin/python3 " + source_dir() + "/bench/frozen_inclusion --cases 3 --cells 0.1" +
                             " --frostmpm " + frostmpm_exe() + " --runs " + dir.file("runs") + " --out " +
                             dir.file("table.csv"));
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  CHECK(r.output.find("INTERFROST 13 codes h") != std::string::npos);
  const CsvTable table = read_csv(dir.file("table.csv"));
  REQUIRE(table.rows.size() == 1);
  const auto& row = table.rows[0];
  CHECK(row[table.column("case")] == 3);
  CHECK(row[table.column("cell_m")] == 0.1);
  CHECK(row[table.column("particles")] == 1200);
  CHECK(row[table.column("thaw_h")] > 5);
  CHECK(row[table.column("thaw_h")] < 30);
  CHECK(row[table.column("V_l_end")] == Approx(1.11).epsilon(1e-9));
}
