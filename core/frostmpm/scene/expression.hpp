#pragma once
// Math expressions in scene input ("5 + 2*sin(2*pi*t/86400)"), parsed and evaluated by
// muparser (https://beltoforion.de/en/muparser/), restricted to the names below.
//
// Syntax, loosest binding first:
//   c ? a : b                                    (a when c != 0, else b)
//   a || b, a && b                               (logical; result 1 or 0)
//   comparison  a < b, a > b, a <= b, a >= b, a == b, a != b   (result 1 or 0)
//   additive    a + b, a - b                     (left-assoc)
//   product     a * b, a / b                     (left-assoc)
//   unary       -a, +a                           (binds weaker than ^: -2^2 = -4)
//   power       a ^ b                            (right-assoc: 2^3^2 = 512; 2^-1 = 0.5)
//   primary     number, variable, constant (pi, e), function(args), (expr)
// Functions: sin cos tan exp log (natural) log10 sqrt abs floor ceil step(x) (1 for x >= 0,
// else 0), min(a,b) max(a,b) pow(a,b) if(c,a,b) (a when c != 0, else b; both are evaluated).
// Math follows <cmath>: a domain error (log(-1), sqrt(-1)) gives NaN, 1/0 gives inf.
// Differences from the hand-written parser FrostMPM had before (muparser's rules): a doubled sign
// ("--3", "2*--t") is an error, write -(-3); == != && || and ?: are accepted; an expression
// is constant only when it names no variable (if(1, 3, t) is evaluated each time).
//
// Evaluation is thread-safe: each thread evaluates with its own muparser instance, created on
// its first evaluate() of the expression; after that evaluate() does no allocation. A constant
// expression is folded to a number when compiled and evaluate() just returns it.
#include <cstddef>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace frostmpm {

/// Malformed expression. what() and detail() are "<what is wrong> at column N[; hint]"; the
/// column is 1-based in the expression text (text length + 1 means "at the end").
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

  /// True when the expression names no variable (its value was computed when compiled).
  bool is_constant() const { return constant_; }
  /// The folded value when is_constant().
  double constant_value() const { return value_; }

  const std::string& text() const { return text_; }
  const std::vector<std::string>& variables() const { return variables_; }

  static const std::vector<std::string>& constant_names();  ///< pi, e
  static const std::vector<std::string>& function_names();  ///< sin, cos, ...

  struct Shared;  ///< the muparser instances, one per evaluating thread (implementation detail)

 private:
  std::string text_;
  std::vector<std::string> variables_;
  bool constant_ = true;
  double value_ = 0;
  std::shared_ptr<Shared> shared_;  ///< null for a constant

  double run(const double* values) const;
};

}  // namespace frostmpm
