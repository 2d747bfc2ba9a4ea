#pragma once
// A small math expression compiler for scene input ("5 + 2*sin(2*pi*t/86400)").
//
// The text is parsed once into postfix bytecode (constant sub-expressions folded, constant
// operands fused into the instruction that uses them) and evaluated with a fixed-size stack on
// the C stack: evaluation does no allocation and no string work, and is thread-safe.
//
// Grammar, loosest binding first:
//   comparison  a < b, a > b, a <= b, a >= b     (left-assoc; result 1 or 0)
//   additive    a + b, a - b                     (left-assoc)
//   product     a * b, a / b                     (left-assoc)
//   unary       -a, +a                           (binds weaker than ^: -2^2 = -4)
//   power       a ^ b                            (right-assoc: 2^3^2 = 512; 2^-1 = 0.5)
//   primary     number, variable, constant (pi, e), function(args), (expr)
// Functions: sin cos tan exp log log10 sqrt abs floor ceil step(x) (1 for x >= 0, else 0),
// min(a,b) max(a,b) pow(a,b) if(c,a,b) (a when c != 0, else b; both are evaluated).
// Math follows <cmath>: a domain error (log(-1), sqrt(-1)) gives NaN, 1/0 gives inf.
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace frostmpm {

/// Malformed expression. what() is "<detail> at column N"; the column is 1-based in the
/// expression text (text length + 1 means "at the end").
class ExpressionError : public std::runtime_error {
 public:
  ExpressionError(const std::string& detail, std::size_t column);
  const std::string& detail() const { return detail_; }
  std::size_t column() const { return column_; }

 private:
  std::string detail_;
  std::size_t column_;
};

class Expression {
 public:
  /// Upper bound of the evaluation stack; deeper expressions are rejected when compiled.
  static constexpr std::size_t kMaxStack = 128;

  /// The constant 0.
  Expression();

  /// Compiles `text` with the given variable names (evaluate() takes their values in this
  /// order). Throws ExpressionError for malformed text or unknown names, and
  /// std::invalid_argument for a variable name that is not an identifier or clashes with a
  /// built-in constant or function.
  static Expression compile(const std::string& text, const std::vector<std::string>& variables = {"t"});

  /// Value for variable values `values[0..variables().size())`.
  double evaluate(const double* values) const {
    if (constant_) return value_;
    return run(values);
  }
  /// Value for an expression of (at most) one variable.
  double operator()(double x) const { return evaluate(&x); }

  /// True when the value depends on no variable (the whole expression folded to a number).
  bool is_constant() const { return constant_; }
  /// The folded value when is_constant().
  double constant_value() const { return value_; }

  const std::string& text() const { return text_; }
  const std::vector<std::string>& variables() const { return variables_; }
  /// Number of bytecode instructions (1 for a folded constant).
  std::size_t size() const { return code_.empty() ? 1 : code_.size(); }
  /// Stack slots evaluation needs.
  std::size_t stack_depth() const { return depth_; }
  /// The bytecode, one instruction per line, for debugging ("push t", "mulk 6.28", ...).
  std::string disassemble() const;

  static const std::vector<std::string>& constant_names();  ///< pi, e
  static const std::vector<std::string>& function_names();  ///< sin, cos, ...

  /// Bytecode instruction (public only so the implementation's helpers can name it).
  struct Instr {
    std::uint8_t op;
    std::uint32_t index;  ///< variable index for a variable push
    double value;         ///< constant operand (pushes and the fused "k" forms)
  };

 private:
  std::string text_;
  std::vector<std::string> variables_;
  std::vector<Instr> code_;
  std::size_t depth_ = 1;
  bool constant_ = true;
  double value_ = 0;

  double run(const double* values) const;
  friend class ExpressionCompiler;
};

}  // namespace frostmpm
