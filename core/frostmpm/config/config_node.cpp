#include "frostmpm/config/config_node.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <unordered_map>
#include <vector>

#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/parser.h>

#include "frostmpm/config/units.hpp"

namespace frostmpm {

namespace {

/// Scene files above this size are refused before reading: no scene is near it, and a
/// device such as /dev/zero would otherwise be read until memory runs out.
constexpr std::uintmax_t kMaxSceneBytes = 16u << 20;

/// Aliases (*name) repeat an anchored node (&name) wherever they stand: nested a few levels, a
/// few hundred bytes expand to billions of nodes (the "billion laughs"), and walking such a
/// scene never ends. A scene has thousands of nodes at most, so the expanded count is bounded.
constexpr double kMaxExpandedNodes = 1e6;

/// Counts the nodes of a document as if every alias were written out, from the parser's events
/// (nothing is built), and throws InputError at the first event past kMaxExpandedNodes.
class ExpansionCounter final : public YAML::EventHandler {
 public:
  explicit ExpansionCounter(std::string name) : name_(std::move(name)) {}
  void OnDocumentStart(const YAML::Mark&) override {}
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark& mark, YAML::anchor_t anchor) override { leaf(mark, anchor); }
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t anchor) override {
    const auto it = size_.find(anchor);
    add(mark, it == size_.end() ? 1.0 : it->second);
  }
  void OnScalar(const YAML::Mark& mark, const std::string&, YAML::anchor_t anchor, const std::string&) override {
    leaf(mark, anchor);
  }
  void OnSequenceStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t anchor,
                       YAML::EmitterStyle::value) override {
    open(mark, anchor);
  }
  void OnSequenceEnd() override { close(); }
  void OnMapStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t anchor, YAML::EmitterStyle::value) override {
    open(mark, anchor);
  }
  void OnMapEnd() override { close(); }

 private:
  void add(const YAML::Mark& mark, double nodes) {
    count_ += nodes;
    if (count_ > kMaxExpandedNodes)
      throw InputError(SourceLocation{name_, "", mark.line + 1, mark.column + 1},
                       "the scene's aliases (*name) expand it to more than 1000000 YAML nodes; write the repeated "
                       "values out or use fewer nested aliases");
  }
  void leaf(const YAML::Mark& mark, YAML::anchor_t anchor) {
    add(mark, 1.0);
    if (anchor != YAML::NullAnchor) size_[anchor] = 1.0;
  }
  void open(const YAML::Mark& mark, YAML::anchor_t anchor) {
    open_.push_back({anchor, count_});
    add(mark, 1.0);
  }
  void close() {
    const auto [anchor, before] = open_.back();
    open_.pop_back();
    if (anchor != YAML::NullAnchor) size_[anchor] = count_ - before;
  }
  std::string name_;
  double count_ = 0;
  std::unordered_map<YAML::anchor_t, double> size_;
  std::vector<std::pair<YAML::anchor_t, double>> open_;
};

void check_alias_expansion(const std::string& text, const std::string& name) {
  if (text.find('*') == std::string::npos) return;  // no alias: nothing to expand
  std::istringstream in(text);
  YAML::Parser parser(in);
  ExpansionCounter counter(name);
  while (parser.HandleNextDocument(counter)) {
  }
}

/// yaml-cpp keeps the first of two equal keys and drops the second silently: refuse both,
/// naming their lines, anywhere in the tree.
void reject_duplicate_keys(const YAML::Node& node, const std::string& file, const std::string& path) {
  auto sub = [&](const std::string& key) { return path.empty() ? key : path + "." + key; };
  if (node.IsMap()) {
    std::map<std::string, YAML::Mark> seen;
    for (const auto& kv : node) {
      const std::string key = kv.first.IsScalar() ? kv.first.Scalar() : std::string("<non-scalar key>");
      const auto [first, inserted] = seen.emplace(key, kv.first.Mark());
      if (!inserted) {
        const YAML::Mark m = kv.first.Mark();
        const std::string first_line = first->second.is_null() ? "?" : std::to_string(first->second.line + 1);
        throw InputError(SourceLocation{file, sub(key), m.is_null() ? 0 : m.line + 1, m.is_null() ? 0 : m.column + 1},
                         "duplicate key '" + key + "' (first on line " + first_line +
                             "); a key may appear once per section");
      }
      reject_duplicate_keys(kv.second, file, sub(key));
    }
  } else if (node.IsSequence()) {
    std::size_t i = 0;
    for (const auto& item : node) reject_duplicate_keys(item, file, sub(std::to_string(i++)));
  }
}

}  // namespace

ConfigNode::ConfigNode(YAML::Node node, std::string file, std::string path)
    : node_(std::move(node)),
      file_(std::move(file)),
      path_(std::move(path)),
      consumed_(std::make_shared<std::set<std::string>>()),
      asked_(std::make_shared<std::set<std::string>>()) {}

ConfigNode ConfigNode::load_file(const std::string& file) { return load_string(read_file(file), file); }

std::string ConfigNode::read_file(const std::string& file) {
  std::error_code ec;
  if (!std::filesystem::exists(file, ec))
    throw InputError(file + ": scene file does not exist");
  if (std::filesystem::is_directory(file, ec))
    throw InputError(file + ": is a directory, expected a YAML scene file");
  if (!std::filesystem::is_regular_file(file, ec))
    throw InputError(file + ": is not a regular file (a device or pipe), expected a YAML scene file");
  if (std::filesystem::file_size(file, ec) > kMaxSceneBytes)
    throw InputError(file + ": is larger than " + std::to_string(kMaxSceneBytes >> 20) +
                     " MB, too large for a YAML scene file");
  std::ifstream in(file);
  if (!in) throw InputError(file + ": cannot be read");
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

ConfigNode ConfigNode::load_string(const std::string& text, const std::string& name) {
  try {
    check_alias_expansion(text, name);
    YAML::Node root = YAML::Load(text);
    if (!root.IsMap())
      throw InputError(name + ": a scene must be a YAML mapping of sections (key: value)");
    reject_duplicate_keys(root, name, "");
    return ConfigNode(root, name, "");
  } catch (const YAML::ParserException& e) {
    SourceLocation where{name, "", e.mark.line + 1, e.mark.column + 1};
    throw InputError(where, "malformed YAML: " + e.msg);
  }
}

void ConfigNode::set_overrides(std::vector<std::string> assignments) {
  overrides_ = std::make_shared<const std::vector<std::string>>(std::move(assignments));
}

ConfigNode ConfigNode::with(YAML::Node node, std::string path) const {
  ConfigNode out(std::move(node), file_, std::move(path));
  out.overrides_ = overrides_;
  return out;
}

SourceLocation ConfigNode::where() const {
  // The last override whose path is this node or one of its parents gave this node's value.
  if (overrides_)
    for (auto it = overrides_->rbegin(); it != overrides_->rend(); ++it) {
      const std::string target = it->substr(0, it->find('='));
      if (path_ == target || path_.rfind(target + ".", 0) == 0) return SourceLocation{"--set " + *it, path_, 0, 0};
    }
  SourceLocation loc{file_, path_, 0, 0};
  if (node_ && node_.Mark().line >= 0 && !node_.Mark().is_null()) {
    loc.line = node_.Mark().line + 1;
    loc.column = node_.Mark().column + 1;
  }
  return loc;
}

std::string ConfigNode::child_path(const std::string& key) const {
  return path_.empty() ? key : path_ + "." + key;
}

bool ConfigNode::has(const std::string& key) const {
  asked_->insert(key);
  return node_.IsMap() && node_[key].IsDefined();
}

std::vector<std::string> ConfigNode::keys() const {
  std::vector<std::string> out;
  if (!node_.IsMap()) return out;
  for (const auto& kv : node_) out.push_back(kv.first.as<std::string>());
  return out;
}

ConfigNode ConfigNode::child(const std::string& key) const {
  if (!node_.IsMap()) throw error("expected a mapping containing '" + key + "'");
  const YAML::Node c = node_[key];
  if (!c.IsDefined()) {
    SourceLocation loc = where();
    throw InputError(loc, "missing required key '" + key + "'");
  }
  consumed_->insert(key);
  return with(c, child_path(key));
}

std::optional<ConfigNode> ConfigNode::optional_child(const std::string& key) const {
  if (!has(key)) return std::nullopt;
  return child(key);
}

void ConfigNode::finish(const std::vector<std::string>& valid_keys) const {
  if (!node_.IsMap()) return;
  std::vector<std::string> unread;
  for (const auto& kv : node_)
    if (!consumed_->count(kv.first.as<std::string>())) unread.push_back(kv.first.as<std::string>());
  // Keys read or asked for by whoever owns this section (a physics reading a boundary
  // condition) are valid here too, besides those the caller lists.
  std::vector<std::string> valid = valid_keys;
  for (const auto* set : {consumed_.get(), asked_.get()})
    for (const auto& key : *set)
      if (std::find(valid.begin(), valid.end(), key) == valid.end()) valid.push_back(key);
  if (!unread.empty()) reject_unknown(valid);
  // Keys that are valid but unread are a programming error in the reader, not user input.
  for (const auto& key : unread)
    if (std::find(valid_keys.begin(), valid_keys.end(), key) != valid_keys.end())
      throw std::logic_error("scene key '" + child_path(key) + "' is valid but was never read");
}

void ConfigNode::reject_unknown(const std::vector<std::string>& valid_keys) const {
  if (!node_.IsMap()) return;
  for (const auto& kv : node_) {
    const std::string key = kv.first.as<std::string>();
    if (std::find(valid_keys.begin(), valid_keys.end(), key) != valid_keys.end()) continue;
    const ConfigNode offending = with(kv.first, child_path(key));  // keeps --set origins
    std::string message = "unknown key '" + key + "'" + did_you_mean(key, valid_keys);
    message += " Valid keys here: " + (valid_keys.empty() ? std::string("(none)") : join(valid_keys));
    throw offending.error(message);
  }
}

std::vector<ConfigNode> ConfigNode::elements() const {
  if (!node_.IsSequence()) throw error("expected a list");
  std::vector<ConfigNode> out;
  std::size_t i = 0;
  for (const auto& item : node_) out.push_back(with(item, child_path(std::to_string(i++))));
  return out;
}

namespace {
std::string scalar_text(const YAML::Node& n) { return n.IsScalar() ? n.Scalar() : std::string("<non-scalar>"); }
}  // namespace

double ConfigNode::as_real(const std::string& unit) const {
  if (!node_.IsScalar()) throw error("expected a number");
  const std::string text = scalar_text(node_);
  double value = 0;
  if (YAML::convert<double>::decode(node_, value)) {
    if (!std::isfinite(value)) throw error("expected a finite number, got '" + text + "'");
    return value;
  }
  const auto quantity = units::split(text);
  if (!quantity)
    throw error("expected a number" + std::string(unit.empty() || unit == "-" ? "" : " (in " + unit + ", or with its unit)") +
                ", got '" + text + "'");
  try {
    value = units::convert(*quantity, unit);
  } catch (const units::UnitError& e) {
    throw error(e.what());
  }
  if (!std::isfinite(value)) throw error("expected a finite number, got '" + text + "'");
  // The tree now says what was read: the number in the declared unit. A string assignment keeps
  // the node's mark (its line in messages); the tag of a quoted scalar ("90 d") would keep the
  // number a string in run.json.
  YAML::Node in_tree = node_;
  in_tree = YAML::Node(value).Scalar();
  in_tree.SetTag("?");
  return value;
}

long ConfigNode::as_integer() const {
  if (!node_.IsScalar()) throw error("expected an integer");
  long value = 0;
  if (!YAML::convert<long>::decode(node_, value))
    throw error("expected an integer, got '" + scalar_text(node_) + "'" +
                (units::split(scalar_text(node_)) ? " (a count takes no unit)" : ""));
  return value;
}

bool ConfigNode::as_bool() const {
  bool value = false;
  if (!node_.IsScalar() || !YAML::convert<bool>::decode(node_, value))
    throw error("expected true or false, got '" + scalar_text(node_) + "'");
  return value;
}

std::string ConfigNode::as_string() const {
  if (!node_.IsScalar()) throw error("expected a string");
  return node_.Scalar();
}

std::vector<double> ConfigNode::as_reals(const std::string& unit) const {
  if (node_.IsScalar()) return {as_real(unit)};
  std::vector<double> out;
  for (const auto& e : elements()) out.push_back(e.as_real(unit));
  return out;
}

std::vector<double> ConfigNode::as_row(const std::vector<std::string>& units, const std::string& what) const {
  if (!node_.IsSequence() || node_.size() != units.size()) throw error("expected " + what);
  std::vector<double> out;
  const auto items = elements();
  for (std::size_t i = 0; i < units.size(); ++i) out.push_back(items[i].as_real(units[i]));
  return out;
}

void apply_override(YAML::Node& root, const std::string& assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw InputError("--set '" + assignment + "': expected path.to.key=value");
  const std::string path = assignment.substr(0, eq);
  const std::string value = assignment.substr(eq + 1);

  std::vector<std::string> parts;
  std::stringstream ss(path);
  for (std::string part; std::getline(ss, part, '.');) parts.push_back(part);

  YAML::Node node = root;
  std::string walked;
  for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
    const std::string& part = parts[i];
    YAML::Node next;
    if (node.IsSequence()) {
      char* end = nullptr;
      const long index = std::strtol(part.c_str(), &end, 10);
      if (*end != '\0' || index < 0 || index >= static_cast<long>(node.size()))
        throw InputError("--set " + path + ": '" + part + "' is not an index of the list at '" +
                         walked + "' (size " + std::to_string(node.size()) + ")");
      next = node[index];
    } else if (node.IsMap() && node[part].IsDefined()) {
      next = node[part];
    } else {
      std::vector<std::string> keys;
      if (node.IsMap())
        for (const auto& kv : node) keys.push_back(kv.first.as<std::string>());
      std::string message = "--set " + path + ": path does not exist: no key '" + part + "' at '" +
                            (walked.empty() ? "<top>" : walked) + "'" + did_you_mean(part, keys);
      if (!keys.empty()) message += " Keys there: " + join(keys);
      throw InputError(message);
    }
    walked += (walked.empty() ? "" : ".") + part;
    node.reset(next);
  }
  if (!node.IsMap() && !node.IsSequence())
    throw InputError("--set " + path + ": '" + walked + "' is a value, not a section");
  YAML::Node parsed;
  try {
    parsed = YAML::Load(value);
  } catch (const YAML::Exception& e) {
    throw InputError(SourceLocation{"--set " + assignment, path, 0, 0}, "the value is not valid YAML: " + e.msg);
  }
  reject_duplicate_keys(parsed, "--set " + assignment, path);
  if (node.IsSequence()) {
    char* end = nullptr;
    const long index = std::strtol(parts.back().c_str(), &end, 10);
    if (*end != '\0' || index < 0 || index >= static_cast<long>(node.size()))
      throw InputError("--set " + path + ": '" + parts.back() + "' is not an index of '" + walked + "'");
    node[index] = parsed;
  } else {
    // A new leaf is allowed here: strict validation later rejects it if the schema has no such key.
    node[parts.back()] = parsed;
  }
}

}  // namespace frostmpm
