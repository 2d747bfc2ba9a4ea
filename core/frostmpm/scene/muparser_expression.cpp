// Expression (expression.hpp) on muparser: our functions and constants, one parser per thread,
// muparser's errors turned into ExpressionError with a 1-based column. The home-made compiler
// this replaced is gone.
#include "frostmpm/scene/expression.hpp"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <map>
#include <mutex>
#include <thread>

#include <muParser.h>

#include "frostmpm/config/input_error.hpp"

namespace frostmpm {

ExpressionError::ExpressionError(const std::string& detail, std::size_t column)
    : std::runtime_error(detail), detail_(detail), column_(column) {}

namespace {

// ---- the names an expression may use -------------------------------------------------------

double nan_aware_min(double a, double b) { return std::isnan(a) || std::isnan(b) ? a + b : (b < a ? b : a); }
double nan_aware_max(double a, double b) { return std::isnan(a) || std::isnan(b) ? a + b : (a < b ? b : a); }

struct Function1 {
  const char* name;
  double (*f)(double);
};
struct Function2 {
  const char* name;
  double (*f)(double, double);
};

const Function1 kFunctions1[] = {
    {"sin", [](double x) { return std::sin(x); }},     {"cos", [](double x) { return std::cos(x); }},
    {"tan", [](double x) { return std::tan(x); }},     {"exp", [](double x) { return std::exp(x); }},
    {"log", [](double x) { return std::log(x); }},     {"log10", [](double x) { return std::log10(x); }},
    {"sqrt", [](double x) { return std::sqrt(x); }},   {"abs", [](double x) { return std::fabs(x); }},
    {"floor", [](double x) { return std::floor(x); }}, {"ceil", [](double x) { return std::ceil(x); }},
    {"step", [](double x) { return x >= 0 ? 1.0 : 0.0; }},
};
const Function2 kFunctions2[] = {
    {"min", nan_aware_min},
    {"max", nan_aware_max},
    {"pow", [](double a, double b) { return std::pow(a, b); }},
};
double if_function(double c, double a, double b) { return c != 0 ? a : b; }

struct Signature {
  const char* name;
  const char* text;
};
const Signature kSignatures[] = {
    {"sin", "sin(x)"},   {"cos", "cos(x)"},     {"tan", "tan(x)"},   {"exp", "exp(x)"},
    {"log", "log(x)"},   {"log10", "log10(x)"}, {"sqrt", "sqrt(x)"}, {"abs", "abs(x)"},
    {"floor", "floor(x)"}, {"ceil", "ceil(x)"}, {"step", "step(x)"}, {"min", "min(a, b)"},
    {"max", "max(a, b)"}, {"pow", "pow(a, b)"}, {"if", "if(c, a, b)"},
};

struct Constant {
  const char* name;
  double value;
};
const Constant kConstants[] = {{"pi", 3.14159265358979323846}, {"e", 2.71828182845904523536}};

const char* signature_of(const std::string& name) {
  for (const auto& s : kSignatures)
    if (name == s.name) return s.text;
  return nullptr;
}
bool is_constant_name(const std::string& name) {
  for (const auto& c : kConstants)
    if (name == c.name) return true;
  return false;
}

bool is_ident_start(char c) { return std::isalpha(static_cast<unsigned char>(c)) || c == '_'; }
bool is_ident_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }

/// A muparser instance that knows exactly our functions, constants and variables; the
/// variables are bound to `values`.
struct Instance {
  std::vector<double> values;
  mu::Parser parser;

  Instance(const std::string& text, const std::vector<std::string>& variables) : values(variables.size(), 0.0) {
    parser.ClearFun();
    parser.ClearConst();
    parser.ClearPostfixOprt();
    for (const auto& f : kFunctions1) parser.DefineFun(f.name, f.f);
    for (const auto& f : kFunctions2) parser.DefineFun(f.name, f.f);
    parser.DefineFun("if", if_function);
    for (const auto& c : kConstants) parser.DefineConst(c.name, c.value);
    for (std::size_t i = 0; i < variables.size(); ++i) parser.DefineVar(variables[i], &values[i]);
    parser.SetExpr(text);
  }
};

// ---- errors ----------------------------------------------------------------------------------

[[noreturn]] void fail(const std::string& detail, std::size_t column, const std::string& tail = "") {
  throw ExpressionError(detail + " at column " + std::to_string(column) + tail, column);
}

/// The identifier that ends just before `end` (spaces skipped), and where it starts.
std::string name_before(const std::string& text, std::size_t end, std::size_t& start) {
  while (end > 0 && std::isspace(static_cast<unsigned char>(text[end - 1]))) --end;
  start = end;
  while (start > 0 && is_ident_char(text[start - 1])) --start;
  return text.substr(start, end - start);
}

[[noreturn]] void unknown_name(const std::string& name, std::size_t column, const std::vector<std::string>& variables) {
  std::vector<std::string> names(variables);
  for (const auto& c : kConstants) names.push_back(c.name);
  for (const auto& s : kSignatures) names.push_back(s.name);
  std::string detail = "unknown name '" + name + "'";
  std::string tail = did_you_mean(name, names) + " Valid names: ";
  if (!variables.empty()) tail += (variables.size() == 1 ? "variable " : "variables ") + join(variables) + "; ";
  tail += "constants " + join(Expression::constant_names()) + "; functions ";
  std::vector<std::string> signatures;
  for (const auto& s : kSignatures) signatures.push_back(s.text);
  tail += join(signatures);
  fail(detail, column, tail);
}

/// A number with something glued to it ("2t", "1.2.3"); `pos` is inside or just after it.
[[noreturn]] void malformed_number(const std::string& text, std::size_t pos) {
  std::size_t start = pos, digits_end = pos, end = pos;
  while (start > 0 && (std::isdigit(static_cast<unsigned char>(text[start - 1])) || text[start - 1] == '.')) --start;
  while (end < text.size() && (is_ident_char(text[end]) || text[end] == '.')) ++end;
  while (digits_end < end && (std::isdigit(static_cast<unsigned char>(text[digits_end])) || text[digits_end] == '.')) ++digits_end;
  const std::string number = text.substr(start, end - start);
  std::string hint;
  if (digits_end < end && is_ident_start(text[digits_end]))
    hint = " (write " + text.substr(start, digits_end - start) + "*" + text.substr(digits_end, end - digits_end) +
           " for a product)";
  fail("malformed number '" + number + "'", start + 1, hint);
}

/// A token muparser could not read: a malformed number, an unknown name, a function without
/// arguments or a stray character.
[[noreturn]] void unreadable_token(const std::string& text, std::size_t pos, const std::vector<std::string>& variables) {
  const std::size_t column = pos + 1;
  const char c = pos < text.size() ? text[pos] : ' ';
  if (std::isdigit(static_cast<unsigned char>(c)) || c == '.') {
    std::size_t end = pos;
    while (end < text.size() && (is_ident_char(text[end]) || text[end] == '.' ||
                                 ((text[end] == '+' || text[end] == '-') && (text[end - 1] == 'e' || text[end - 1] == 'E'))))
      ++end;
    const std::string number = text.substr(pos, end - pos);
    char* stop = nullptr;
    const double v = std::strtod(number.c_str(), &stop);
    if (*stop == '\0' && !std::isfinite(v)) fail("number '" + number + "' is out of range", column);
    malformed_number(text, pos);
  }
  if (is_ident_start(c) && pos > 0 && (std::isdigit(static_cast<unsigned char>(text[pos - 1])) || text[pos - 1] == '.'))
    malformed_number(text, pos);
  if (is_ident_start(c)) {
    std::size_t end = pos;
    while (end < text.size() && is_ident_char(text[end])) ++end;
    const std::string name = text.substr(pos, end - pos);
    if (const char* signature = signature_of(name))
      fail("function '" + name + "' needs its arguments in parentheses, e.g. " + signature, column);
    unknown_name(name, column, variables);
  }
  // Show a whole UTF-8 character, not one byte of it.
  std::size_t end = pos + 1;
  if (static_cast<unsigned char>(c) >= 0xC0)
    while (end < text.size() && (static_cast<unsigned char>(text[end]) & 0xC0) == 0x80) ++end;
  fail("unexpected character '" + text.substr(pos, end - pos) + "'", column);
}

/// Rethrows muparser's error as an ExpressionError with a 1-based column and our wording.
[[noreturn]] void translate(const mu::ParserError& e, const std::string& text, const std::vector<std::string>& variables) {
  const std::size_t end_column = text.size() + 1;
  const int raw = e.GetPos();
  const std::size_t pos = raw < 0 ? 0 : std::min<std::size_t>(static_cast<std::size_t>(raw), text.size());
  const std::size_t column = pos + 1;
  const std::string token = e.GetToken();
  switch (e.GetCode()) {
    case mu::ecEMPTY_EXPRESSION: fail("expression is empty", 1);
    case mu::ecUNEXPECTED_EOF: fail("expected a number, a name or '('", end_column);
    case mu::ecMISSING_PARENS: fail("expected ')'", end_column);
    case mu::ecUNASSIGNABLE_TOKEN: unreadable_token(text, pos, variables);
    case mu::ecUNEXPECTED_OPERATOR: {
      const std::string detail = "expected a number, a name or '(', found '" + token + "'";
      const char before = pos > 0 ? text[pos - 1] : ' ';
      if (token == "*" && before == '*') fail(detail, column, "; '**' is not an operator, use '^' for powers");
      if ((token == "-" || token == "+") && (before == '-' || before == '+'))
        fail(detail, column, "; a doubled sign needs parentheses, e.g. -(-3)");
      fail(detail, column);
    }
    case mu::ecUNEXPECTED_VAL:
    case mu::ecUNEXPECTED_VAR:
    case mu::ecUNEXPECTED_FUN:
      if (pos > 0 && (std::isdigit(static_cast<unsigned char>(text[pos - 1])) || text[pos - 1] == '.'))
        malformed_number(text, pos);
      fail("expected an operator or the end of the expression, found '" + token + "'", column);
    case mu::ecUNEXPECTED_PARENS: {
      if (token != "(") fail("unmatched ')'", column);
      std::size_t start = 0;
      const std::string name = name_before(text, pos, start);
      if (std::find(variables.begin(), variables.end(), name) != variables.end())
        fail("'" + name + "' is a variable, not a function", start + 1);
      if (is_constant_name(name)) fail("'" + name + "' is a constant, not a function", start + 1);
      fail("unexpected '('", column);
    }
    case mu::ecTOO_MANY_PARAMS:
    case mu::ecTOO_FEW_PARAMS: {
      const std::string signature = signature_of(token) ? signature_of(token) : token + "(...)";
      const auto arity = 1 + std::count(signature.begin(), signature.end(), ',');
      const std::size_t at = text.rfind(token, pos);
      fail("function '" + token + "' takes " + std::to_string(arity) + (arity == 1 ? " argument, " : " arguments, ") +
               signature + (e.GetCode() == mu::ecTOO_MANY_PARAMS ? ", but got more" : ", but got fewer"),
           at == std::string::npos ? column : at + 1);
    }
    default: break;
  }
  // Anything else: muparser's message without its 0-based position.
  std::string detail = e.GetMsg();
  for (const char* cut : {" found at position", " at expression position", " at position"}) {
    const std::size_t at = detail.find(cut);
    if (at != std::string::npos) detail.erase(at);
  }
  while (!detail.empty() && (detail.back() == '.' || detail.back() == '!')) detail.pop_back();
  if (!detail.empty()) detail[0] = static_cast<char>(std::tolower(static_cast<unsigned char>(detail[0])));
  fail(detail, column);
}

/// muparser extras we do not want: assignment (t = 1, t += 1) and top-level commas (1, 2).
void reject_extras(const std::string& text) {
  int depth = 0;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '(') ++depth;
    if (c == ')') --depth;
    if (c == ',' && depth == 0) fail("',' outside a function's parentheses", i + 1);
    if (c == '=') {
      const char before = i > 0 ? text[i - 1] : ' ';
      const char after = i + 1 < text.size() ? text[i + 1] : ' ';
      if (after != '=' && before != '=' && before != '<' && before != '>' && before != '!')
        fail("'" + std::string(before == '+' || before == '-' || before == '*' || before == '/' ? 1 : 0, before) +
                 "=' is not an operator; comparisons are < > <= >= == !=",
             i + 1);
    }
  }
}

void check_variables(const std::vector<std::string>& variables) {
  for (std::size_t i = 0; i < variables.size(); ++i) {
    const std::string& v = variables[i];
    bool ok = !v.empty() && is_ident_start(v[0]);
    for (char c : v) ok = ok && is_ident_char(c);
    if (!ok) throw std::invalid_argument("expression variable '" + v + "' is not an identifier");
    if (signature_of(v) || is_constant_name(v))
      throw std::invalid_argument("expression variable '" + v + "' clashes with a built-in name");
    if (std::find(variables.begin(), variables.begin() + i, v) != variables.begin() + i)
      throw std::invalid_argument("expression variable '" + v + "' is listed twice");
  }
}

std::atomic<std::uint64_t> next_id{1};

}  // namespace

// ---- one muparser instance per thread --------------------------------------------------------

struct Expression::Shared {
  const std::uint64_t id = next_id++;
  std::string text;
  std::vector<std::string> variables;
  std::mutex mutex;
  std::map<std::thread::id, std::unique_ptr<Instance>> instances;  ///< guarded by mutex

  /// This thread's instance. The hot path is a look-up in a small thread-local table keyed by
  /// the never-reused id; a miss takes the lock (and builds the instance on first use).
  Instance& local() {
    struct Slot {
      std::uint64_t id = 0;
      Instance* instance = nullptr;
    };
    constexpr std::size_t kSlots = 64;
    thread_local Slot slots[kSlots];
    Slot& slot = slots[id % kSlots];
    if (slot.id == id) return *slot.instance;
    std::lock_guard<std::mutex> lock(mutex);
    std::unique_ptr<Instance>& instance = instances[std::this_thread::get_id()];
    if (!instance) instance = std::make_unique<Instance>(text, variables);
    slot = {id, instance.get()};
    return *instance;
  }
};

Expression::Expression() : text_("0") {}

Expression Expression::compile(const std::string& text, const std::vector<std::string>& variables) {
  check_variables(variables);
  reject_extras(text);
  auto shared = std::make_shared<Shared>();
  shared->text = text;
  shared->variables = variables;
  Instance& instance = shared->local();
  Expression out;
  out.text_ = text;
  out.variables_ = variables;
  try {
    const double value = instance.parser.Eval();  // parses; unknown names are errors here
    if (instance.parser.GetNumResults() != 1) fail("',' outside a function's parentheses", 1);
    if (instance.parser.GetUsedVar().empty()) {
      out.constant_ = true;
      out.value_ = value;
      return out;
    }
  } catch (const mu::ParserError& e) {
    translate(e, text, variables);
  }
  out.constant_ = false;
  out.shared_ = std::move(shared);
  return out;
}

double Expression::run(const double* values) const {
  Instance& instance = shared_->local();
  std::copy(values, values + instance.values.size(), instance.values.begin());
  return instance.parser.Eval();
}

const std::vector<std::string>& Expression::constant_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const auto& c : kConstants) out.push_back(c.name);
    return out;
  }();
  return names;
}

const std::vector<std::string>& Expression::function_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const auto& s : kSignatures) out.push_back(s.name);
    return out;
  }();
  return names;
}

}  // namespace frostmpm
