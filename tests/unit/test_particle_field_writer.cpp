// Particle field output (fields.h5 + fields.xdmf) is checked by reading it back with an
// independent reader, scripts/read_fields.py: it parses the XDMF with xml.etree, resolves every
// DataItem "fields.h5:/path" and reads it with h5py, as a visualiser does. Values must come back
// bit for bit. Python with h5py is a required test dependency (scripts/setup-debian.sh).
#include <catch2/catch.hpp>

#include <charconv>
#include <cmath>
#include <filesystem>
#include <limits>
#include <stdexcept>
#include <string>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

#include "frostmpm/io/particle_field_writer.hpp"
#include "test_support.hpp"

namespace {

using Catch::Matchers::Contains;
using frostmpm::FieldView;
using frostmpm::ParticleFieldWriter;
using frostmpm::test::TempDir;

const std::string kPython = "/usr/bin/python3";

std::string reader_script() { return frostmpm::test::source_dir() + "/scripts/read_fields.py"; }

/// Fails (never skips) when the reader's dependencies are missing.
void require_python_with_h5py() {
  const auto probe = frostmpm::test::run_command(kPython + " -c 'import h5py, numpy'");
  if (probe.exit_code != 0) {
    FAIL(kPython + " cannot import h5py/numpy; run scripts/setup-debian.sh (installs python3-h5py).\n" +
         probe.output);
  }
}

frostmpm::test::CommandResult run_reader(const std::string& dir, const std::string& extra_args = "") {
  return frostmpm::test::run_command(kPython + " " + reader_script() + " '" + dir + "' " + extra_args);
}

/// Shortest decimal text that parses back to exactly `v` (Python's float() does so too).
std::string num(double v) {
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, v);
  return std::string(buffer, result.ptr);
}

/// count x columns values as JSON: a flat list for one column, else a list of rows.
std::string json_array(const std::vector<double>& data, int columns) {
  std::string out = "[";
  const std::size_t rows = data.size() / columns;
  for (std::size_t r = 0; r < rows; ++r) {
    if (r) out += ", ";
    if (columns == 1) {
      out += num(data[r]);
      continue;
    }
    out += "[";
    for (int c = 0; c < columns; ++c) out += (c ? ", " : "") + num(data[r * columns + c]);
    out += "]";
  }
  return out + "]";
}

struct ExpectedField {
  std::string name;
  std::vector<double> values;
  int components;
  std::string type;
  std::string unit;
};

struct ExpectedFrame {
  double time;
  long step;
  std::vector<double> positions;
  int dim;
  std::vector<ExpectedField> fields;

  std::size_t count() const { return positions.size() / dim; }
  std::vector<FieldView> views() const {
    std::vector<FieldView> out;
    for (const auto& f : fields) out.push_back({f.name, f.values.data(), f.components, f.unit});
    return out;
  }
};

std::string expected_json(const std::vector<ExpectedFrame>& frames) {
  std::string out = "{\"frames\": [\n";
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const auto& f = frames[i];
    out += i ? ",\n" : "";
    out += " {\"time\": " + num(f.time) + ", \"step\": " + std::to_string(f.step) +
           ", \"count\": " + std::to_string(f.count()) + ",\n  \"coordinates\": " + json_array(f.positions, f.dim) +
           ",\n  \"fields\": {";
    std::string types, units;
    for (std::size_t k = 0; k < f.fields.size(); ++k) {
      const auto& field = f.fields[k];
      out += (k ? ", " : "") + ("\"" + field.name + "\": ") + json_array(field.values, field.components);
      types += (k ? ", " : "") + ("\"" + field.name + "\": \"" + field.type + "\"");
      units += (k ? ", " : "") + ("\"" + field.name + "\": \"" + field.unit + "\"");
    }
    out += "},\n  \"types\": {" + types + "},\n  \"units\": {" + units + "}}";
  }
  return out + "\n]}\n";
}

/// Writes the expected JSON next to (not inside) the output and runs the reader's check.
frostmpm::test::CommandResult check_with_reader(const TempDir& tmp, const std::string& out_dir,
                                                const std::vector<ExpectedFrame>& frames,
                                                const std::string& json_name = "expected.json") {
  const std::string json_path = tmp.file(json_name);
  frostmpm::test::write_file(json_path, expected_json(frames));
  return run_reader(out_dir, "--check-against '" + json_path + "'");
}

/// A small 2D cloud whose values are awkward doubles (thirds, ulps, tiny and huge magnitudes).
ExpectedFrame cloud_2d(double time, long step, std::size_t count) {
  ExpectedFrame f{time, step, {}, 2, {}};
  ExpectedField T{"T", {}, 1, "Scalar", "degC"}, v{"velocity", {}, 2, "Vector", "m/s"};
  for (std::size_t i = 0; i < count; ++i) {
    const double s = static_cast<double>(i) + time;
    f.positions.push_back(0.1 * s + 1.0 / 3.0);
    f.positions.push_back(std::nextafter(1.0, 2.0) * s - 2.5e-9);
    T.values.push_back(273.15 + 1e-13 * s - time);
    v.values.push_back(-1e-300 * (s + 1.0));
    v.values.push_back(6.02214076e23 / (s + 3.0));
  }
  f.fields = {T, v};
  return f;
}

void write_frame(ParticleFieldWriter& writer, const ExpectedFrame& f) {
  writer.write(f.time, f.step, f.count(), f.positions.data(), f.views());
}

/// Message of the std::runtime_error thrown by `fn`; fails the test if none (or another type) is thrown.
template <class F>
std::string runtime_error_of(F&& fn) {
  try {
    fn();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  FAIL("expected a std::runtime_error");
  return {};
}

}  // namespace

TEST_CASE("ParticleFieldWriter: 2D frames with a changing particle count read back exactly", "[io]") {
  require_python_with_h5py();
  TempDir tmp;
  const std::string out = tmp.file("out");
  const std::vector<ExpectedFrame> frames = {cloud_2d(0.0, 0, 4), cloud_2d(0.25, 10, 7), cloud_2d(1.0 / 3.0, 25, 3)};
  {
    ParticleFieldWriter writer(out, 2);
    REQUIRE(writer.frames() == 0);
    for (const auto& f : frames) write_frame(writer, f);
    REQUIRE(writer.frames() == 3);
  }
  REQUIRE(std::filesystem::exists(out + "/fields.h5"));
  REQUIRE(std::filesystem::exists(out + "/fields.xdmf"));
  REQUIRE_FALSE(std::filesystem::exists(out + "/fields.xdmf.partial"));

  const std::string xdmf = frostmpm::test::read_file(out + "/fields.xdmf");
  CHECK_THAT(xdmf, Contains("CollectionType=\"Temporal\""));
  CHECK_THAT(xdmf, Contains("TopologyType=\"Polyvertex\""));
  CHECK_THAT(xdmf, Contains("GeometryType=\"XYZ\""));
  CHECK_THAT(xdmf, Contains("fields.h5:/step_000025/velocity"));

  const auto ok = check_with_reader(tmp, out, frames);
  INFO(ok.output);
  REQUIRE(ok.exit_code == 0);

  SECTION("the check notices a one-ulp difference") {
    auto changed = frames;
    auto& T = changed[2].fields[0].values;
    T[1] = std::nextafter(T[1], std::numeric_limits<double>::infinity());
    const auto bad = check_with_reader(tmp, out, changed, "changed.json");
    INFO(bad.output);
    REQUIRE(bad.exit_code == 1);
    REQUIRE_THAT(bad.output, Contains("frame 2") && Contains("field T"));
  }
  SECTION("the check notices a wrong unit") {
    auto changed = frames;
    changed[1].fields[1].unit = "m/d";
    const auto bad = check_with_reader(tmp, out, changed, "changed.json");
    INFO(bad.output);
    REQUIRE(bad.exit_code == 1);
    REQUIRE_THAT(bad.output, Contains("frame 1") && Contains("field velocity has units 'm/s', expected 'm/d'"));
  }
  SECTION("the check notices a missing frame and a wrong time") {
    auto changed = frames;
    changed.pop_back();
    changed[1].time = 0.5;
    const auto bad = check_with_reader(tmp, out, changed, "changed.json");
    INFO(bad.output);
    REQUIRE(bad.exit_code == 1);
    REQUIRE_THAT(bad.output, Contains("3 frames") && Contains("time"));
  }
  SECTION("the summary lists every frame") {
    const auto summary = run_reader(out);
    INFO(summary.output);
    REQUIRE(summary.exit_code == 0);
    REQUIRE_THAT(summary.output, Contains("\"name\": \"step_000000\"") && Contains("\"name\": \"step_000010\"") &&
                                     Contains("\"name\": \"step_000025\"") && Contains("\"type\": \"Vector\"") &&
                                     Contains("\"units\": \"degC\""));
  }
}

TEST_CASE("ParticleFieldWriter: frames already written stay readable if the run dies", "[io]") {
  require_python_with_h5py();
  TempDir tmp;
  const std::string out = tmp.file("out");
  const std::vector<ExpectedFrame> frames = {cloud_2d(0.0, 0, 5), cloud_2d(0.5, 1, 6)};

  SECTION("writer still open") {
    ParticleFieldWriter writer(out, 2);
    for (const auto& f : frames) write_frame(writer, f);
    REQUIRE(writer.frames() == 2);
    // The file is still open for writing here, as in a run that is about to crash.
    const auto result = check_with_reader(tmp, out, frames);
    INFO(result.output);
    REQUIRE(result.exit_code == 0);
    REQUIRE_THAT(result.output, Contains("2 frames"));
  }
  SECTION("process killed without closing the file") {
    const pid_t child = fork();
    REQUIRE(child >= 0);
    if (child == 0) {
      int code = 0;
      try {
        ParticleFieldWriter writer(out, 2);
        for (const auto& f : frames) write_frame(writer, f);
      } catch (...) {
        code = 3;
      }
      std::_Exit(code);  // no destructors, no H5Fclose: the files stay as a crash leaves them
    }
    int status = 0;
    REQUIRE(waitpid(child, &status, 0) == child);
    REQUIRE(WIFEXITED(status));
    REQUIRE(WEXITSTATUS(status) == 0);
    const auto result = check_with_reader(tmp, out, frames);
    INFO(result.output);
    REQUIRE(result.exit_code == 0);
  }
}

TEST_CASE("ParticleFieldWriter: non-finite values and bad arguments are refused before writing", "[io]") {
  require_python_with_h5py();
  TempDir tmp;
  const std::string out = tmp.file("out");
  ExpectedFrame good = cloud_2d(0.0, 0, 3);
  ParticleFieldWriter writer(out, 2);

  auto nan_positions = good;
  nan_positions.positions[3] = std::numeric_limits<double>::quiet_NaN();
  REQUIRE_THAT(runtime_error_of([&] { write_frame(writer, nan_positions); }), Contains("positions"));

  auto inf_field = good;
  inf_field.fields[1].values[4] = -std::numeric_limits<double>::infinity();
  REQUIRE_THAT(runtime_error_of([&] { write_frame(writer, inf_field); }), Contains("field 'velocity'"));

  auto bad_name = good;
  bad_name.fields[0].name = "T/K";
  REQUIRE_THROWS_AS(write_frame(writer, bad_name), std::invalid_argument);
  auto reserved = good;
  reserved.fields[0].name = "coordinates";
  REQUIRE_THROWS_AS(write_frame(writer, reserved), std::invalid_argument);
  auto twice = good;
  twice.fields[1].name = "T";
  REQUIRE_THROWS_AS(write_frame(writer, twice), std::invalid_argument);
  auto no_components = good;
  no_components.fields[0].components = 0;
  REQUIRE_THROWS_AS(write_frame(writer, no_components), std::invalid_argument);
  for (const char* unit : {"", "deg\nC"}) {
    auto bad_unit = good;
    bad_unit.fields[0].unit = unit;
    REQUIRE_THROWS_AS(write_frame(writer, bad_unit), std::invalid_argument);
  }
  REQUIRE_THROWS_AS(ParticleFieldWriter(tmp.file("other"), 1), std::invalid_argument);

  REQUIRE(writer.frames() == 0);
  write_frame(writer, good);
  REQUIRE_THROWS_AS(write_frame(writer, good), std::invalid_argument);  // step 0 again
  REQUIRE(writer.frames() == 1);

  // The refused frames left nothing behind: the output holds exactly the good frame.
  const auto result = check_with_reader(tmp, out, {good});
  INFO(result.output);
  REQUIRE(result.exit_code == 0);
}

TEST_CASE("ParticleFieldWriter: 3D fields map to XDMF Scalar, Vector, Tensor6, Tensor and Matrix", "[io]") {
  require_python_with_h5py();
  TempDir tmp;
  const std::string out = tmp.file("out");
  const std::size_t count = 5;
  ExpectedFrame f{2.5e-3, 7, {}, 3, {}};
  for (std::size_t i = 0; i < count * 3; ++i) f.positions.push_back(std::sqrt(static_cast<double>(i) + 0.5));
  const std::vector<std::pair<int, std::string>> layouts = {
      {1, "Scalar"}, {3, "Vector"}, {6, "Tensor6"}, {9, "Tensor"}, {4, "Matrix"}, {2, "Vector"}};
  for (const auto& [components, type] : layouts) {
    ExpectedField field{"f" + std::to_string(components), {}, components, type, "kg/(m^3 s)"};
    for (std::size_t i = 0; i < count * components; ++i) field.values.push_back(1.0 / (i + components + 1.0));
    f.fields.push_back(field);
  }
  {
    ParticleFieldWriter writer(out, 3);
    write_frame(writer, f);
    REQUIRE(writer.frames() == 1);
  }
  const auto result = check_with_reader(tmp, out, {f});
  INFO(result.output);
  REQUIRE(result.exit_code == 0);
}

TEST_CASE("ParticleFieldWriter: reopen keeps the first frames in step order, drops the rest, appends", "[io]") {
  require_python_with_h5py();
  TempDir tmp;
  const std::string out = tmp.file("out");
  // Group names sort by step only up to six digits: step_1000000 comes before step_999999.
  const std::vector<ExpectedFrame> frames = {cloud_2d(0.0, 0, 4), cloud_2d(0.5, 999999, 5),
                                             cloud_2d(0.75, 1000000, 6), cloud_2d(0.875, 1000001, 2)};
  {
    ParticleFieldWriter writer(out, 2);
    for (const auto& f : frames) write_frame(writer, f);
  }
  const ExpectedFrame later = cloud_2d(1.0, 1000002, 3);
  {
    ParticleFieldWriter writer = ParticleFieldWriter::reopen(out, 2, 2);
    REQUIRE(writer.frames() == 2);
    // The xdmf lists the kept frames at once, as after any write.
    const auto kept = check_with_reader(tmp, out, {frames[0], frames[1]});
    INFO(kept.output);
    REQUIRE(kept.exit_code == 0);
    REQUIRE_THROWS_AS(write_frame(writer, frames[1]), std::invalid_argument);  // kept: already written
    write_frame(writer, frames[2]);  // dropped: its step can be written again
    write_frame(writer, later);
    REQUIRE(writer.frames() == 4);
  }
  const auto result = check_with_reader(tmp, out, {frames[0], frames[1], frames[2], later});
  INFO(result.output);
  REQUIRE(result.exit_code == 0);

  REQUIRE_THAT(runtime_error_of([&] { ParticleFieldWriter::reopen(out, 2, 5); }), Contains("fewer than the 5"));
  REQUIRE_THAT(runtime_error_of([&] { ParticleFieldWriter::reopen(out, 3, 1); }), Contains("2-D frames, not 3-D"));
  REQUIRE_THAT(runtime_error_of([&] { ParticleFieldWriter::reopen(tmp.file("nowhere"), 2, 0); }),
               Contains("nowhere/fields.h5"));
}

TEST_CASE("ParticleFieldWriter: reopen drops a frame whose object header a kill left broken, the rest readable",
          "[io]") {
  require_python_with_h5py();
  TempDir tmp;
  const std::string out = tmp.file("out");
  const std::vector<ExpectedFrame> frames = {cloud_2d(0.0, 0, 4), cloud_2d(0.5, 10, 5), cloud_2d(0.75, 20, 6)};
  {
    ParticleFieldWriter writer(out, 2);
    for (const auto& f : frames) write_frame(writer, f);
  }
  // The newest frame's group header overwritten, as a SIGKILL while it is written can leave it:
  // its link is there, the object it names cannot be read (nor its link deleted: HDF5 updates
  // the object's header for that).
  const std::string h5 = out + "/fields.h5";
  const auto broken = frostmpm::test::run_command(
      kPython + " -c \"import h5py; f = h5py.File('" + h5 +
      "', 'r'); a = h5py.h5o.get_info(f['step_000020'].id).addr; f.close(); g = open('" + h5 +
      "', 'r+b'); g.seek(a); g.write(b'\\xff' * 16); g.close()\"");
  INFO(broken.output);
  REQUIRE(broken.exit_code == 0);
  {
    ParticleFieldWriter writer = ParticleFieldWriter::reopen(out, 2, 2);
    REQUIRE(writer.frames() == 2);
    write_frame(writer, frames[2]);  // the broken frame's step, written again
  }
  const auto result = check_with_reader(tmp, out, frames);
  INFO(result.output);
  REQUIRE(result.exit_code == 0);
}
