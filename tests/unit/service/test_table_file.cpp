// The exported table's C header: every number is a floating literal a C or C++
// compiler accepts ("0f" is an integer constant with a bad suffix, an error), and
// reads back as the float it stands for. tests/model/test_export_c_header.py
// compiles real exports with gcc and g++.
#include <gtest/gtest.h>

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

#include "daemon/service/table_file.h"

namespace resolver {
namespace {

TEST(CFloatLiteral, IntegralValuesKeepAPoint) {
  EXPECT_EQ(c_float_literal(0.0), "0.0f");
  EXPECT_EQ(c_float_literal(-0.0), "-0.0f");
  EXPECT_EQ(c_float_literal(1.0), "1.0f");
  EXPECT_EQ(c_float_literal(-100.0), "-100.0f");
  EXPECT_EQ(c_float_literal(0.0, false), "0.0");
  EXPECT_EQ(c_float_literal(-0.0, false), "-0.0");
  EXPECT_EQ(c_float_literal(3.0, false), "3.0");
}

TEST(CFloatLiteral, FractionsAndExponentsAreLeftAlone) {
  EXPECT_EQ(c_float_literal(0.5), "0.5f");
  EXPECT_EQ(c_float_literal(1e-5), "9.99999975e-06f");  // the float nearest 1e-5, 9 digits
  EXPECT_EQ(c_float_literal(1e20), "1.00000002e+20f");
  EXPECT_EQ(c_float_literal(1e-6, false), "1e-06");
  EXPECT_EQ(c_float_literal(2.5e-7, false), "2.5e-07");
}

TEST(CFloatLiteral, BelowFloatRangeIsTheFloatItBecomes) {
  EXPECT_EQ(c_float_literal(1e-60), "0.0f");
  EXPECT_EQ(c_float_literal(-1e-60), "-0.0f");
}

TEST(CFloatLiteral, NoLiteralForNonFiniteOrOutOfRange) {
  EXPECT_THROW((void)c_float_literal(std::numeric_limits<double>::quiet_NaN()), std::invalid_argument);
  EXPECT_THROW((void)c_float_literal(std::numeric_limits<double>::infinity()), std::invalid_argument);
  EXPECT_THROW((void)c_float_literal(-std::numeric_limits<double>::infinity(), false), std::invalid_argument);
  EXPECT_THROW((void)c_float_literal(1e300), std::invalid_argument);  // beyond FLT_MAX
  EXPECT_EQ(c_float_literal(1e300, false), "1e+300");
}

// Property: random values of every magnitude read back exactly (strtof) and
// always carry a point or an exponent.
TEST(CFloatLiteral, RoundTripsEveryMagnitude) {
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> mantissa(-10.0, 10.0);
  std::uniform_int_distribution<int> exponent(-40, 38);
  for (int i = 0; i < 20000; ++i) {
    const double v = i % 50 == 0 ? std::round(mantissa(rng)) : mantissa(rng) * std::pow(10.0, exponent(rng));
    if (std::abs(v) > static_cast<double>(std::numeric_limits<float>::max())) continue;
    const std::string lit = c_float_literal(v);
    ASSERT_EQ(lit.back(), 'f') << lit;
    const std::string number = lit.substr(0, lit.size() - 1);
    ASSERT_NE(number.find_first_of(".e"), std::string::npos) << lit;
    ASSERT_EQ(std::strtof(number.c_str(), nullptr), static_cast<float>(v)) << lit << " for " << v;
    const std::string dbl = c_float_literal(v, false);
    ASSERT_NE(dbl.find_first_of(".e"), std::string::npos) << dbl;
    ASSERT_EQ(std::strtod(dbl.c_str(), nullptr), v) << dbl;
  }
}

/// Whether `h` holds an integer with the float suffix ("0f", "-0f", "2f"): digits, maybe
/// signed, right before an 'f' that ends a word, not part of a decimal number or a name.
/// (A scanner, not std::regex: GCC 12 warns inside <regex> under ASan at -O1.)
bool has_integer_float_literal(const std::string& h) {
  const auto word = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_'; };
  for (std::size_t f = h.find('f'); f != std::string::npos; f = h.find('f', f + 1)) {
    if (f + 1 < h.size() && word(h[f + 1])) continue;
    std::size_t i = f;
    while (i > 0 && std::isdigit(static_cast<unsigned char>(h[i - 1])) != 0) --i;
    if (i == f) continue;
    if (i > 0 && h[i - 1] == '-') --i;
    if (i == 0) return true;
    const char before = h[i - 1];
    if (before != '.' && before != '+' && before != '-' && !word(before)) return true;
  }
  return false;
}

TEST(TableCHeader, ZeroTableHasNoIntegerConstants) {
  CalibrationTable t;
  t.p_r = 3;
  t.p = 3;
  t.correction.assign(16, 0.0);
  t.correction[3] = -0.0;
  t.correction[5] = 2.0;
  t.model = {"delay"};
  const std::string h = format_table_c_header(t, TableOrigin{"x.log", "2026-01-01T00:00:00Z", "test"});
  // The scanner itself: it finds what it looks for, and only that.
  EXPECT_TRUE(has_integer_float_literal("{0f, 1.0f}") && has_integer_float_literal("= -2f;"));
  EXPECT_FALSE(has_integer_float_literal("{1.0f, -0.0f, 1e-5f, x2f, 2fx}"));
  EXPECT_FALSE(has_integer_float_literal(h)) << h;
  EXPECT_NE(h.find("  0.0f, 0.0f, 0.0f, -0.0f, 0.0f, 2.0f,\n"), std::string::npos) << h;
  EXPECT_NE(h.find("resolver_cal_delay_s = 0.0;"), std::string::npos) << h;
  t.correction[7] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW((void)format_table_c_header(t, TableOrigin{}), std::invalid_argument);
}

}  // namespace
}  // namespace resolver
