#include "frostmpm/scene/expression.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <sstream>

#include "frostmpm/config/input_error.hpp"

namespace frostmpm {

ExpressionError::ExpressionError(const std::string& detail, std::size_t column)
    : std::runtime_error(detail), detail_(detail), column_(column) {}

namespace {

// ---- operations (shared by constant folding and evaluation, so both agree exactly) ----------

enum Op : std::uint8_t {
  kConst, kVar,
  // unary
  kNeg, kSin, kCos, kTan, kExp, kLog, kLog10, kSqrt, kAbs, kFloor, kCeil, kStep,
  // binary
  kAdd, kSub, kMul, kDiv, kPow, kLt, kGt, kLe, kGe, kMin, kMax,
  // ternary
  kIf,
  // fused with a constant operand k: "x op k", or "k op x" for the kK* forms
  kAddK, kSubK, kMulK, kDivK, kPowK, kLtK, kGtK, kLeK, kGeK, kKSub, kKDiv, kKPow,
};

const char* op_name(std::uint8_t op) {
  static const char* const names[] = {
      "push", "load", "neg", "sin", "cos", "tan", "exp", "log", "log10", "sqrt", "abs", "floor",
      "ceil", "step", "add", "sub", "mul", "div", "pow", "lt", "gt", "le", "ge", "min", "max",
      "if", "addk", "subk", "mulk", "divk", "powk", "ltk", "gtk", "lek", "gek", "ksub", "kdiv",
      "kpow"};
  return op < sizeof(names) / sizeof(names[0]) ? names[op] : "?";
}

inline double truth(bool b) { return b ? 1.0 : 0.0; }
inline double op_min(double a, double b) { return std::isnan(a) || std::isnan(b) ? a + b : (b < a ? b : a); }
inline double op_max(double a, double b) { return std::isnan(a) || std::isnan(b) ? a + b : (a < b ? b : a); }

inline double apply_unary(std::uint8_t op, double x) {
  switch (op) {
    case kNeg: return -x;
    case kSin: return std::sin(x);
    case kCos: return std::cos(x);
    case kTan: return std::tan(x);
    case kExp: return std::exp(x);
    case kLog: return std::log(x);
    case kLog10: return std::log10(x);
    case kSqrt: return std::sqrt(x);
    case kAbs: return std::fabs(x);
    case kFloor: return std::floor(x);
    case kCeil: return std::ceil(x);
    case kStep: return truth(x >= 0);
    default: return std::nan("");
  }
}

inline double apply_binary(std::uint8_t op, double a, double b) {
  switch (op) {
    case kAdd: return a + b;
    case kSub: return a - b;
    case kMul: return a * b;
    case kDiv: return a / b;
    case kPow: return std::pow(a, b);
    case kLt: return truth(a < b);
    case kGt: return truth(a > b);
    case kLe: return truth(a <= b);
    case kGe: return truth(a >= b);
    case kMin: return op_min(a, b);
    case kMax: return op_max(a, b);
    default: return std::nan("");
  }
}

inline double apply_if(double c, double a, double b) { return c != 0 ? a : b; }

// ---- names ---------------------------------------------------------------------------------

struct FunctionInfo {
  const char* name;
  std::uint8_t op;
  std::size_t arity;
  const char* signature;
};

const FunctionInfo kFunctions[] = {
    {"sin", kSin, 1, "sin(x)"},       {"cos", kCos, 1, "cos(x)"},
    {"tan", kTan, 1, "tan(x)"},       {"exp", kExp, 1, "exp(x)"},
    {"log", kLog, 1, "log(x)"},       {"log10", kLog10, 1, "log10(x)"},
    {"sqrt", kSqrt, 1, "sqrt(x)"},    {"abs", kAbs, 1, "abs(x)"},
    {"floor", kFloor, 1, "floor(x)"}, {"ceil", kCeil, 1, "ceil(x)"},
    {"step", kStep, 1, "step(x)"},    {"min", kMin, 2, "min(a, b)"},
    {"max", kMax, 2, "max(a, b)"},    {"pow", kPow, 2, "pow(a, b)"},
    {"if", kIf, 3, "if(c, a, b)"},
};

struct ConstantInfo {
  const char* name;
  double value;
};
const ConstantInfo kConstants[] = {{"pi", 3.14159265358979323846}, {"e", 2.71828182845904523536}};

const FunctionInfo* find_function(const std::string& name) {
  for (const auto& f : kFunctions)
    if (name == f.name) return &f;
  return nullptr;
}
const ConstantInfo* find_constant(const std::string& name) {
  for (const auto& c : kConstants)
    if (name == c.name) return &c;
  return nullptr;
}

bool is_ident_start(char c) { return std::isalpha(static_cast<unsigned char>(c)) || c == '_'; }
bool is_ident_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }
bool is_digit(char c) { return c >= '0' && c <= '9'; }

/// Shortest text that reads back as the same double.
std::string number_text(double v) {
  char buf[64];
  const auto result = std::to_chars(buf, buf + sizeof(buf), v);
  return std::string(buf, result.ptr);
}

}  // namespace

// ---- compiler --------------------------------------------------------------------------------

class ExpressionCompiler {
 public:
  ExpressionCompiler(const std::string& text, const std::vector<std::string>& variables)
      : text_(text), variables_(variables) {}

  Expression compile() {
    check_variables();
    lex();
    if (tokens_.size() == 1) fail("expression is empty", 1);
    const int root = parse_comparison();
    const Token& tok = peek();
    if (tok.kind != Token::End) {
      if (tok.text == ")") fail("unmatched ')'", tok.column);
      expected("an operator or the end of the expression");
    }

    Expression out;
    out.text_ = text_;
    out.variables_ = variables_;
    const Node& r = nodes_[root];
    if (r.op == kConst) {
      out.constant_ = true;
      out.value_ = r.value;
      out.depth_ = 1;
      return out;
    }
    emit(root);
    if (max_depth_ > Expression::kMaxStack)
      fail("expression is too deeply nested (needs " + std::to_string(max_depth_) +
               " stack slots, at most " + std::to_string(Expression::kMaxStack) + ")",
           1);
    out.constant_ = false;
    out.code_ = std::move(code_);
    out.depth_ = max_depth_;
    return out;
  }

 private:
  struct Token {
    enum Kind { Number, Name, Punct, End } kind;
    std::string text;
    double value = 0;
    std::size_t column = 0;  // 1-based
  };
  struct Node {
    std::uint8_t op = kConst;
    double value = 0;
    std::uint32_t index = 0;
    int kid[3] = {-1, -1, -1};
  };

  static constexpr int kMaxNesting = 100;

  const std::string& text_;
  const std::vector<std::string>& variables_;
  std::vector<Token> tokens_;
  std::size_t pos_ = 0;
  int nesting_ = 0;
  std::vector<Node> nodes_;
  std::vector<Expression::Instr> code_;
  std::size_t depth_ = 0, max_depth_ = 0;

  [[noreturn]] static void fail(const std::string& detail, std::size_t column,
                                const std::string& tail = "") {
    throw ExpressionError(detail + " at column " + std::to_string(column) + tail, column);
  }

  void check_variables() const {
    for (std::size_t i = 0; i < variables_.size(); ++i) {
      const std::string& v = variables_[i];
      bool ok = !v.empty() && is_ident_start(v[0]);
      for (char c : v) ok = ok && is_ident_char(c);
      if (!ok) throw std::invalid_argument("expression variable '" + v + "' is not an identifier");
      if (find_function(v) || find_constant(v))
        throw std::invalid_argument("expression variable '" + v + "' clashes with a built-in name");
      if (std::find(variables_.begin(), variables_.begin() + i, v) != variables_.begin() + i)
        throw std::invalid_argument("expression variable '" + v + "' is listed twice");
    }
  }

  // ---- lexer ----

  void lex() {
    const std::size_t n = text_.size();
    std::size_t i = 0;
    while (i < n) {
      const char c = text_[i];
      const std::size_t column = i + 1;
      if (c == ' ' || c == '\t' || c == '\n' || c == '\r') {
        ++i;
        continue;
      }
      if (is_digit(c) || (c == '.' && i + 1 < n && is_digit(text_[i + 1]))) {
        std::size_t j = i;
        while (j < n && is_digit(text_[j])) ++j;
        if (j < n && text_[j] == '.') {
          ++j;
          while (j < n && is_digit(text_[j])) ++j;
        }
        if (j < n && (text_[j] == 'e' || text_[j] == 'E')) {
          std::size_t k = j + 1;
          if (k < n && (text_[k] == '+' || text_[k] == '-')) ++k;
          if (k < n && is_digit(text_[k])) {
            while (k < n && is_digit(text_[k])) ++k;
            j = k;
          }
        }
        if (j < n && (is_ident_char(text_[j]) || text_[j] == '.')) {
          std::size_t k = j;
          while (k < n && (is_ident_char(text_[k]) || text_[k] == '.')) ++k;
          const std::string bad = text_.substr(i, k - i);
          std::string hint;
          if (is_ident_start(text_[j]))
            hint = " (write " + text_.substr(i, j - i) + "*" + text_.substr(j, k - j) + " for a product)";
          fail("malformed number '" + bad + "'", column, hint);
        }
        Token tok{Token::Number, text_.substr(i, j - i), 0, column};
        const auto result = std::from_chars(text_.data() + i, text_.data() + j, tok.value);
        if (result.ec != std::errc() || !std::isfinite(tok.value))
          fail("number '" + tok.text + "' is out of range", column);
        tokens_.push_back(tok);
        i = j;
        continue;
      }
      if (is_ident_start(c)) {
        std::size_t j = i;
        while (j < n && is_ident_char(text_[j])) ++j;
        tokens_.push_back({Token::Name, text_.substr(i, j - i), 0, column});
        i = j;
        continue;
      }
      const std::string two = text_.substr(i, 2);
      if (two == "<=" || two == ">=") {
        tokens_.push_back({Token::Punct, two, 0, column});
        i += 2;
        continue;
      }
      if (two == "**") fail("'**' is not an operator", column, "; use '^' for powers");
      if (two == "==" || two == "!=" || c == '=')
        fail("'" + (c == '=' && two != "==" ? std::string("=") : two) + "' is not an operator", column,
             "; comparisons are < > <= >=");
      if (std::string("+-*/^(),<>").find(c) != std::string::npos) {
        tokens_.push_back({Token::Punct, std::string(1, c), 0, column});
        ++i;
        continue;
      }
      // Show a whole UTF-8 character, not one byte of it.
      std::size_t j = i + 1;
      if (static_cast<unsigned char>(c) >= 0xC0)
        while (j < n && (static_cast<unsigned char>(text_[j]) & 0xC0) == 0x80) ++j;
      fail("unexpected character '" + text_.substr(i, j - i) + "'", column);
    }
    tokens_.push_back({Token::End, "", 0, n + 1});
  }

  // ---- parser ----

  const Token& peek() const { return tokens_[pos_]; }
  bool at(const char* punct) const { return peek().kind == Token::Punct && peek().text == punct; }
  const Token& advance() { return tokens_[pos_ < tokens_.size() - 1 ? pos_++ : pos_]; }

  [[noreturn]] void expected(const std::string& what) const {
    const Token& tok = peek();
    if (tok.kind == Token::End) fail("expected " + what, tok.column);
    fail("expected " + what + ", found '" + tok.text + "'", tok.column);
  }

  int parse_comparison() {
    int left = parse_additive();
    for (;;) {
      std::uint8_t op;
      if (at("<")) op = kLt;
      else if (at(">")) op = kGt;
      else if (at("<=")) op = kLe;
      else if (at(">=")) op = kGe;
      else return left;
      advance();
      const int right = parse_additive();
      left = make_binary(op, left, right);
    }
  }

  int parse_additive() {
    int left = parse_product();
    for (;;) {
      std::uint8_t op;
      if (at("+")) op = kAdd;
      else if (at("-")) op = kSub;
      else return left;
      advance();
      const int right = parse_product();
      left = make_binary(op, left, right);
    }
  }

  int parse_product() {
    int left = parse_unary();
    for (;;) {
      std::uint8_t op;
      if (at("*")) op = kMul;
      else if (at("/")) op = kDiv;
      else return left;
      advance();
      const int right = parse_unary();
      left = make_binary(op, left, right);
    }
  }

  // Unary minus binds weaker than '^' (-2^2 = -4) but tighter than '*'.
  int parse_unary() {
    if (++nesting_ > kMaxNesting)
      fail("expression is nested too deeply (more than " + std::to_string(kMaxNesting) + " levels)",
           peek().column);
    int result;
    if (at("-")) {
      advance();
      result = make_unary(kNeg, parse_unary());
    } else if (at("+")) {
      advance();
      result = parse_unary();
    } else {
      result = parse_power();
    }
    --nesting_;
    return result;
  }

  // Right-associative: the exponent is itself a unary expression (2^3^2 = 2^9, 2^-1 = 0.5).
  int parse_power() {
    const int base = parse_primary();
    if (!at("^")) return base;
    advance();
    const int exponent = parse_unary();
    return make_binary(kPow, base, exponent);
  }

  int parse_primary() {
    const Token& tok = peek();
    if (tok.kind == Token::Number) {
      advance();
      return make_const(tok.value);
    }
    if (at("(")) {
      advance();
      const int inner = parse_comparison();
      if (!at(")")) expected("')'");
      advance();
      return inner;
    }
    if (tok.kind == Token::Name) return parse_name();
    expected("a number, a name or '('");
  }

  int parse_name() {
    const Token tok = advance();
    const auto var = std::find(variables_.begin(), variables_.end(), tok.text);
    if (var != variables_.end()) {
      if (at("(")) fail("'" + tok.text + "' is a variable, not a function", tok.column);
      Node node;
      node.op = kVar;
      node.index = static_cast<std::uint32_t>(var - variables_.begin());
      return add(node);
    }
    if (const ConstantInfo* c = find_constant(tok.text)) {
      if (at("(")) fail("'" + tok.text + "' is a constant, not a function", tok.column);
      return make_const(c->value);
    }
    if (const FunctionInfo* f = find_function(tok.text)) {
      if (!at("(")) fail("function '" + tok.text + "' needs its arguments in parentheses, e.g. " + f->signature,
                         tok.column);
      advance();
      std::vector<int> args;
      if (!at(")")) {
        for (;;) {
          args.push_back(parse_comparison());
          if (at(",")) {
            advance();
            continue;
          }
          if (at(")")) break;
          expected(args.size() >= f->arity ? "')'" : "','");
        }
      }
      advance();  // ')'
      if (args.size() != f->arity)
        fail("function '" + tok.text + "' takes " + std::to_string(f->arity) +
                 (f->arity == 1 ? " argument" : " arguments") + ", " + f->signature + ", but got " +
                 std::to_string(args.size()),
             tok.column);
      if (f->arity == 1) return make_unary(f->op, args[0]);
      if (f->arity == 2) return make_binary(f->op, args[0], args[1]);
      return make_if(args[0], args[1], args[2]);
    }
    std::vector<std::string> names(variables_.begin(), variables_.end());
    for (const auto& c : kConstants) names.push_back(c.name);
    for (const auto& f : kFunctions) names.push_back(f.name);
    std::string tail;
    const std::string hint = closest_match(tok.text, names);
    if (!hint.empty()) tail += "; did you mean '" + hint + "'?";
    tail += " Valid names: ";
    if (!variables_.empty())
      tail += (variables_.size() == 1 ? "variable " : "variables ") + join(variables_) + "; ";
    tail += "constants " + join(Expression::constant_names()) + "; functions ";
    std::vector<std::string> signatures;
    for (const auto& f : kFunctions) signatures.push_back(f.signature);
    tail += join(signatures);
    fail("unknown name '" + tok.text + "'", tok.column, tail);
  }

  // ---- tree building with constant folding ----

  int add(const Node& node) {
    nodes_.push_back(node);
    return static_cast<int>(nodes_.size() - 1);
  }
  int make_const(double v) {
    Node node;
    node.op = kConst;
    node.value = v;
    return add(node);
  }
  bool is_const(int n) const { return nodes_[n].op == kConst; }

  int make_unary(std::uint8_t op, int a) {
    if (is_const(a)) return make_const(apply_unary(op, nodes_[a].value));
    Node node;
    node.op = op;
    node.kid[0] = a;
    return add(node);
  }
  int make_binary(std::uint8_t op, int a, int b) {
    if (is_const(a) && is_const(b)) return make_const(apply_binary(op, nodes_[a].value, nodes_[b].value));
    Node node;
    node.op = op;
    node.kid[0] = a;
    node.kid[1] = b;
    return add(node);
  }
  int make_if(int c, int a, int b) {
    // Both branches are evaluated anyway, so a constant condition just picks one.
    if (is_const(c)) return nodes_[c].value != 0 ? a : b;
    Node node;
    node.op = kIf;
    node.kid[0] = c;
    node.kid[1] = a;
    node.kid[2] = b;
    return add(node);
  }

  // ---- code generation ----

  void push_instr(std::uint8_t op, double value = 0, std::uint32_t index = 0) {
    code_.push_back({op, index, value});
  }
  void grow() { max_depth_ = std::max(max_depth_, ++depth_); }

  static bool fusable(std::uint8_t op) {
    return op == kAdd || op == kSub || op == kMul || op == kDiv || op == kPow || op == kLt ||
           op == kGt || op == kLe || op == kGe;
  }
  // x op k
  static std::uint8_t fused_right(std::uint8_t op) {
    switch (op) {
      case kAdd: return kAddK;
      case kSub: return kSubK;
      case kMul: return kMulK;
      case kDiv: return kDivK;
      case kPow: return kPowK;
      case kLt: return kLtK;
      case kGt: return kGtK;
      case kLe: return kLeK;
      default: return kGeK;
    }
  }
  // k op x, rewritten on x (IEEE + and * are commutative; comparisons flip)
  static std::uint8_t fused_left(std::uint8_t op) {
    switch (op) {
      case kAdd: return kAddK;
      case kSub: return kKSub;
      case kMul: return kMulK;
      case kDiv: return kKDiv;
      case kPow: return kKPow;
      case kLt: return kGtK;
      case kGt: return kLtK;
      case kLe: return kGeK;
      default: return kLeK;
    }
  }

  void emit(int n) {
    const Node node = nodes_[n];
    switch (node.op) {
      case kConst:
        push_instr(kConst, node.value);
        grow();
        return;
      case kVar:
        push_instr(kVar, 0, node.index);
        grow();
        return;
      case kIf:
        emit(node.kid[0]);
        emit(node.kid[1]);
        emit(node.kid[2]);
        push_instr(kIf);
        depth_ -= 2;
        return;
      default: break;
    }
    if (node.kid[1] < 0) {  // unary
      emit(node.kid[0]);
      push_instr(node.op);
      return;
    }
    const int a = node.kid[0], b = node.kid[1];
    if (fusable(node.op) && is_const(b)) {
      emit(a);
      push_instr(fused_right(node.op), nodes_[b].value);
      return;
    }
    if (fusable(node.op) && is_const(a)) {
      emit(b);
      push_instr(fused_left(node.op), nodes_[a].value);
      return;
    }
    emit(a);
    emit(b);
    push_instr(node.op);
    --depth_;
  }
};

// ---- Expression ------------------------------------------------------------------------------

Expression::Expression() : text_("0") {}

Expression Expression::compile(const std::string& text, const std::vector<std::string>& variables) {
  return ExpressionCompiler(text, variables).compile();
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
    for (const auto& f : kFunctions) out.push_back(f.name);
    return out;
  }();
  return names;
}

// Dispatch by compare-and-branch rather than a jump table: with Spectre v2 mitigations (IBRS)
// indirect jumps are slow, and this measured 2-3x faster there. Every case is written out here
// (no helper with its own switch) so nothing dispatches through a table. The semantics match
// apply_unary / apply_binary, which constant folding uses.
#if defined(__GNUC__) && !defined(__clang__)
__attribute__((optimize("no-jump-tables")))
#endif
double Expression::run(const double* values) const {
  // The top of the stack lives in a register (`top`); `stack` holds the slots below it.
  double stack[kMaxStack];
  double* sp = stack;  // next free slot below the top
  double top = 0;
  for (const Instr& in : code_) {
    switch (in.op) {
      case kConst: *sp++ = top; top = in.value; break;
      case kVar: *sp++ = top; top = values[in.index]; break;
      case kNeg: top = -top; break;
      case kSin: top = std::sin(top); break;
      case kCos: top = std::cos(top); break;
      case kTan: top = std::tan(top); break;
      case kExp: top = std::exp(top); break;
      case kLog: top = std::log(top); break;
      case kLog10: top = std::log10(top); break;
      case kSqrt: top = std::sqrt(top); break;
      case kAbs: top = std::fabs(top); break;
      case kFloor: top = std::floor(top); break;
      case kCeil: top = std::ceil(top); break;
      case kStep: top = truth(top >= 0); break;
      case kAdd: top = *--sp + top; break;
      case kSub: top = *--sp - top; break;
      case kMul: top = *--sp * top; break;
      case kDiv: top = *--sp / top; break;
      case kPow: top = std::pow(*--sp, top); break;
      case kLt: top = truth(*--sp < top); break;
      case kGt: top = truth(*--sp > top); break;
      case kLe: top = truth(*--sp <= top); break;
      case kGe: top = truth(*--sp >= top); break;
      case kMin: --sp; top = op_min(*sp, top); break;
      case kMax: --sp; top = op_max(*sp, top); break;
      case kIf: sp -= 2; top = apply_if(sp[0], sp[1], top); break;
      case kAddK: top += in.value; break;
      case kSubK: top -= in.value; break;
      case kMulK: top *= in.value; break;
      case kDivK: top /= in.value; break;
      case kPowK: top = std::pow(top, in.value); break;
      case kLtK: top = truth(top < in.value); break;
      case kGtK: top = truth(top > in.value); break;
      case kLeK: top = truth(top <= in.value); break;
      case kGeK: top = truth(top >= in.value); break;
      case kKSub: top = in.value - top; break;
      case kKDiv: top = in.value / top; break;
      case kKPow: top = std::pow(in.value, top); break;
      default: break;
    }
  }
  return top;
}

std::string Expression::disassemble() const {
  if (constant_) return "push " + number_text(value_) + "\n";
  std::ostringstream out;
  for (const Instr& in : code_) {
    out << op_name(in.op);
    if (in.op == kVar)
      out << ' ' << variables_[in.index];
    else if (in.op == kConst || in.op >= kAddK)
      out << ' ' << number_text(in.value);
    out << '\n';
  }
  return out.str();
}

}  // namespace frostmpm
