// Time functions for boundary conditions and sources: constants, tables and compiled
// expressions of t, with every bad input reported as an InputError at its YAML path and line.
#include <catch2/catch.hpp>

#include <cmath>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "frostmpm/config/config_node.hpp"
#include "frostmpm/scene/expression.hpp"
#include "frostmpm/scene/time_function.hpp"

using frostmpm::ConfigNode;
using frostmpm::Expression;
using frostmpm::ExpressionError;
using frostmpm::InputError;
using frostmpm::TimeFunction;

namespace {

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

/// Reads `top.temperature: <value_yaml>` from a scene text (the value starts on line 2).
TimeFunction read_tf(const std::string& value_yaml) {
  const auto root = ConfigNode::load_string("top:\n  temperature: " + value_yaml + "\n", "scene.yaml");
  return TimeFunction::read(root.child("top").child("temperature"), "degC");
}

/// Message of the InputError thrown by reading `value_yaml`; fails the test if none is thrown.
std::string read_error(const std::string& value_yaml) {
  try {
    read_tf(value_yaml);
  } catch (const InputError& e) {
    return e.what();
  }
  FAIL("expected an InputError for: " << value_yaml);
  return {};
}

std::string expression_error(const std::string& text) {
  try {
    Expression::compile(text);
  } catch (const ExpressionError& e) {
    return e.what();
  }
  FAIL("expected an ExpressionError for: " << text);
  return {};
}

double eval(const std::string& text, double t = 0) { return Expression::compile(text)(t); }

}  // namespace

// ---- constants ---------------------------------------------------------------------------------

TEST_CASE("constant time functions", "[timefunction]") {
  const TimeFunction c = TimeFunction::constant(5.0);
  REQUIRE(c(0.0) == 5.0);
  REQUIRE(c(1e9) == 5.0);
  REQUIRE(c.is_constant());
  REQUIRE(c.describe() == "5");
  REQUIRE(c.kind() == TimeFunction::Kind::Constant);

  const TimeFunction read = read_tf("-2.5");
  REQUIRE(read(123.0) == -2.5);
  REQUIRE(read.is_constant());
  REQUIRE(read.to_yaml().as<double>() == -2.5);

  const TimeFunction zero;
  REQUIRE(zero(7.0) == 0.0);

  // Copies share the implementation and behave identically.
  const TimeFunction table = read_tf("{table: [[0, 1], [10, 2]]}");
  const TimeFunction copy = table;
  REQUIRE(copy(5.0) == table(5.0));
  REQUIRE(copy(5.0) == 1.5);
}

// ---- tables --------------------------------------------------------------------------------------

TEST_CASE("table with linear interpolation and hold extrapolation", "[timefunction]") {
  const TimeFunction f = read_tf("{table: [[0, 10], [100, 20], [300, 0], [400, 0]]}");
  REQUIRE(f.kind() == TimeFunction::Kind::Table);
  REQUIRE_FALSE(f.is_constant());
  REQUIRE(f.describe() == "table(4 rows, linear)");
  // At the knots: exactly the table values.
  REQUIRE(f(0.0) == 10.0);
  REQUIRE(f(100.0) == 20.0);
  REQUIRE(f(300.0) == 0.0);
  REQUIRE(f(400.0) == 0.0);
  // Between knots.
  REQUIRE(f(50.0) == Approx(15.0));
  REQUIRE(f(25.0) == Approx(12.5));
  REQUIRE(f(200.0) == Approx(10.0));
  REQUIRE(f(250.0) == Approx(5.0));
  REQUIRE(f(350.0) == 0.0);
  // Hold outside.
  REQUIRE(f(-1e6) == 10.0);
  REQUIRE(f(1e9) == 0.0);

  const YAML::Node y = f.to_yaml();
  REQUIRE(y["interpolation"].as<std::string>() == "linear");
  REQUIRE(y["extrapolation"].as<std::string>() == "hold");
  REQUIRE(y["table"].size() == 4);
  REQUIRE(y["table"][1][0].as<double>() == 100.0);
  REQUIRE(y["table"][1][1].as<double>() == 20.0);
}

TEST_CASE("table with step interpolation", "[timefunction]") {
  const TimeFunction f = read_tf("{table: [[0, 1], [10, 2], [20, 3]], interpolation: step}");
  REQUIRE(f.describe() == "table(3 rows, step)");
  REQUIRE(f(-5.0) == 1.0);
  REQUIRE(f(0.0) == 1.0);
  REQUIRE(f(9.999) == 1.0);
  REQUIRE(f(10.0) == 2.0);
  REQUIRE(f(15.0) == 2.0);
  REQUIRE(f(20.0) == 3.0);
  REQUIRE(f(1e6) == 3.0);
}

TEST_CASE("table extrapolation error and single-row tables", "[timefunction]") {
  const TimeFunction f = read_tf("{table: [[0, 1], [10, 2]], extrapolation: error}");
  REQUIRE(f(0.0) == 1.0);
  REQUIRE(f(10.0) == 2.0);
  REQUIRE(f(5.0) == Approx(1.5));
  REQUIRE_THROWS_AS(f(10.5), InputError);
  REQUIRE_THROWS_AS(f(-0.5), InputError);
  try {
    f(11.0);
    FAIL("expected an InputError");
  } catch (const InputError& e) {
    REQUIRE(contains(e.what(), "top.temperature.table"));
    REQUIRE(contains(e.what(), "outside"));
  }

  const TimeFunction one = read_tf("{table: [[5, 3]]}");
  REQUIRE(one(0.0) == 3.0);
  REQUIRE(one(100.0) == 3.0);
  REQUIRE(one.is_constant());
  REQUIRE(one.describe() == "table(1 row, linear)");

  // Tables built from code validate the same way.
  REQUIRE(TimeFunction::table({0, 1}, {2, 4})(0.25) == Approx(2.5));
  REQUIRE_THROWS_AS(TimeFunction::table({0, 0}, {2, 4}), InputError);
  REQUIRE_THROWS_AS(TimeFunction::table({}, {}), InputError);
}

TEST_CASE("table input errors name the path, the line and the row", "[timefunction]") {
  const std::string unsorted = read_error("{table: [[0, 1], [10, 2], [5, 3]]}");
  REQUIRE(contains(unsorted, "scene.yaml:2"));
  REQUIRE(contains(unsorted, "top.temperature.table"));
  REQUIRE(contains(unsorted, "increasing"));
  REQUIRE(contains(unsorted, "row 2"));

  const std::string repeated = read_error("{table: [[0, 1], [0, 2]]}");
  REQUIRE(contains(repeated, "increasing"));
  REQUIRE(contains(repeated, "row 1"));

  // A multi-line table reports the line of the offending row.
  {
    const auto root = ConfigNode::load_string(
        "top:\n  temperature:\n    table:\n      - [0, 1]\n      - [10, 2]\n      - [10, 3]\n", "scene.yaml");
    try {
      TimeFunction::read(root.child("top").child("temperature"), "degC");
      FAIL("expected an InputError");
    } catch (const InputError& e) {
      REQUIRE(contains(e.what(), "scene.yaml:6"));
      REQUIRE(contains(e.what(), "top.temperature.table.2"));
      REQUIRE(contains(e.what(), "increasing"));
    }
  }

  REQUIRE(contains(read_error("{table: [[0, 1, 2]]}"), "pair"));
  REQUIRE(contains(read_error("{table: [[0, abc]]}"), "expected a number"));
  REQUIRE(contains(read_error("{table: []}"), "at least one row"));
  REQUIRE(contains(read_error("{table: 5}"), "list of rows"));
  const std::string interp = read_error("{table: [[0, 1]], interpolation: cubic}");
  REQUIRE(contains(interp, "top.temperature.interpolation"));
  REQUIRE(contains(interp, "linear, step"));
  REQUIRE(contains(read_error("{table: [[0, 1]], extrapolation: clamp}"), "hold, error"));
  // Unknown keys next to a table are rejected by finish().
  const std::string extra = read_error("{table: [[0, 1]], interpolaton: step}");
  REQUIRE(contains(extra, "unknown key 'interpolaton'"));
  REQUIRE(contains(extra, "did you mean 'interpolation'"));
}

TEST_CASE("anything that is not a time function lists the three forms", "[timefunction]") {
  for (const std::string& bad : {std::string("hello"), std::string("[1, 2]"), std::string("{tabel: [[0, 1]]}"),
                                 std::string("{}"), std::string("{table: [[0, 1]], expression: t}")}) {
    const std::string message = read_error(bad);
    INFO(bad << " -> " << message);
    REQUIRE(contains(message, "top.temperature"));
    REQUIRE(contains(message, "table"));
    REQUIRE(contains(message, "expression"));
    REQUIRE(contains(message, "number"));
  }
  REQUIRE(contains(read_error("{tabel: [[0, 1]]}"), "did you mean 'table'"));
  REQUIRE(contains(read_error("{expression: t, interpolation: step}"), "unknown key 'interpolation'"));
}

// ---- expressions ---------------------------------------------------------------------------------

TEST_CASE("expression arithmetic and precedence", "[timefunction]") {
  REQUIRE(eval("2+3*4^2") == 50.0);
  REQUIRE(eval("-2^2") == -4.0);
  REQUIRE(eval("2^3^2") == 512.0);
  REQUIRE(eval("(2^3)^2") == 64.0);
  REQUIRE(eval("2^-1") == 0.5);
  REQUIRE(eval("-2^-2") == -0.25);
  REQUIRE(eval("(-2)^2") == 4.0);
  REQUIRE(eval("-(-3)") == 3.0);
  REQUIRE(eval("+3 - -3") == 6.0);
  REQUIRE(eval("2*-3") == -6.0);
  REQUIRE(eval("1 - 2 - 3") == -4.0);
  REQUIRE(eval("8 / 4 / 2") == 1.0);
  REQUIRE(eval("2 * 3 + 4 * 5") == 26.0);
  REQUIRE(eval("2 * (3 + 4) * 5") == 70.0);
  REQUIRE(eval("1e3 + 2.5e-1 + .5") == 1000.75);
  REQUIRE(eval("10 - t", 4) == 6.0);
  REQUIRE(eval("t - 10", 4) == -6.0);
  REQUIRE(eval("100 / t", 4) == 25.0);
  REQUIRE(eval("t / 100", 4) == 0.04);
  REQUIRE(eval("2^t", 10) == 1024.0);
  REQUIRE(eval("t^2", 3) == 9.0);
  REQUIRE(eval("t*t - 2*t + 1", 5) == 16.0);
  REQUIRE(eval("(t + 1) * (t - 1)", 5) == 24.0);
  REQUIRE(eval("-t", 5) == -5.0);
  REQUIRE(eval("pi") == Approx(3.141592653589793).epsilon(1e-15));
  REQUIRE(eval("e") == Approx(2.718281828459045).epsilon(1e-15));
  REQUIRE(std::isinf(eval("1/0")));
  REQUIRE(std::isinf(eval("log(t)", 0)));
  REQUIRE(std::isnan(eval("sqrt(t)", -1)));
}

TEST_CASE("expression functions, comparisons, if and step", "[timefunction]") {
  const double pi = 3.14159265358979323846;
  REQUIRE(eval("sin(pi/2)") == Approx(1.0));
  REQUIRE(eval("cos(0)") == 1.0);
  REQUIRE(eval("tan(pi/4)") == Approx(1.0));
  REQUIRE(eval("exp(1)") == Approx(2.718281828459045));
  REQUIRE(eval("log(e^2)") == Approx(2.0));
  REQUIRE(eval("log10(1000)") == Approx(3.0));
  REQUIRE(eval("sqrt(16)") == 4.0);
  REQUIRE(eval("abs(-3.5)") == 3.5);
  REQUIRE(eval("floor(-2.5)") == -3.0);
  REQUIRE(eval("ceil(-2.5)") == -2.0);
  REQUIRE(eval("min(3, t)", 7) == 3.0);
  REQUIRE(eval("max(3, t)", 7) == 7.0);
  REQUIRE(eval("min(t, 3)", 1) == 1.0);
  REQUIRE(eval("pow(2, 10)") == 1024.0);
  REQUIRE(eval("pow(t, 0.5)", 9) == 3.0);
  REQUIRE(eval("sin(t)^2 + cos(t)^2", 0.7) == Approx(1.0));
  REQUIRE(eval("5 + 2*sin(2*pi*t/86400)", 21600) == Approx(7.0));
  REQUIRE(eval("5 + 2*sin(2*pi*t/86400)", 64800) == Approx(3.0));
  REQUIRE(eval("sqrt(abs(t - 20))", 4) == 4.0);
  REQUIRE(eval("max(min(t, 10), -10)", 25) == 10.0);
  REQUIRE(eval("exp(-t/10)", 10) == Approx(std::exp(-1.0)));
  REQUIRE(eval("cos(2*pi*t)", 0.5) == Approx(std::cos(pi)));

  // Comparisons give 1 or 0 and bind weaker than arithmetic.
  REQUIRE(eval("t < 5", 4) == 1.0);
  REQUIRE(eval("t < 5", 5) == 0.0);
  REQUIRE(eval("t <= 5", 5) == 1.0);
  REQUIRE(eval("t > 5", 5) == 0.0);
  REQUIRE(eval("t >= 5", 5) == 1.0);
  REQUIRE(eval("5 > t", 4) == 1.0);
  REQUIRE(eval("5 <= t", 4) == 0.0);
  REQUIRE(eval("t + 1 < 2 * 3", 4) == 1.0);
  REQUIRE(eval("(t > 2) + (t > 3)", 4) == 2.0);
  REQUIRE(eval("t < 2*t", 3) == 1.0);

  REQUIRE(eval("if(t < 3600, 1, 2)", 0) == 1.0);
  REQUIRE(eval("if(t < 3600, 1, 2)", 3600) == 2.0);
  REQUIRE(eval("if(t, 10, 20)", 0) == 20.0);
  REQUIRE(eval("if(t, 10, 20)", -1) == 10.0);
  REQUIRE(eval("if(1, t, 0)", 7) == 7.0);
  REQUIRE(eval("if(0, t, -t)", 7) == -7.0);
  REQUIRE(eval("step(t)", -1e-9) == 0.0);
  REQUIRE(eval("step(t)", 0) == 1.0);
  REQUIRE(eval("step(t)", 2) == 1.0);
  REQUIRE(eval("-20 + 25*step(t - 86400)", 86399) == -20.0);
  REQUIRE(eval("-20 + 25*step(t - 86400)", 86400) == 5.0);

  // Read through YAML as a time function.
  const TimeFunction f = read_tf("{expression: \"5 + 2*sin(2*pi*t/86400)\"}");
  REQUIRE(f.kind() == TimeFunction::Kind::Expression);
  REQUIRE_FALSE(f.is_constant());
  REQUIRE(f(0.0) == Approx(5.0));
  REQUIRE(f(21600.0) == Approx(7.0));
  REQUIRE(f.describe() == "expression: 5+2*sin(2*pi*t/86400)");
  REQUIRE(f.to_yaml()["expression"].as<std::string>() == "5 + 2*sin(2*pi*t/86400)");
}

TEST_CASE("expressions are compiled: constants fold and evaluation is deterministic", "[timefunction]") {
  const Expression folded = Expression::compile("2*pi*3 + sqrt(4)");
  REQUIRE(folded.is_constant());
  REQUIRE(folded.constant_value() == Approx(6 * 3.14159265358979323846 + 2));
  REQUIRE(folded(123.0) == folded.constant_value());
  REQUIRE(read_tf("{expression: \"2^10\"}").is_constant());
  // Constant means "names no variable": a constant condition does not fold the branches.
  const TimeFunction branch = read_tf("{expression: \"if(1 > 0, 3, t)\"}");
  REQUIRE_FALSE(branch.is_constant());
  REQUIRE(branch(5.0) == 3.0);

  const Expression e = Expression::compile("5 + 2*sin(2*pi*t/86400)");
  REQUIRE_FALSE(e.is_constant());
  REQUIRE(e.text() == "5 + 2*sin(2*pi*t/86400)");
  REQUIRE(e.variables() == std::vector<std::string>{"t"});

  const TimeFunction f = read_tf("{expression: \"exp(-t/3600) * if(t > 100, cos(t), sin(t)) + t^1.5\"}");
  std::vector<double> first, second;
  for (int i = 0; i < 1000; ++i) first.push_back(f(i * 7.3));
  for (int i = 0; i < 1000; ++i) second.push_back(f(i * 7.3));
  REQUIRE(first == second);
  const TimeFunction copy = f;
  REQUIRE(copy(511.0) == f(511.0));
  REQUIRE(f(511.0) == Approx(std::exp(-511.0 / 3600) * std::cos(511.0) + std::pow(511.0, 1.5)));

  // Expressions with several variables take their values in order.
  const Expression xy = Expression::compile("x - 2*y", {"x", "y"});
  const double values[] = {10, 3};
  REQUIRE(xy.evaluate(values) == 4.0);
  REQUIRE_THROWS_AS(Expression::compile("1", {"pi"}), std::invalid_argument);
  REQUIRE_THROWS_AS(Expression::compile("1", {"x", "x"}), std::invalid_argument);
  REQUIRE_THROWS_AS(Expression::compile("1", {"2x"}), std::invalid_argument);
}

TEST_CASE("expressions evaluate concurrently, one parser per thread", "[timefunction]") {
  const Expression a = Expression::compile("5 + 2*sin(2*pi*t/86400)");
  const Expression b = Expression::compile("if(t > 50, t^2, -t) + max(t, 3)");
  const Expression copy = b;  // copies share the per-thread parsers
  constexpr int n = 20000;
  std::vector<double> serial(n), parallel(n);
  for (int i = 0; i < n; ++i) serial[i] = a(i * 0.37) + b(i * 0.01) - copy(i * 0.02);
#pragma omp parallel for schedule(dynamic, 97)
  for (int i = 0; i < n; ++i) parallel[i] = a(i * 0.37) + b(i * 0.01) - copy(i * 0.02);
  REQUIRE(serial == parallel);
  // Many expressions alive at once (more than the per-thread look-up table has slots).
  std::vector<Expression> many;
  for (int k = 0; k < 200; ++k) many.push_back(Expression::compile("t + " + std::to_string(k)));
  double sum = 0;
#pragma omp parallel for reduction(+ : sum)
  for (int i = 0; i < 4000; ++i) sum += many[i % 200](1.0);
  REQUIRE(sum == Approx(4000.0 + 20.0 * (199.0 * 200.0 / 2.0)));
}

TEST_CASE("malformed expressions report the column and the YAML path", "[timefunction]") {
  const std::string unclosed = read_error("{expression: \"sin(t\"}");
  REQUIRE(contains(unclosed, "top.temperature.expression"));
  REQUIRE(contains(unclosed, "scene.yaml:2"));
  REQUIRE(contains(unclosed, "expression 'sin(t' : expected ')' at column 6"));

  REQUIRE(expression_error("(1 + 2") == "expected ')' at column 7");
  try {
    Expression::compile("1 + * 2");
    FAIL("expected an ExpressionError");
  } catch (const ExpressionError& e) {
    REQUIRE(e.column() == 5);
    REQUIRE(e.detail() == e.what());
  }
  REQUIRE(expression_error("1 + ") == "expected a number, a name or '(' at column 5");
  REQUIRE(expression_error("1 + * 2") == "expected a number, a name or '(', found '*' at column 5");
  REQUIRE(expression_error("1 2") == "expected an operator or the end of the expression, found '2' at column 3");
  REQUIRE(expression_error("(1))") == "unmatched ')' at column 4");
  REQUIRE(expression_error("") == "expression is empty at column 1");
  REQUIRE(expression_error("   ") == "expression is empty at column 1");
  REQUIRE(contains(expression_error("2 ** 3"), "use '^'"));
  REQUIRE(contains(expression_error("t = 3"), "comparisons are"));
  REQUIRE(contains(expression_error("t += 3"), "'+=' is not an operator"));
  REQUIRE(expression_error("1, 2") == "',' outside a function's parentheses at column 2");
  REQUIRE(contains(expression_error("--3"), "doubled sign"));
  REQUIRE(contains(expression_error("1 + $"), "unexpected character '$' at column 5"));
  REQUIRE(contains(expression_error("2t"), "malformed number '2t' at column 1 (write 2*t for a product)"));
  REQUIRE(contains(expression_error("1.2.3"), "malformed number"));
  REQUIRE(contains(expression_error("1e999"), "out of range at column 1"));
  REQUIRE(contains(expression_error("min(1)"), "takes 2 arguments"));
  REQUIRE(contains(expression_error("min(1)"), "at column 1"));
  REQUIRE(contains(expression_error("sin(1, 2)"), "takes 1 argument"));
  REQUIRE(contains(expression_error("if(1, 2)"), "takes 3 arguments"));
  REQUIRE(expression_error("min(1 2)") == "expected an operator or the end of the expression, found '2' at column 7");
  REQUIRE(contains(expression_error("2 * sin"), "needs its arguments in parentheses"));
  REQUIRE(contains(expression_error("2 * sin"), "at column 5"));
  REQUIRE(contains(expression_error("t(2)"), "'t' is a variable, not a function at column 1"));
  REQUIRE(contains(expression_error("1 + pi(2)"), "not a function at column 5"));
  REQUIRE(eval(std::string(150, '(') + "1" + std::string(150, ')')) == 1.0);

  const std::string via_yaml = read_error("{expression: \"2 +\"}");
  REQUIRE(contains(via_yaml, "top.temperature.expression"));
  REQUIRE(contains(via_yaml, "at column 4"));
  REQUIRE(contains(read_error("{expression: [1, 2]}"), "as a string"));
}

TEST_CASE("unknown names in expressions list the valid names", "[timefunction]") {
  const std::string message = read_error("{expression: \"5 + flor(t)\"}");
  REQUIRE(contains(message, "top.temperature.expression"));
  REQUIRE(contains(message, "unknown name 'flor' at column 5"));
  REQUIRE(contains(message, "did you mean 'floor'"));
  REQUIRE(contains(message, "variable t"));
  REQUIRE(contains(message, "pi, e"));
  REQUIRE(contains(message, "sin(x)"));
  REQUIRE(contains(message, "if(c, a, b)"));

  const std::string time = expression_error("2 * time");
  REQUIRE(contains(time, "unknown name 'time' at column 5"));
  REQUIRE(contains(time, "Valid names"));
  // Names are case-sensitive.
  REQUIRE(contains(expression_error("Sin(t)"), "unknown name 'Sin' at column 1"));
}
