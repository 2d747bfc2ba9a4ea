// The `frostmpm` command: run, check, plugins, describe, test-model.
#include <charconv>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <optional>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <omp.h>

#include "frostmpm/config/input_error.hpp"
#include "frostmpm/parallel/parallel.hpp"
#include "frostmpm/io/checkpoint.hpp"
#include "frostmpm/io/log.hpp"
#include "frostmpm/linalg/mpi_session.hpp"
#include "frostmpm/scene/plugin_setup.hpp"
#include "frostmpm/simulation/interrupt.hpp"
#include "frostmpm/simulation/simulation.hpp"
#include "reference.hpp"
#include "run_summary.hpp"
#include "task.hpp"
#include "test_model.hpp"

namespace fs = std::filesystem;
using namespace frostmpm;

namespace {

struct SceneOptions {
  std::string scene;
  std::vector<std::string> overrides;
  std::vector<std::string> plugin_paths;
};

void add_scene_options(CLI::App* cmd, SceneOptions& o, bool scene_required) {
  cmd->add_option("scene", o.scene, "scene file (YAML)")->required(scene_required);
  // One value per --set / --plugin-path (repeat the option), so the scene may come before or
  // after them.
  cmd->add_option("--set", o.overrides, "override a scene value by its YAML path: path.to.key=value (repeatable)")
      ->allow_extra_args(false)
      ->take_all();
  cmd->add_option("--plugin-path", o.plugin_paths, "extra plugin folder or library (repeatable)")
      ->allow_extra_args(false)
      ->take_all();
}

/// The scene as given on the command line, in the form a checkpoint keeps: absolute paths, so
/// a restart from another folder finds the same plugins.
SceneSource scene_source(const SceneOptions& o) {
  SceneSource source;
  source.text = ConfigNode::read_file(o.scene);
  source.path = fs::absolute(o.scene).lexically_normal().string();
  source.overrides = o.overrides;
  for (const auto& path : o.plugin_paths) source.plugin_paths.push_back(fs::absolute(path).lexically_normal().string());
  return source;
}

/// `word` as one shell word (quoted only when it needs to be).
std::string shell_word(const std::string& word) {
  if (!word.empty() && word.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_./-+=:,@%") ==
                           std::string::npos)
    return word;
  std::string quoted = "'";
  for (const char c : word) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

/// Everything up to (not including) execution: parse, override, load plugins, validate.
struct PreparedScene {
  Registry registry;
  std::unique_ptr<PluginLoader> loader;
  std::unique_ptr<ConfigNode> root;
  std::unique_ptr<app::Task> task;
  std::string task_name;
  YAML::Node resolved;
};

/// `scene_name` is what messages call the scene file (the path as the user typed it).
std::unique_ptr<PreparedScene> prepare(const SceneSource& source, const std::string& scene_name) {
  auto prepared = std::make_unique<PreparedScene>();
  ConfigNode file_root = ConfigNode::load_string(source.text, scene_name);
  YAML::Node tree = file_root.raw();
  for (const auto& assignment : source.overrides) apply_override(tree, assignment);
  prepared->root = std::make_unique<ConfigNode>(tree, scene_name);
  prepared->root->set_overrides(source.overrides);
  const ConfigNode& root = *prepared->root;

  prepared->loader = std::make_unique<PluginLoader>(prepared->registry);
  PluginSetup setup{source.plugin_paths};
  setup.load_defaults(*prepared->loader);
  setup.load_scene_paths(*prepared->loader, root);
  for (const auto& warning : refusal_warnings(*prepared->loader)) log::warning(warning);
  for (const auto& p : prepared->loader->loaded())
    log::debug("plugin " + p.name + " " + p.version + " from " + p.file);

  std::vector<std::string> task_names;
  for (const auto& [name, _] : app::tasks()) task_names.push_back(name);
  const ConfigNode task_node = root.child("task");
  prepared->task_name = task_node.as_string();
  const auto it = app::tasks().find(prepared->task_name);
  if (it == app::tasks().end()) {
    throw task_node.error("unknown task '" + prepared->task_name + "'" + did_you_mean(prepared->task_name, task_names) +
                          " Valid: " + join(task_names));
  }
  prepared->task = it->second(app::TaskContext{prepared->registry, *prepared->loader, root});
  std::vector<std::string> valid = {"task", "plugin_paths"};
  for (const auto& s : prepared->task->sections()) valid.push_back(s);
  root.finish(valid);

  prepared->resolved = YAML::Node(YAML::NodeType::Map);
  prepared->resolved["task"] = prepared->task_name;
  for (const auto& kv : prepared->task->resolved()) prepared->resolved[kv.first] = kv.second;
  return prepared;
}

nlohmann::json to_json(const YAML::Node& node) {
  switch (node.Type()) {
    case YAML::NodeType::Map: {
      nlohmann::json j = nlohmann::json::object();
      for (const auto& kv : node) j[kv.first.as<std::string>()] = to_json(kv.second);
      return j;
    }
    case YAML::NodeType::Sequence: {
      nlohmann::json j = nlohmann::json::array();
      for (const auto& item : node) j.push_back(to_json(item));
      return j;
    }
    case YAML::NodeType::Scalar: {
      const std::string& text = node.Scalar();
      double number = 0;
      bool flag = false;
      // Whole numbers (counts, steps, sample numbers) stay JSON integers: 601, not 601.0.
      long long whole = 0;
      const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), whole);
      if (node.Tag() != "!" && !text.empty() && ec == std::errc() && end == text.data() + text.size()) return whole;
      if (node.Tag() != "!" && YAML::convert<double>::decode(node, number)) return number;
      if (node.Tag() != "!" && YAML::convert<bool>::decode(node, flag)) return flag;
      return text;
    }
    default: return nullptr;
  }
}

/// A new run into a folder that holds another run's results would replace them without a word:
/// refused unless `overwrite` (then the new run replaces them file by file, as it writes).
void refuse_earlier_results(const std::string& dir, bool overwrite, const std::string& program) {
  if (overwrite) {  // the new run replaces the rest as it writes; an old checkpoint would outlive it
    std::error_code ec;
    fs::remove(fs::path(dir) / "checkpoint.h5", ec);
    return;
  }
  std::vector<std::string> found;
  for (const char* name : {"run.json", "metrics.csv", "fields.h5", "fields.xdmf", "checkpoint.h5"}) {
    std::error_code ec;
    if (fs::exists(fs::path(dir) / name, ec)) found.push_back(name);
  }
  if (found.empty()) return;
  std::string listed;
  for (const auto& name : found) listed += (listed.empty() ? "" : ", ") + name;
  const bool resumable = std::find(found.begin(), found.end(), "checkpoint.h5") != found.end();
  throw InputError(dir + ": holds the results of an earlier run (" + listed + "); give another -o, add --overwrite " +
                   "to replace them" +
                   (resumable ? ", or continue that run with: " + shell_word(program) + " run --restart " + shell_word(dir) +
                                 " (if it finished, with --set time.end=LATER)"
                              : std::string()));
}

/// `frostmpm run`: a new run of `o.scene`, or with `restart_dir` the continuation of the run
/// in that folder from its checkpoint (which holds the scene, overrides and plugin paths).
int cmd_run(const SceneOptions& o, const std::string& out_dir, const std::string& restart_dir, bool overwrite,
            const std::string& program) {
  const auto start = std::chrono::steady_clock::now();
  const bool restart = !restart_dir.empty();
  if (restart && (!o.scene.empty() || !out_dir.empty() || !o.plugin_paths.empty() || overwrite))
    throw InputError("--restart OUT takes no scene, -o, --plugin-path or --overwrite: the checkpoint in OUT holds them");
  if (!restart && o.scene.empty()) throw InputError("give a scene file to run, or --restart OUT to continue a run");
  SceneSource source = restart ? CheckpointReader(restart_dir).scene() : scene_source(o);
  if (restart) {
    // Only what may change between two parts of one run: its end and how often it writes.
    // Anything else would make the continued run differ from the same run made in one go.
    static const std::vector<std::string> changeable = {
        "time.end", "output.every", "output.metrics_every", "output.progress",
        "checkpoint.every_steps", "checkpoint.every_minutes", "checkpoint.at_end"};
    for (const auto& assignment : o.overrides) {
      const std::string key = assignment.substr(0, assignment.find('='));
      if (std::find(changeable.begin(), changeable.end(), key) == changeable.end())
        throw InputError("--set " + assignment + ": a restart may change only " + join(changeable) +
                         "; other keys would make the continued run differ from one made in one go (start a new "
                         "run with -o instead)");
      source.overrides.push_back(assignment);
    }
  }
  auto prepared = prepare(source, restart ? source.path : o.scene);
  const std::string dir =
      restart ? restart_dir : out_dir.empty() ? "frostmpm-out/" + fs::path(o.scene).stem().string() : out_dir;
  if (!restart) refuse_earlier_results(dir, overwrite, program);
  OutputDir out(dir);
  log::debug("task '" + prepared->task_name + "' on " + std::to_string(thread_count()) + " thread(s), output in " + dir);
  std::optional<RunInterrupted> interrupted;
  try {
    const InterruptGuard stop_cleanly_on_sigint_and_sigterm;
    prepared->task->execute(out, app::RunRequest{source, restart});
  } catch (const NumericalBlowUp& e) {
    log::error(std::string(e.what()) + "; the frames written before it in " + dir + " stay readable");
    return kBlowUpExitCode;
  } catch (const RunInterrupted& e) {
    interrupted = e;
  }

  nlohmann::json summary;
  summary["frostmpm_version"] = FROSTMPM_VERSION;
  summary["scene"] = restart ? source.path : o.scene;
  summary["task"] = prepared->task_name;
  summary["status"] = interrupted ? "interrupted" : "finished";
  summary["overrides"] = source.overrides;
  summary["plugins"] = nlohmann::json::array();
  for (const auto& p : prepared->loader->loaded())
    summary["plugins"].push_back({{"name", p.name}, {"version", p.version}, {"library", p.file}});
  summary["resolved_scene"] = to_json(prepared->resolved);
  summary["run"] = to_json(prepared->task->summary());
  // The CSV keeps its one header line (what spreadsheets and pandas read); its units are here.
  if (const auto units = prepared->task->metrics_units(); !units.empty()) {
    summary["metrics_units"] = nlohmann::json::object();
    for (const auto& [column, unit] : units) summary["metrics_units"][column] = unit;
  }
  summary["threads"] = thread_count();
  // MPI is linked (Trilinos needs it) but runs are not distributed: one rank, initialized only
  // when a sparse solver ran.
  summary["mpi"] = {{"library", mpi_library_version()}, {"ranks", 1}, {"initialized", mpi_is_active()}};
  summary["wall_seconds"] =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  out.write_text("run.json", summary.dump(2) + "\n");
  if (interrupted) {
    std::ostringstream message;
    message << std::setprecision(10) << "interrupted at t = " << interrupted->time << " s (step " << interrupted->step
            << "); resume with: " << shell_word(program) << " run --restart " << shell_word(dir);
    log::write(log::Level::warning, message.str());
    return 128 + interrupted->signal;
  }
  log::info(app::run_summary(summary, dir));
  return 0;
}

int cmd_check(const SceneOptions& o) {
  auto prepared = prepare(scene_source(o), o.scene);
  YAML::Emitter emitter;
  emitter << prepared->resolved;
  std::cout << "# " << o.scene << ": valid. Resolved scene with defaults:\n" << emitter.c_str() << "\n";
  // The resolved step as YAML comments, so that the output stays a loadable scene.
  std::istringstream step(prepared->task->step_description());
  for (std::string line; std::getline(step, line);) std::cout << "# " << line << "\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  // A file-size limit (ulimit -f) is a full disk to us: the write fails with EFBIG and the
  // output code reports it in one line, instead of SIGXFSZ killing the run.
  std::signal(SIGXFSZ, SIG_IGN);
  CLI::App cli{"FrostMPM — thermo-hydro-mechanical material point method for freezing and thawing ground"};
  cli.require_subcommand(1);
  cli.set_version_flag("--version", std::string(FROSTMPM_VERSION) + " (" + mpi_library_version() +
                                        " linked, runs on one rank; OpenMP: " + std::to_string(thread_count()) +
                                        " threads by default)");

  SceneOptions run_options, check_options;
  std::string out_dir, restart_dir;
  auto* run = cli.add_subcommand("run", "run a scene, or continue a stopped run with --restart OUT");
  add_scene_options(run, run_options, /*scene_required=*/false);  // not with --restart
  run->add_option("-o,--output", out_dir, "output folder (default: frostmpm-out/<scene name>)");
  bool overwrite = false;
  run->add_flag("--overwrite", overwrite, "replace the results of an earlier run in the output folder");
  run->add_option("--restart", restart_dir,
                  "continue the run in folder OUT from OUT/checkpoint.h5, appending to its outputs; the "
                  "checkpoint holds the scene, overrides and plugin paths, and --set may change only "
                  "time.end (extending a finished run), output and checkpoint frequencies")
      ->type_name("OUT");
  int threads = 0;
  run->add_option("--threads", threads,
                  "OpenMP threads for particle and node loops (default: OMP_NUM_THREADS, else every core); "
                  "results do not depend on it")
      ->check(CLI::Range(1, 1024));
  bool quiet = false, verbose = false;
  auto* quiet_flag = run->add_flag("-q,--quiet", quiet, "print warnings and errors only (no progress or info lines)");
  run->add_flag("-v,--verbose", verbose, "also print debug lines (plugins loaded, threads, output folder)")
      ->excludes(quiet_flag);

  auto* check = cli.add_subcommand("check", "validate a scene and print it with defaults filled in");
  add_scene_options(check, check_options, /*scene_required=*/true);

  std::vector<std::string> list_paths;
  auto* plugins = cli.add_subcommand("plugins", "list every registered model by kind, with library and version");
  plugins->add_option("--plugin-path", list_paths, "extra plugin folder or library (repeatable)")
      ->allow_extra_args(false)
      ->take_all();

  std::string describe_target;
  bool markdown = false;
  std::vector<std::string> describe_paths;
  auto* describe = cli.add_subcommand("describe", "show a model's parameters: units, defaults, ranges, docs");
  describe->add_option("target", describe_target, "KIND/NAME (e.g. sfcc/exponential), KIND, a kernel section (grid, time, output, checkpoint), or 'all'")
      ->required();
  describe->add_flag("--markdown", markdown, "print Markdown (used to generate docs/config-reference.md)");
  describe->add_option("--plugin-path", describe_paths, "extra plugin folder or library (repeatable)")
      ->allow_extra_args(false)
      ->take_all();

  app::TestModelOptions test_model_options;
  auto* test_model = cli.add_subcommand(
      "test-model", "check a model's contract by sampling it (bounds, monotonicity, derivatives, continuity, objectivity); "
                    "exit 1 with one line per violation");
  test_model->add_option("target", test_model_options.target, "KIND/NAME, e.g. sfcc/exponential")->required();
  test_model->add_option("--set", test_model_options.settings,
                         "a model parameter: name=value (repeatable; required ones not given are picked inside their range)")
      ->allow_extra_args(false)
      ->take_all();
  test_model->add_option("--plugin-path", test_model_options.plugin_paths, "extra plugin folder or library (repeatable)")
      ->allow_extra_args(false)
      ->take_all();
  test_model->add_option("--temperature-range", test_model_options.temperature_range,
                         "SFCC: sampled temperatures LO HI in degC (default: freezing point -10 to +2)")
      ->expected(2);
  test_model->add_option("--samples", test_model_options.samples, "sample points, or states of a mechanical model (default 2001)")
      ->check(CLI::Range(2, 10000000));

  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version exit 0; a malformed command line is bad input like any other.
    const int code = cli.exit(e);
    return code == 0 ? 0 : kInputErrorExitCode;
  }
  try {
    refuse_multiple_ranks();
    if (*run) {
      if (threads > 0) omp_set_num_threads(threads);
      if (quiet) log::set_level(log::Level::warning);
      if (verbose) log::set_level(log::Level::debug);
      return cmd_run(run_options, out_dir, restart_dir, overwrite, argv[0]);
    }
    if (*check) return cmd_check(check_options);
    if (*plugins) return app::cmd_plugins(list_paths, std::cout);
    if (*describe) return app::cmd_describe(describe_target, markdown, describe_paths, std::cout);
    if (*test_model) return app::cmd_test_model(test_model_options, std::cout);
  } catch (const InputError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kInputErrorExitCode;
  } catch (const std::exception& e) {
    std::cerr << "internal error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
