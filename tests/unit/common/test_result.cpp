#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "dh3/base/result.hpp"

namespace dh3 {
namespace {

enum class Fault { broken, missing };

struct Located {
  std::string file;
  int line = 0;
};

Result<int, Fault> half(int n) {
  if (n % 2 != 0) return fail(Fault::broken);
  return n / 2;
}

Result<int, std::string> parse_digit(char c) {
  if (c < '0' || c > '9') return fail("not a digit");
  return c - '0';
}

Result<void, Located> check_line(int line) {
  if (line <= 0) return fail(Located{"a.yaml", line});
  return {};
}

Result<void, Located> check_line_in_place(int line) {
  if (line <= 0) return fail("b.yaml", line);  // Located built from the arguments
  return {};
}

TEST(Result, HoldsTheValueItWasGiven) {
  const auto r = half(8);
  ASSERT_TRUE(r.ok());
  EXPECT_TRUE(r.has_value());
  EXPECT_TRUE(static_cast<bool>(r));
  EXPECT_EQ(r.value(), 4);
  EXPECT_EQ(*r, 4);
}

TEST(Result, HoldsTheErrorItFailedWith) {
  const auto r = half(3);
  ASSERT_FALSE(r.ok());
  EXPECT_FALSE(r.has_value());
  EXPECT_EQ(r.error(), Fault::broken);
}

TEST(Result, FailWithTextMakesAStringError) {
  const auto r = parse_digit('x');
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error(), "not a digit");
  EXPECT_EQ(parse_digit('7').value(), 7);
}

TEST(Result, FailBuildsAStructErrorFromAnInstanceOrFromItsFields) {
  const auto whole = check_line(-1);
  ASSERT_FALSE(whole.ok());
  EXPECT_EQ(whole.error().file, "a.yaml");
  EXPECT_EQ(whole.error().line, -1);

  const auto in_place = check_line_in_place(0);
  ASSERT_FALSE(in_place.ok());
  EXPECT_EQ(in_place.error().file, "b.yaml");
  EXPECT_EQ(in_place.error().line, 0);

  EXPECT_TRUE(check_line(3).ok());
}

TEST(Result, ValueOrGivesTheFallbackOnlyOnError) {
  EXPECT_EQ(half(10).value_or(-1), 5);
  EXPECT_EQ(half(9).value_or(-1), -1);
  EXPECT_EQ(parse_digit('?').value_or(0), 0);
}

TEST(Result, MovesAMoveOnlyValueOut) {
  auto make = [](bool good) -> Result<std::unique_ptr<int>, std::string> {
    if (!good) return fail("no");
    return std::make_unique<int>(42);
  };
  auto r = make(true);
  ASSERT_TRUE(r.ok());
  std::unique_ptr<int> taken = std::move(r).value();
  ASSERT_NE(taken, nullptr);
  EXPECT_EQ(*taken, 42);
  EXPECT_EQ(make(false).error(), "no");
}

TEST(Result, ErrorCanBeForwardedIntoAnotherResult) {
  auto outer = [](char c) -> Result<long, std::string> {
    auto digit = parse_digit(c);
    if (!digit) return fail(std::move(digit).error());
    return static_cast<long>(*digit) * 10;
  };
  EXPECT_EQ(outer('4').value(), 40);
  EXPECT_EQ(outer('z').error(), "not a digit");
}

TEST(Result, VoidResultIsOkUnlessFailed) {
  const Result<void, Fault> fine;
  EXPECT_TRUE(fine.ok());
  const Result<void, Fault> failed = fail(Fault::missing);
  ASSERT_FALSE(failed.ok());
  EXPECT_EQ(failed.error(), Fault::missing);
}

// Asking for what is not there is a programming error: it stops the program
// with a message in every build type instead of throwing in the data path.
TEST(ResultDeathTest, ValueOfAnErrorStopsWithAMessage) {
  const auto r = half(1);
  EXPECT_DEATH((void)r.value(), "value\\(\\) of a Result that holds an error");
}

TEST(ResultDeathTest, ErrorOfAValueStopsWithAMessage) {
  const auto r = half(2);
  EXPECT_DEATH((void)r.error(), "error\\(\\) of a Result that holds a value");
  const Result<void, Fault> fine;
  EXPECT_DEATH((void)fine.error(), "error\\(\\) of a Result that holds no error");
}

}  // namespace
}  // namespace dh3
